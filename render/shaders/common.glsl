// Shared by every vtbake validation shader: push constants and the anisotropic footprint.
// Both the reference and the virtual-texture path filter with exactly this code, so the
// comparison measures the bake, not a difference in filtering.

layout(push_constant) uniform Push {
  mat4 mvp;
  // xy: level-0 texel size of the texture; z: derivative scale (render size over pass size:
  // the feedback pass runs at reduced resolution but must pick the full-resolution LOD);
  // w: alpha cutoff, negative when the material has no alpha test: kAlphaBlended (-2) for a
  // blended material, -1 for an opaque one.
  vec4 tex;
  // x: level count, y: page payload, z: page border, w: page size (payload + 2 * border).
  ivec4 vt;
  // x: frame index (feedback tap rotation), y: address mode (0 clamp, 1 wrap, 2 the sampler's:
  // taps are left as they are, for material samplers with per-axis modes), z: max LOD; w, in the
  // feedback and virtual passes: 1 = an HDR lighting layer (rgb tone-mapped x / (1 + x), alpha
  // is AO: no alpha test), 0 otherwise; in the reference pass: 1 = a page file's levels
  // (reference.frag); the lit passes use w for their inputs (lit.glsl).
  ivec4 misc;
}
pc;

#ifndef VT_VERTEX_STAGE
// pc.misc and pc.tex.w as flat inputs (mesh.vert copies them), which every branch reads instead
// of the push constants: lavapipe (Mesa 22.3) inlines push constants and uniforms that decide a
// fragment shader's branches, compiling the shader anew on each draw that sets them and never
// freeing it (about 12 ms and 1.7 MB a draw: a 372-mesh track grew 1 GB a view in validate's lit
// passes, one of 1,465 meshes ran out of 24 GB). Inputs it cannot inline.
layout(location = 7) flat in ivec4 v_misc;
layout(location = 8) flat in float v_alpha_cutoff;

// At most this many taps per pixel: 16x anisotropic, as GPUs' highest setting. A fixed, smaller
// count blurred footprints beyond its ratio isotropically in each texture's own space, and the
// source's UV space and the atlas's differ in shape: grazing faces then differed by up to 8 dB
// per tile between two renders of correct texels (docs/BENCHMARKS.md, validation section).
const int kMaxTaps = 16;

// Alpha within this much of a material's cutoff may flip the alpha test between two renders of
// the same texels: the passes flag such fragments so the exact check can tell a flipped alpha
// test from a wrong texel. Inside a page the two alphas agree to a rounding, but a tap on a
// page's border reads that page's own encoding of its neighbour's texels, which the check lets
// differ by up to its border bound (render/streaming_check.cpp, border_max_abs: 40 steps); a
// masked edge across a seam then flips where the alphas lie that far apart. At 4.5 / 255 the
// sample scene baked at its default density (a 12480² atlas) failed its exact check on 12 leaf
// edge pixels off by up to 126 steps, each a flipped test on a seam.
const float kAlphaEdge = 40.0 / 255.0;

// A blended material's colour is written as it composites, premultiplied by its alpha, in both
// renders: colour under zero alpha is never seen and must not count (the bake bleeds colour
// there, the source keeps whatever its artist left).
const float kAlphaBlended = -2.0;
bool alpha_blended() { return v_alpha_cutoff <= kAlphaBlended; }

// Anisotropic footprint: `taps` taps (the anisotropy ratio, rounded up, 1..kMaxTaps) along the
// major axis of the pixel's footprint; the LOD comes from the larger of the minor axis and the
// major axis over the tap count (each tap then covers its share of the footprint). `step` is
// the uv distance between taps.
struct Footprint {
  vec2 step;
  float lod;
  int taps;
};

// dx, dy: the pixel's derivatives in texels of level 0; texel: level 0's texel size in uv.
// The axes are the footprint ellipse's (the singular values of [dx dy]), not the lengths of dx
// and dy: where a UV map shears hard (a pole vertex shared by a whole fan, earthCylindrical.DAE;
// teapots.DAE's squeezed spout) dx and dy point almost the same way in the texture, and the
// shorter one's length taken as the minor axis blurred across the shear what the pixel sees
// sharp (12 dB against the pixel's supersampled box average in the pole's tile;
// docs/BENCHMARKS.md, "earthCylindrical's pole" and "Sheared footprints").
// Equal to the lengths where dx and dy are orthogonal.
Footprint footprint_texels(vec2 dx, vec2 dy, vec2 texel, float max_lod) {
  // J J^T = [a b; b c]; its eigenvalues are the squared axes.
  float a = dot(vec2(dx.x, dy.x), vec2(dx.x, dy.x));
  float b = dot(vec2(dx.x, dy.x), vec2(dx.y, dy.y));
  float c = dot(vec2(dx.y, dy.y), vec2(dx.y, dy.y));
  float half_sum = 0.5 * (a + c);
  float root = sqrt(max(0.25 * (a - c) * (a - c) + b * b, 0.0));
  float lmaj = sqrt(half_sum + root);
  // The minor axis from the area, which stays exact when the two axes differ by orders.
  float lmin = abs(dx.x * dy.y - dx.y * dy.x) / max(lmaj, 1e-12);
  // The major axis' direction: the eigenvector of the larger eigenvalue, from whichever row of
  // (J J^T - l I) is the longer (any direction where the footprint is round: one tap).
  float l1 = half_sum + root;
  vec2 e1 = vec2(b, l1 - a), e2 = vec2(l1 - c, b);
  vec2 e = dot(e1, e1) >= dot(e2, e2) ? e1 : e2;
  vec2 major = dot(e, e) > 0.0 ? normalize(e) * lmaj : vec2(lmaj, 0.0);
  Footprint f;
  f.taps = int(clamp(ceil(lmaj / max(lmin, 1e-6)), 1.0, float(kMaxTaps)));
  f.lod = clamp(log2(max(max(lmaj / float(f.taps), lmin), 1e-6)), 0.0, max_lod);
  f.step = major * texel / float(f.taps);
  return f;
}

Footprint footprint(vec2 uv, float deriv_scale) {
  return footprint_texels(dFdx(uv) * pc.tex.xy * deriv_scale, dFdy(uv) * pc.tex.xy * deriv_scale,
                          1.0 / pc.tex.xy, float(v_misc.z));
}

// A page file level's size in texels (runtime/page_table.h): level 0's (pc.tex.xy) halved with
// ceil, where Vulkan's mips halve with floor.
ivec2 vt_level_size(int level) {
  return max(ivec2(1), (ivec2(pc.tex.xy) + (1 << level) - 1) >> level);
}

vec2 tap_offset(Footprint f, int i) { return f.step * (float(i) - 0.5 * float(f.taps - 1)); }

vec2 tap_uv(vec2 uv, Footprint f, int i) {
  vec2 u = uv + tap_offset(f, i);
  if (v_misc.y == 2) return u;
  return v_misc.y == 1 ? fract(u) : clamp(u, 0.0, 1.0);
}
#endif  // VT_VERTEX_STAGE
