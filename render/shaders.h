// SPIR-V of the validation shaders, compiled from render/shaders/ by glslc at build time.
#pragma once

#include <cstdint>
#include <span>

namespace vt::render {

std::span<const uint32_t> spirv_mesh_vert();
std::span<const uint32_t> spirv_reference_frag();
std::span<const uint32_t> spirv_feedback_frag();
std::span<const uint32_t> spirv_virtual_frag();
std::span<const uint32_t> spirv_lit_reference_frag();
std::span<const uint32_t> spirv_lit_virtual_frag();

}  // namespace vt::render
