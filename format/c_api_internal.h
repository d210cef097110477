// Internal to the C APIs' implementations: how a Status, a NULL argument or an exception becomes
// a vt_error code and the calling thread's vt_last_error() message (format/vt_error_c.h).
#pragma once

#include <exception>
#include <memory>
#include <string>

#include "common/status.h"
#include "format/byte_source.h"
#include "format/page_geometry.h"
#include "format/vt_error_c.h"
#include "format/vt_io_c.h"

namespace vt::c_api {

// Records the failure as the thread's last error; returns its code.
int fail(const Status& status);
// A NULL argument: VT_ERR_INVALID_ARGUMENT naming it.
int fail_null(const char* what);

// Runs `body` (returning int) so that no exception crosses into C.
template <typename Fn>
int guard(Fn&& body) {
  try {
    return body();
  } catch (const std::exception& e) {  // std::bad_alloc above all
    return fail(Error(ErrorCode::kResourceLimit, e.what()));
  }
}

// The engine's read callbacks as a ByteSource (release called when the last user lets go);
// nullptr after recording the error when the callbacks are unusable.
std::shared_ptr<const ByteSource> callback_byte_source(const vt_read_callbacks* io);

// Fills the geometry fields that vtpf_geometry and vtrt_geometry share.
template <typename CGeometry>
void fill_geometry(const PageGeometry& g, CGeometry* out) {
  out->width = g.width;
  out->height = g.height;
  out->payload = g.payload;
  out->border = g.border;
  out->page_size = g.page_size();
  out->level_count = g.level_count();
}

}  // namespace vt::c_api
