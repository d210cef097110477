#version 450
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"
#define LIT_FRAME_BINDING 5
#include "lit.glsl"
#include "virtual_texture.glsl"

// Lit virtual texture: albedo, normal, ORM and emissive from their layers' physical caches, all
// addressed through the one page table (every layer shares the page grid and slots) with the
// taps and trilinear blend of virtual.frag (virtual_texture.glsl addresses the pages). The baked
// normal is in the atlas tangent frame
// (bake/transfer.cpp): tangent along +u of the atlas, bitangent up the atlas image.
layout(set = 0, binding = 0) uniform usampler2D u_page_table;
layout(set = 0, binding = 1) uniform sampler2D u_albedo;
layout(set = 0, binding = 2) uniform sampler2D u_normal;
layout(set = 0, binding = 3) uniform sampler2D u_orm;
layout(set = 0, binding = 4) uniform sampler2D u_emissive;

layout(location = 0) in vec2 v_uv;
layout(location = 2) in vec3 v_normal;
layout(location = 4) in vec3 v_world;
layout(location = 0) out vec4 out_color;
layout(location = 1) out uint out_status;

struct Inputs {
  vec4 albedo, normal, orm, emissive;
};

// One bilinear tap of every cache at `uv` in `level` (the resident ancestor where the page is
// not in the cache).
Inputs sample_level(vec2 uv, int level, inout int sampled) {
  vec2 phys;
  Inputs r;
  if (!vt_physical(u_page_table, uv, level, phys, sampled)) {
    r.albedo = r.emissive = vec4(1.0, 0.0, 1.0, 1.0);  // nothing resident at all: a loud colour
    r.normal = r.orm = vec4(0.5);
    return r;
  }
  phys /= vec2(textureSize(u_albedo, 0));
  // Only the inputs this frame shades with (uniform branches): the emissive-only frame reads two
  // caches of four.
  r.albedo = textureLod(u_albedo, phys, 0.0);
  r.normal = (v_misc.w & kLitNormal) != 0 ? textureLod(u_normal, phys, 0.0) : vec4(0.5);
  r.orm = (v_misc.w & kLitOrm) != 0 ? textureLod(u_orm, phys, 0.0) : vec4(0.0);
  r.emissive = (v_misc.w & kLitEmissive) != 0 ? textureLod(u_emissive, phys, 0.0) : vec4(0.0);
  return r;
}

void main() {
  // The atlas frame from the triangle's position and atlas-UV derivatives (flat per triangle,
  // as the transfer's per-triangle gradients).
  vec3 dpx = dFdx(v_world), dpy = dFdy(v_world);
  vec2 dux = dFdx(v_uv), duy = dFdy(v_uv);
  Footprint f = footprint(v_uv, 1.0);
  int l0 = int(floor(f.lod));
  int l1 = min(l0 + 1, v_misc.z);
  float blend = f.lod - float(l0);
  int sampled = 0, ignored = 0;
  Inputs c = Inputs(vec4(0.0), vec4(0.0), vec4(0.0), vec4(0.0));
  for (int i = 0; i < f.taps; ++i) {
    vec2 uv = tap_uv(v_uv, f, i);
    Inputs a = sample_level(uv, l0, sampled);
    Inputs b = l1 != l0 ? sample_level(uv, l1, ignored) : a;
    c.albedo += mix(a.albedo, b.albedo, blend);
    c.normal += mix(a.normal, b.normal, blend);
    c.orm += mix(a.orm, b.orm, blend);
    c.emissive += mix(a.emissive, b.emissive, blend);
  }
  vec4 albedo = c.albedo / float(f.taps);
  if (v_alpha_cutoff >= 0.0 && albedo.a < v_alpha_cutoff) discard;

  vec3 n = normalize(v_normal);
  vec3 shading = n;
  if ((v_misc.w & kLitNormal) != 0) {
    float det = dux.x * duy.y - dux.y * duy.x;
    vec3 dpdu = (dpx * duy.y - dpy * dux.y) * sign(det);
    vec3 dpdv = (dpy * dux.x - dpx * duy.x) * sign(det);
    vec3 t = dpdu - n * dot(n, dpdu);
    t = dot(t, t) > 1e-20 ? normalize(t)
                          : normalize(cross(abs(n.x) < 0.9 ? vec3(1, 0, 0) : vec3(0, 1, 0), n));
    vec3 b = cross(n, t) * (dot(cross(n, t), dpdv) > 0.0 ? -1.0 : 1.0);
    vec3 tn = decode_normal_xy(c.normal.xy / float(f.taps));
    shading = normalize(t * tn.x + b * tn.y + n * tn.z);
  }
  if (dot(n, lit.eye.xyz - v_world) < 0.0) shading = -shading;
  if (lit_normals_frame()) {
    out_color = lit_normal_detail(shading, n, v_world);
    out_status = 0x80000000u | uint(l0) | (uint(sampled) << 8);
    return;
  }
  vec3 orm = (v_misc.w & kLitOrm) != 0 ? c.orm.rgb / float(f.taps) : kLitDefaultOrm;
  vec3 emissive =
      (v_misc.w & kLitEmissive) != 0 ? srgb_to_linear3(c.emissive.rgb / float(f.taps)) : vec3(0.0);
  vec3 lin = shade(v_world, shading, srgb_to_linear3(albedo.rgb), orm, emissive);
  out_color = vec4(linear_to_srgb3(alpha_blended() ? lin * albedo.a : lin), 1.0);
  out_status = 0x80000000u | uint(l0) | (uint(sampled) << 8);
}
