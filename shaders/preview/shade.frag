#version 450
#extension GL_GOOGLE_include_directive : require
// Lighting pass over the G-buffer (thesis 5.2): one directional key light with Lambert diffuse and
// Blinn-Phong specular, its shadow map sampled with 3x3 percentage-closer filtering, a hemisphere
// ambient term, ambient occlusion from the SDF on the ray-cast surface, and a ground plane under
// the scene that catches the shadows. Colours are sRGB in and out, lit in linear light.
#include "preview/bindings.h"
#include "preview/camera.glsl"
#include "preview/look.h"
#include "preview/volume.glsl"

layout(binding = TS_PREVIEW_UNIT_ALBEDO) uniform sampler2D albedo_texture;
layout(binding = TS_PREVIEW_UNIT_NORMAL) uniform sampler2D normal_texture;
layout(binding = TS_PREVIEW_UNIT_DEPTH) uniform sampler2D depth_texture;
layout(binding = TS_PREVIEW_UNIT_SHADOW) uniform sampler2DShadow shadow_map;
#include "common/params.h"
layout(std140, binding = TS_PREVIEW_PARAMS) uniform ShadeBlock { ShadeParams params; };


out vec4 color;

vec3 to_linear(vec3 c) { return pow(c, vec3(TS_PREVIEW_GAMMA)); }
vec3 to_srgb(vec3 c) { return pow(clamp(c, 0.0, 1.0), vec3(1.0 / TS_PREVIEW_GAMMA)); }

// 1 lit .. 0 in shadow. The point is pushed along its normal by two texels against acne.
float light_visibility(vec3 p, vec3 n) {
  if (params.flags.x == 0) return 1.0;
  vec4 c = params.light_view_projection * vec4(p + n * (TS_PREVIEW_SHADOW_OFFSET_TEXELS * params.shadow.x), 1.0);
  vec3 s = 0.5 * c.xyz / c.w + 0.5;
  if (any(lessThan(s.xy, vec2(0.0))) || any(greaterThan(s.xy, vec2(1.0)))) return 1.0;
  float ref = min(s.z, 1.0) - params.shadow.y;
  float lit = 0.0;
  for (int y = -1; y <= 1; ++y)
    for (int x = -1; x <= 1; ++x) lit += texture(shadow_map, vec3(s.xy + vec2(x, y) * params.shadow.zw, ref));
  return lit / 9.0;
}

// Ambient occlusion of the ray-cast surface: how much the SDF, sampled outward along the normal,
// falls short of the distance travelled (the surface's own neighbourhood closing in).
float surface_occlusion(vec3 p, vec3 n) {
  if (params.flags.y == 0) return 1.0;
  vec3 u = to_voxel(p);
  float occlusion = 0.0, weight = 0.5;
  for (int k = 1; k <= 4; ++k) {
    float delta = 0.25 * float(k) * volume.dims_band.w;
    occlusion += weight * clamp((delta - sdf_at(u + n * delta)) / delta, 0.0, 1.0);
    weight *= 0.5;
  }
  return clamp(1.0 - TS_PREVIEW_OCCLUSION_GAIN * occlusion, 0.0, 1.0);
}

vec3 lit(vec3 base, vec3 p, vec3 n, vec3 view, float specular, float occlusion) {
  float visibility = light_visibility(p, n);
  float diffuse = max(dot(n, params.light_dir.xyz), 0.0);
  vec3 h = normalize(params.light_dir.xyz + view);
  float spec = diffuse > 0.0 ? specular * pow(max(dot(n, h), 0.0), TS_PREVIEW_SPECULAR_POWER) : 0.0;
  float ambient = mix(TS_PREVIEW_AMBIENT_DOWN, TS_PREVIEW_AMBIENT_UP, 0.5 + 0.5 * dot(n, params.world_up.xyz));
  float fill = TS_PREVIEW_CAMERA_FILL * max(dot(n, view), 0.0);  // a weak light from the camera keeps shadows readable
  return base * ((ambient + fill) * occlusion + TS_PREVIEW_DIFFUSE * diffuse * visibility) + vec3(spec * visibility);
}

void main() {
  ivec2 pixel = ivec2(gl_FragCoord.xy);
  vec4 nl = texelFetch(normal_texture, pixel, 0);
  int layer = int(nl.w + 0.5);
  vec3 near_point = world_from_window(gl_FragCoord.xy, 0.0);
  vec3 far_point = world_from_window(gl_FragCoord.xy, 1.0);
  vec3 ray = normalize(far_point - near_point);

  if (layer != TS_PREVIEW_LAYER_BACKGROUND) {
    vec3 p = world_from_window(gl_FragCoord.xy, texelFetch(depth_texture, pixel, 0).r);
    vec3 n = normalize(nl.xyz);
    vec3 base = to_linear(texelFetch(albedo_texture, pixel, 0).rgb);
    bool surface = layer == TS_PREVIEW_LAYER_SURFACE;
    float specular = surface ? TS_PREVIEW_SPECULAR_SURFACE : TS_PREVIEW_SPECULAR_PARTICLE;
    vec3 c = lit(base, p, n, -ray, specular, surface ? surface_occlusion(p, n) : 1.0);
    color = vec4(to_srgb(c), 1.0);
    return;
  }

  float height = gl_FragCoord.y / camera.viewport.y;
  vec3 sky = mix(params.background_bottom.xyz, params.background_top.xyz, height);
  color = params.flags.w == 1 ? vec4(0.0) : vec4(sky, 1.0);
  float along = dot(params.world_up.xyz, ray);
  if (params.flags.z == 0 || along >= 0.0) return;
  float t = (params.ground.w - dot(params.world_up.xyz, near_point)) / along;
  if (t <= 0.0) return;
  vec3 g = near_point + t * ray;
  float fade_radius = params.ground_color.w;
  float fade = 1.0 - smoothstep(TS_PREVIEW_GROUND_FADE_START * fade_radius, fade_radius, length(g - params.ground.xyz));
  if (fade <= 0.0) return;
  float visibility = light_visibility(g, params.world_up.xyz);
  if (params.flags.w == 1) {
    color = vec4(0.0, 0.0, 0.0, TS_PREVIEW_GROUND_SHADOW_ALPHA * fade * (1.0 - visibility));
  } else {
    vec3 base = to_linear(params.ground_color.xyz);
    float diffuse = max(dot(params.world_up.xyz, params.light_dir.xyz), 0.0);
    vec3 c = base * (TS_PREVIEW_GROUND_AMBIENT + TS_PREVIEW_GROUND_DIFFUSE * diffuse * visibility);
    color = vec4(mix(sky, to_srgb(c), fade), 1.0);
  }
}
