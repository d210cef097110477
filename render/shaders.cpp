#include "render/shaders.h"

namespace vt::render {
namespace {

const uint32_t kMeshVert[] =
#include "spirv/mesh.vert.inc"
    ;
const uint32_t kReferenceFrag[] =
#include "spirv/reference.frag.inc"
    ;
const uint32_t kFeedbackFrag[] =
#include "spirv/feedback.frag.inc"
    ;
const uint32_t kVirtualFrag[] =
#include "spirv/virtual.frag.inc"
    ;
const uint32_t kLitReferenceFrag[] =
#include "spirv/lit_reference.frag.inc"
    ;
const uint32_t kLitVirtualFrag[] =
#include "spirv/lit_virtual.frag.inc"
    ;

}  // namespace

std::span<const uint32_t> spirv_mesh_vert() {
  return kMeshVert;
}
std::span<const uint32_t> spirv_reference_frag() {
  return kReferenceFrag;
}
std::span<const uint32_t> spirv_feedback_frag() {
  return kFeedbackFrag;
}
std::span<const uint32_t> spirv_virtual_frag() {
  return kVirtualFrag;
}
std::span<const uint32_t> spirv_lit_reference_frag() {
  return kLitReferenceFrag;
}
std::span<const uint32_t> spirv_lit_virtual_frag() {
  return kLitVirtualFrag;
}

}  // namespace vt::render
