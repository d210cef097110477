// Layer error text and the --min-psnr flag (see layer_error_text.h).
#include "cli/layer_error_text.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace vt::cli {

std::string hdr_error_text(const HdrError& e) {
  char buf[160];
  const double psnr = e.tonemapped_psnr_db();
  if (!std::isfinite(psnr)) return "exact";
  std::snprintf(buf, sizeof buf,
                "log2 error mean %.3g max %.3g, relative max %.3g, tone-mapped PSNR %.2f dB",
                e.log_abs_mean(), e.log_abs_max, e.relative_max, psnr);
  return buf;
}

std::string runtime_error_text(const LayerSummary& l) {
  std::string text;
  char buf[160];
  const RuntimeError& r = l.runtime;
  if (r.hdr.samples > 0) {
    text +=
        ", after " + std::string(to_string(l.spec.runtime_format)) + ": " + hdr_error_text(r.hdr);
  }
  if (r.samples > 0) {
    const double psnr = r.psnr_db();
    if (std::isfinite(psnr)) {
      std::snprintf(buf, sizeof buf, ", after %s: PSNR %.2f dB, max error %u",
                    to_string(l.spec.runtime_format), psnr, r.max_error);
    } else {
      std::snprintf(buf, sizeof buf, ", after %s: exact", to_string(l.spec.runtime_format));
    }
    text += buf;
    if (r.normals > 0) {
      std::snprintf(buf, sizeof buf, ", angle mean/p99/max %.2f/%.2f/%.2f deg", r.angle_mean_deg(),
                    r.angle_p99_deg(), r.angle_max_deg);
      text += buf;
    }
  }
  if (l.spec.codec == PageCodec::kDct) {
    const char* sep = "; pages";
    for (int m = 0; m < kDctModeKinds; ++m) {
      if (!l.dct_modes[m]) continue;
      std::snprintf(buf, sizeof buf, "%s %llu %s", sep, (unsigned long long)l.dct_modes[m],
                    dct_mode_name(uint8_t(m)));
      text += buf;
      sep = ",";
    }
  }
  return text;
}

Status parse_min_psnr(const std::string& text, PageEncoderOptions* options) {
  const size_t eq = text.find('=');
  const std::string value = eq == std::string::npos ? text : text.substr(eq + 1);
  char* end = nullptr;
  const double db = std::strtod(value.c_str(), &end);
  if (value.empty() || *end || !(db >= 0 && db <= 100) || eq == 0)
    return Error(ErrorCode::kInvalidArgument,
                 "--min-psnr: expected DB or LAYER=DB with DB in 0..100, got '" + text + "'");
  if (eq == std::string::npos) {
    options->min_psnr = db;
  } else {
    options->layer_min_psnr[text.substr(0, eq)] = db;
  }
  return Status::Ok();
}

}  // namespace vt::cli
