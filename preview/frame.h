#pragma once
// What both preview renderers (the GL one, preview/renderer.h, and the CPU one, preview/cpu_renderer.h)
// plan the same way before drawing a frame: the scene's bounding sphere, the camera relative to its
// centre, the key light and its orthographic shadow camera, the ground plane and the backdrop. One
// plan, so both draw the same picture from the same settings.
#include <Eigen/Core>
#include <optional>
#include <vector>

#include "core/mesh.h"
#include "preview/camera.h"
#include "preview/image_renderer.h"

namespace ts::preview {

// A camera as the passes see it: relative to the scene origin.
struct CameraState {
  Eigen::Matrix4d view_projection, inverse;  // world (relative) -> clip, and back
  Eigen::Vector3d eye, forward, right, up;   // eye relative to the origin [m]; unit axes
  bool ortho = false;
  int width = 0, height = 0;  // pixels (texels for the shadow camera)
};

CameraState camera_state(const Camera& camera, int width, int height, const Eigen::Vector3d& origin, double radius);

// The backdrop's colours (sRGB): a vertical gradient, and the ground plane's.
inline const Eigen::Vector3f kBackgroundTop{0.97f, 0.97f, 0.98f};
inline const Eigen::Vector3f kBackgroundBottom{0.80f, 0.82f, 0.86f};
inline const Eigen::Vector3f kGroundColor{0.88f, 0.88f, 0.87f};

// What every pass of one frame reads: the scene's bounding sphere, the cameras, light and ground.
struct Frame {
  Aabb content;               // what is drawn [m, world]
  Eigen::Vector3d origin;     // the sphere's centre; positions are drawn relative to it [m, world]
  double radius = 0.0;        // everything drawn lies within it [m]
  CameraState camera;         // the image's
  Eigen::Vector3d up, light;  // unit, world; `light` points towards the key light
  double ground_level = 0.0;  // the ground plane along `up`, relative to origin [m]
  Eigen::Vector3d ground_center;  // below the content's centre on the ground plane, relative [m]
  double ground_fade = 0.0;   // the ground fades out this far from ground_center [m]
  int shadow_size = 0;        // shadow-map texels per side; 0 without shadows
  CameraState light_camera;   // with shadows: orthographic along the light, holding the sphere
  double shadow_texel = 0.0;  // with shadows: one shadow-map texel [m]
  double shadow_bias = 0.0;   // with shadows: one texel of light depth (window units, 0..1)
};

// The box of the particle spheres [m, world] (invalid for none), after checking them: ts::InputError
// for a radius count other than 1 or n, a colour count other than 0 or n, or a particle with a
// non-finite centre or a radius that is not positive.
Aabb particle_box(const Particles& particles);

// What a renderer draws, for framing: the surface's box (when there is a surface) joined with the
// particles' (when valid).
Aabb content_box(const std::optional<Aabb>& surface, const Aabb& particles);

// The key light's default direction: from the upper left, behind the camera, about 50 degrees above
// the ground plane, turning with the camera about `up`.
Eigen::Vector3d default_light(const Camera& camera, const Eigen::Vector3d& up);

// Checks the settings (ts::InputError for a bad camera, up vector, light or colour map, or an
// invalid `content`, nothing to draw) and plans the frame of `content` (the surface and the
// particles); `volume_box`, when there is an SDF, joins the bounding sphere. The shadow map is at
// most `max_texture` texels a side.
Frame plan_frame(const RenderSettings& settings, const Aabb& content, const std::optional<Aabb>& volume_box,
                 int max_texture);

// The surface scalar over one image: `values` per pixel, NaN where no surface was coloured (both
// renderers fill them so); count, mean and maximum of the others (all 0 for none).
ScalarSummary summarize_scalar(const std::vector<double>& values);

}  // namespace ts::preview
