// Shared by the two lit passes (lit_reference.frag, lit_virtual.frag): one metal-roughness
// shading, so that the two renders differ only in where their inputs come from. Include after
// common.glsl and after defining LIT_FRAME_BINDING.
//
// Push constants as common.glsl, plus misc.w: which inputs come from the materials or layers
// (kLitNormal, kLitOrm, kLitEmissive; an input not set takes the same fixed value on both paths)
// and kLitNormalsFrame.

const int kLitNormal = 1;
const int kLitOrm = 2;
const int kLitEmissive = 4;
const int kLitNormalsFrame = 8;

// The lights of one view (world space): the key and fill lights' directions towards the light
// (w: intensity), fixed relative to the camera so that every view is lit; eye.w: ambient.
layout(set = 0, binding = LIT_FRAME_BINDING) uniform LitFrame {
  vec4 eye;
  vec4 key;
  vec4 fill;
}
lit;

// A normals frame writes the normal map's detail instead of a colour: the shading normal minus
// the interpolated vertex normal `n` (both facing the eye), * 0.5 + 0.5 (render/normal_check.h).
bool lit_normals_frame() { return (v_misc.w & kLitNormalsFrame) != 0; }
vec4 lit_normal_detail(vec3 shading, vec3 n, vec3 world) {
  vec3 g = dot(n, lit.eye.xyz - world) < 0.0 ? -n : n;
  return vec4((shading - g) * 0.5 + 0.5, 1.0);
}

vec3 srgb_to_linear3(vec3 c) {
  return mix(c / 12.92, pow((c + 0.055) / 1.055, vec3(2.4)), greaterThan(c, vec3(0.04045)));
}

vec3 linear_to_srgb3(vec3 c) {
  c = clamp(c, 0.0, 1.0);
  return mix(c * 12.92, 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, greaterThan(c, vec3(0.0031308)));
}

// Unit normal from tangent-space XY in [0, 1] (n * 0.5 + 0.5), z reconstructed.
vec3 decode_normal_xy(vec2 xy) {
  vec2 n = xy * 2.0 - 1.0;
  return vec3(n, sqrt(max(0.0, 1.0 - dot(n, n))));
}

// GGX specular (Smith-Schlick visibility, Schlick Fresnel) and Lambert diffuse per light.
vec3 light_term(vec3 n, vec3 v, vec3 l, vec3 diffuse, vec3 f0, float a2) {
  float nl = max(dot(n, l), 0.0);
  if (nl <= 0.0) return vec3(0.0);
  vec3 h = normalize(l + v);
  float nv = max(dot(n, v), 1e-4);
  float nh = max(dot(n, h), 0.0);
  float d = a2 / (3.14159265 * pow(nh * nh * (a2 - 1.0) + 1.0, 2.0));
  float k = sqrt(a2) * 0.5;
  float vis = 0.25 / ((nl * (1.0 - k) + k) * (nv * (1.0 - k) + k));
  vec3 f = f0 + (1.0 - f0) * pow(1.0 - max(dot(v, h), 0.0), 5.0);
  return (diffuse * (1.0 - f) + f * d * vis) * nl;
}

// Linear colour of a surface point: `n` the shading normal, `orm` occlusion, roughness,
// metallic, `emissive` linear.
vec3 shade(vec3 world, vec3 n, vec3 albedo, vec3 orm, vec3 emissive) {
  vec3 v = normalize(lit.eye.xyz - world);
  float rough = clamp(orm.y, 0.05, 1.0);
  float a2 = rough * rough * rough * rough;
  vec3 f0 = mix(vec3(0.04), albedo, orm.z);
  vec3 diffuse = albedo * (1.0 - orm.z);
  vec3 c = lit.key.w * light_term(n, v, normalize(lit.key.xyz), diffuse, f0, a2) +
           lit.fill.w * light_term(n, v, normalize(lit.fill.xyz), diffuse, f0, a2);
  c += lit.eye.w * orm.x * (diffuse + f0);
  return c + emissive;
}

// The lit inputs that are not set on this pass.
const vec3 kLitDefaultOrm = vec3(1.0, 0.5, 0.0);
