// Page-table addressing shared by every pass that reads the virtual texture (virtual.frag,
// lit_virtual.frag, feedback.frag), so that all of them agree on which page and texel a tap
// reads. Include after common.glsl. The page table is the RGBA8 mip chain of runtime/: R, G =
// physical slot, B = resident level, A bit 0 = valid.

// The page of `level` holding `uv`.
ivec2 vt_page(vec2 uv, int level) {
  ivec2 pages = (vt_level_size(level) + pc.vt.y - 1) / pc.vt.y;
  return clamp(ivec2(floor(uv * vec2(vt_level_size(level)) / float(pc.vt.y))), ivec2(0), pages - 1);
}

// Set by vt_physical when a bilinear tap reads a page's border texels: those are the page's own
// encoding of its neighbour's texels, so they may differ from the neighbour's payload by the
// codec's error (the exact check bounds such pixels apart).
bool vt_border_read = false;
bool vt_coarse_fallback = false;

// Where the texel at `uv` of `level` lies in the physical cache, in texels: the resident
// ancestor's slot where the page itself is not in the cache. False when nothing is resident
// (`sampled` set to 31); otherwise `sampled` is raised to the level actually read.
bool vt_physical(usampler2D table, vec2 uv, int level, out vec2 phys, inout int sampled) {
  ivec2 page = vt_page(uv, level);
  uvec4 e = texelFetch(table, page, level);
  if ((e.a & 1u) == 0u) {
    sampled = 31;
    phys = vec2(0.0);
    return false;
  }
  int resident = int(e.b);
  // The slot holds the ancestor page; address its texels in the resident level.
  ivec2 rpage = page >> max(resident - level, 0);
  float payload = float(pc.vt.y);
  vec2 local = uv * vec2(vt_level_size(resident)) - vec2(rpage) * payload;
  if (any(lessThan(local, vec2(0.5))) || any(greaterThan(local, vec2(payload - 0.5))))
    vt_border_read = true;
  float lo = 0.5 - float(pc.vt.z);
  local = clamp(local, vec2(lo), vec2(payload - lo));
  phys = vec2(e.rg) * float(pc.vt.w) + float(pc.vt.z) + local;
  sampled = max(sampled, resident);
  return true;
}

// One bilinear tap of `cache` at `uv` in `level` through the page table; a loud colour where
// nothing is resident.
vec4 vt_sample_level(sampler2D cache, usampler2D table, vec2 uv, int level, inout int sampled) {
  vec2 phys;
  if (!vt_physical(table, uv, level, phys, sampled)) return vec4(1.0, 0.0, 1.0, 1.0);
  return textureLod(cache, phys / vec2(textureSize(cache, 0)), 0.0);
}

// The filtered virtual-texture colour at `uv`: common.glsl's anisotropic taps, each trilinear as
// two levels and a blend. `sampled`: the coarsest level a tap of the finer level read;
// vt_coarse_fallback: a tap of the coarser level read an ancestor of its page (a fallback too).
vec4 vt_filtered(sampler2D cache, usampler2D table, vec2 uv, Footprint f, out int sampled) {
  int l0 = int(floor(f.lod));
  int l1 = min(l0 + 1, v_misc.z);
  float blend = f.lod - float(l0);
  sampled = 0;
  int coarse = l1;
  vec4 c = vec4(0.0);
  for (int i = 0; i < f.taps; ++i) {
    vec2 t = tap_uv(uv, f, i);
    vec4 a = vt_sample_level(cache, table, t, l0, sampled);
    vec4 b = l1 != l0 ? vt_sample_level(cache, table, t, l1, coarse) : a;
    c += mix(a, b, blend);
  }
  if (coarse > l1 && blend > 0.0) vt_coarse_fallback = true;
  return c / float(f.taps);
}
