#version 450
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"
#define LIT_FRAME_BINDING 5
#include "lit.glsl"

// Lit reference: the original materials under the bake's rules (scene/material_rules.h): each
// texture on its own UV set through its own KHR_texture_transform (the vertex's tex_uv) and its
// own per-axis sampler. Albedo as reference.frag; the normal map decoded in the mesh's tangent
// frame (the frame the bake's transfer decodes it in); occlusion, roughness and metallic with the
// material's factors applied; emissive texture times factor x strength.
// Per draw: vt.xyz emissive factor x strength and vt.w normal scale (float bits); misc.x bit 0:
// the material has a normal map, bit 1: a two-channel one (z reconstructed).
layout(set = 0, binding = 0) uniform sampler2D u_albedo;
layout(set = 0, binding = 1) uniform sampler2D u_normal;
layout(set = 0, binding = 2) uniform sampler2D u_orm;
layout(set = 0, binding = 3) uniform sampler2D u_emissive;
layout(set = 0, binding = 4) uniform sampler2D u_occlusion;

layout(location = 0) in vec2 v_uv;
layout(location = 1) in vec4 v_color;  // vertex colour (linear), as reference.frag applies it
layout(location = 2) in vec3 v_normal;
layout(location = 3) in vec4 v_tangent;
layout(location = 4) in vec3 v_world;
layout(location = 5) in vec4 v_tex_uv01;  // normal, occlusion
layout(location = 6) in vec4 v_tex_uv23;  // metallic-roughness, emissive
layout(location = 0) out vec4 out_color;
layout(location = 1) out uint out_covered;

// common.glsl's anisotropic taps in the texture's own texel size and level count.
vec4 sample_taps(sampler2D t, vec2 uv) {
  vec2 size = vec2(textureSize(t, 0));
  Footprint f = footprint_texels(dFdx(uv) * size, dFdy(uv) * size, 1.0 / size,
                                 float(textureQueryLevels(t) - 1));
  vec4 c = vec4(0.0);
  for (int i = 0; i < f.taps; ++i) c += textureLod(t, uv + tap_offset(f, i), f.lod);
  return c / float(f.taps);
}

void main() {
  Footprint f = footprint(v_uv, 1.0);
  vec4 albedo = vec4(0.0);
  for (int i = 0; i < f.taps; ++i) albedo += textureLod(u_albedo, tap_uv(v_uv, f, i), f.lod);
  albedo /= float(f.taps);
  albedo.a *= v_color.a;
  if (v_alpha_cutoff >= 0.0 && albedo.a < v_alpha_cutoff) discard;
  // Only the inputs this frame shades with (uniform branches).
  const bool normal_in = (v_misc.w & kLitNormal) != 0, orm_in = (v_misc.w & kLitOrm) != 0;
  vec4 tn = normal_in ? sample_taps(u_normal, v_tex_uv01.xy) : vec4(0.5, 0.5, 1.0, 1.0);
  float occlusion = orm_in ? sample_taps(u_occlusion, v_tex_uv01.zw).r : 1.0;
  vec4 tmr = orm_in ? sample_taps(u_orm, v_tex_uv23.xy) : vec4(0.0);
  vec4 te = (v_misc.w & kLitEmissive) != 0 ? sample_taps(u_emissive, v_tex_uv23.zw) : vec4(0.0);

  vec3 n = normalize(v_normal);
  vec3 shading = n;
  if ((v_misc.w & kLitNormal) != 0 && (v_misc.x & 1) != 0) {
    vec3 t = v_tangent.xyz - n * dot(n, v_tangent.xyz);
    t = dot(t, t) > 1e-12 ? normalize(t) : normalize(cross(abs(n.x) < 0.9 ? vec3(1, 0, 0) : vec3(0, 1, 0), n));
    vec3 b = cross(n, t) * (v_tangent.w < 0.0 ? -1.0 : 1.0);
    float scale = intBitsToFloat(pc.vt.w);
    vec2 xy = (tn.xy * 2.0 - 1.0) * scale;
    float z = (v_misc.x & 2) != 0 ? sqrt(max(0.0, 1.0 - dot(xy, xy))) : tn.z * 2.0 - 1.0;
    vec3 w = t * xy.x + b * xy.y + n * z;
    shading = dot(w, w) > 1e-12 ? normalize(w) : n;
  }
  // Back faces (open or two-sided surfaces) are lit as seen.
  if (dot(n, lit.eye.xyz - v_world) < 0.0) shading = -shading;
  if (lit_normals_frame()) {
    out_color = lit_normal_detail(shading, n, v_world);
    out_covered = 1u;
    return;
  }
  vec3 orm = (v_misc.w & kLitOrm) != 0 ? vec3(occlusion, tmr.gb) : kLitDefaultOrm;
  vec3 emissive = vec3(0.0);
  if ((v_misc.w & kLitEmissive) != 0) {
    emissive = srgb_to_linear3(te.rgb) *
               vec3(intBitsToFloat(pc.vt.x), intBitsToFloat(pc.vt.y), intBitsToFloat(pc.vt.z));
  }
  vec3 c = shade(v_world, shading, srgb_to_linear3(albedo.rgb) * v_color.rgb, orm, emissive);
  out_color = vec4(linear_to_srgb3(alpha_blended() ? c * albedo.a : c), 1.0);
  out_covered = 1u;
}
