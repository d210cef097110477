// The error after the runtime format (see runtime_error.h).
#include "codec/runtime_error.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <numbers>

namespace vt {
namespace {

// 0..255 to -1..1 with Z rebuilt as a shader does after BC5 (codec/metrics.h's convention).
void unpack_normal(const uint8_t* t, double n[3]) {
  n[0] = t[0] / 127.5 - 1.0;
  n[1] = t[1] / 127.5 - 1.0;
  n[2] = std::sqrt(std::max(0.0, 1.0 - n[0] * n[0] - n[1] * n[1]));
}

double angle_deg(const uint8_t* a, const uint8_t* b) {
  double u[3], v[3];
  unpack_normal(a, u);
  unpack_normal(b, v);
  const double lu = std::sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
  const double lv = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  if (lu <= 0 || lv <= 0) return 0;
  const double c = (u[0] * v[0] + u[1] * v[1] + u[2] * v[2]) / (lu * lv);
  return std::acos(std::clamp(c, -1.0, 1.0)) * (180.0 / std::numbers::pi);
}

// What the GPU samples: `bc_blocks` (or `stored` encoded as the runtime transcodes it) decoded
// to size x size texels of `channels` channels, in a buffer of this thread's that the next call
// reuses.
Expected<const std::vector<uint8_t>*> land(BcFormat format, const uint8_t* stored,
                                           const uint8_t* bc_blocks, int size, int channels) {
  thread_local std::vector<uint8_t> blocks, landed;
  if (!bc_blocks) {
    blocks.resize(bc_image_bytes(format, size, size));
    VT_RETURN_IF_ERROR(
        bc_encode_image(format, BcQuality::kRealtime, stored, size, size, channels, blocks.data()));
    bc_blocks = blocks.data();
  }
  landed.resize(size_t(size) * size * size_t(channels) * size_t(bc_channel_bytes(format)));
  VT_RETURN_IF_ERROR(bc_decode_image(format, bc_blocks, size, size, channels, landed.data()));
  return &landed;
}

}  // namespace

void RuntimeError::add(const RuntimeError& o) {
  squared_error += o.squared_error;
  samples += o.samples;
  max_error = std::max(max_error, o.max_error);
  normals += o.normals;
  angle_sum_deg += o.angle_sum_deg;
  angle_max_deg = std::max(angle_max_deg, o.angle_max_deg);
  hdr.add(o.hdr);
  if (!o.angle_histogram.empty()) {
    angle_histogram.resize(kAngleBins);
    for (int i = 0; i < kAngleBins; ++i) angle_histogram[size_t(i)] += o.angle_histogram[size_t(i)];
  }
}

double RuntimeError::psnr_db() const {
  if (samples == 0 || squared_error <= 0) return INFINITY;
  return 10.0 * std::log10(255.0 * 255.0 * double(samples) / squared_error);
}

double RuntimeError::angle_p99_deg() const {
  if (normals == 0 || angle_histogram.empty()) return 0;
  const uint64_t target = normals - normals / 100;  // texels at or below the 99th percentile
  uint64_t seen = 0;
  for (int i = 0; i < kAngleBins; ++i) {
    seen += angle_histogram[size_t(i)];
    if (seen >= target) return std::min(angle_max_deg, (i + 1) * kAngleBinDeg);
  }
  return angle_max_deg;
}

Status measure_runtime_error(BcFormat format, bool normal, const uint8_t* source,
                             const uint8_t* stored, const uint8_t* bc_blocks, int size,
                             int channels, RuntimeError& out, const float* reference) {
  out = RuntimeError{};
  VT_ASSIGN_OR_RETURN(const std::vector<uint8_t>* landed_texels,
                      land(format, stored, bc_blocks, size, channels));
  const std::vector<uint8_t>& landed = *landed_texels;
  const int kept = std::min(channels, bc_format_channels(format));
  const size_t texels = size_t(size) * size;
  if (reference) {
    double sse = 0, mx = 0;
    for (size_t i = 0; i < texels; ++i) {
      for (int c = 0; c < kept; ++c) {
        const double d = double(reference[i * channels + c]) - double(landed[i * channels + c]);
        sse += d * d;
        mx = std::max(mx, std::abs(d));
      }
    }
    out.squared_error = sse;
    out.max_error = uint32_t(std::min(std::round(mx), double(UINT32_MAX)));
  } else {
    uint64_t sse = 0;
    for (size_t i = 0; i < texels; ++i) {
      for (int c = 0; c < kept; ++c) {
        const int d = int(source[i * channels + c]) - int(landed[i * channels + c]);
        sse += uint64_t(d * d);
        out.max_error = std::max<uint32_t>(out.max_error, uint32_t(std::abs(d)));
      }
    }
    out.squared_error = double(sse);
  }
  out.samples = texels * size_t(kept);
  if (normal && channels >= 2) {
    out.angle_histogram.assign(RuntimeError::kAngleBins, 0);
    for (size_t i = 0; i < texels; ++i) {
      const double a = angle_deg(source + i * channels, landed.data() + i * channels);
      out.angle_sum_deg += a;
      out.angle_max_deg = std::max(out.angle_max_deg, a);
      const int bin = std::min(RuntimeError::kAngleBins - 1, int(a / RuntimeError::kAngleBinDeg));
      ++out.angle_histogram[size_t(bin)];
    }
    out.normals = texels;
  }
  return Status::Ok();
}

Status measure_runtime_hdr_error(BcFormat format, const uint8_t* source, const uint8_t* stored,
                                 const uint8_t* bc_blocks, int size, int channels,
                                 RuntimeError& out, const float* reference) {
  out = RuntimeError{};
  if (!bc_is_bc6h(format))
    return Error(ErrorCode::kInvalidArgument, "HDR runtime error: not a BC6H format");
  VT_ASSIGN_OR_RETURN(const std::vector<uint8_t>* landed,
                      land(format, stored, bc_blocks, size, channels));
  const size_t texels = size_t(size) * size;
  const int kept = std::min(channels, 3);
  if (reference) {
    add_hdr_error(reference, landed->data(), texels, channels, kept, out.hdr);
  } else {
    add_hdr_error(source, landed->data(), texels, channels, kept, out.hdr);
  }
  return Status::Ok();
}

}  // namespace vt
