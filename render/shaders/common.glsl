// Shared by every vtbake validation shader: push constants and the anisotropic footprint.
// Both the reference and the virtual-texture path filter with exactly this code, so the
// comparison measures the bake, not a difference in filtering.

layout(push_constant) uniform Push {
  mat4 mvp;
  // xy: level-0 texel size of the texture; z: derivative scale (render size over pass size:
  // the feedback pass runs at reduced resolution but must pick the full-resolution LOD);
  // w: alpha cutoff, negative when the material has no alpha test.
  vec4 tex;
  // x: level count, y: page payload, z: page border, w: page size (payload + 2 * border).
  ivec4 vt;
  // x: frame index (feedback tap rotation), y: address mode (0 clamp, 1 wrap, 2 the sampler's:
  // taps are left as they are, for material samplers with per-axis modes), z: max LOD; w, in the
  // feedback and virtual passes: 1 = an HDR lighting layer (rgb tone-mapped x / (1 + x), alpha
  // is AO: no alpha test), 0 otherwise (the lit passes use w for their inputs, lit.glsl).
  ivec4 misc;
}
pc;

#ifndef VT_VERTEX_STAGE
const int kTaps = 4;

// Alpha within this much of a material's cutoff may flip the alpha test between two renders of
// the same texels (BC decoding and filtering rounding): the passes flag such fragments so the
// exact check can tell a flipped alpha test from a wrong texel.
const float kAlphaEdge = 4.5 / 255.0;

// 4x anisotropic footprint: kTaps taps along the major axis of the pixel's footprint; the LOD
// comes from the larger of the minor axis and the major axis over the tap count (each tap then
// covers its share of the footprint). `step` is the uv distance between taps.
struct Footprint {
  vec2 step;
  float lod;
};

Footprint footprint(vec2 uv, float deriv_scale) {
  vec2 dx = dFdx(uv) * pc.tex.xy * deriv_scale;
  vec2 dy = dFdy(uv) * pc.tex.xy * deriv_scale;
  float lx = length(dx);
  float ly = length(dy);
  vec2 major = lx >= ly ? dx : dy;
  float lmaj = max(lx, ly);
  float lmin = min(lx, ly);
  Footprint f;
  f.lod = clamp(log2(max(max(lmaj / float(kTaps), lmin), 1e-6)), 0.0, float(pc.misc.z));
  f.step = major / (pc.tex.xy * float(kTaps));
  return f;
}

vec2 tap_uv(vec2 uv, Footprint f, int i) {
  vec2 u = uv + f.step * (float(i) - 0.5 * float(kTaps - 1));
  if (pc.misc.y == 2) return u;
  return pc.misc.y == 1 ? fract(u) : clamp(u, 0.0, 1.0);
}
#endif  // VT_VERTEX_STAGE
