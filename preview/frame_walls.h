#pragma once
// The walls of a scene as the PNG frames of `tetrasand sim` show them (preview/sim_frames.h): what of
// them the default camera frames, their outlines, and where a view ray meets the far side of a box or
// cylinder, so the frame can tint it faintly behind the grains. Boxes and cylinders are drawn whole;
// a plane is clipped to the content's box (the grains'), and a floor
// (normal within 25 degrees of +z) is left to the renderer's ground plane.
#include <Eigen/Core>
#include <optional>
#include <vector>

#include "core/mesh.h"
#include "preview/camera.h"
#include "preview/image.h"
#include "preview/renderer.h"
#include "scene/scene.h"

namespace ts::preview {

struct Segment {
  Eigen::Vector3d a, b;  // m, world
};

class FrameWalls {
 public:
  explicit FrameWalls(const scene::Scene& scene);

  // What the default camera frames of the walls around `content` (m): each box's and cylinder's
  // footprint, from its floor up to its top or the content's top, whichever is lower (a tall box
  // holding a shallow bed is framed around the bed), and each plane clipped to `content` widened by
  // 5 % of its diagonal (so that a plane bounding the grains cuts it).
  Aabb framing_box(const Aabb& content) const;

  // The edges of the boxes, the rims of each cylinder, the outline of each non-floor plane clipped as
  // in framing_box (m, world).
  std::vector<Segment> outlines(const Aabb& content) const;

  // The distance along a view ray (origin, unit direction) to the far inside of a box's side wall or
  // a cylinder's wall: the walls seen behind the grains. None when the ray meets no such wall.
  std::optional<double> far_wall(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction) const;

  // The lowest floor plane's height (m along +z), if the scene has one.
  std::optional<double> floor_level() const { return floor_level_; }

  bool empty() const { return boxes_.empty() && cylinders_.empty() && planes_.empty(); }

 private:
  std::vector<scene::Boundary> boxes_, cylinders_, planes_;  // planes: the non-floor ones
  std::optional<double> floor_level_;
};

// The corners of the polygon where the plane (point, unit normal) cuts the box, in order around it;
// empty when it misses.
std::vector<Eigen::Vector3d> clip_plane(const Eigen::Vector3d& point, const Eigen::Vector3d& normal,
                                        const Aabb& box);

// Draws the walls into a rendered frame (perspective `camera`), faintly: the far walls tinted over
// the background (the pixels `layers` marks Background, where the wall is nearer than the ground at
// `ground_level`), the outlines in `color` over the background and translucent over grains and props.
struct WallStyle {
  Eigen::Vector3f color{0.30f, 0.46f, 0.62f};  // sRGB, outlines
  float tint = 0.22f;                          // opacity of the far walls' tint
  float over_content = 0.35f;                  // opacity of outlines drawn over grains and props
};
void draw_walls(Image& image, const std::vector<Layer>& layers, const Camera& camera, const FrameWalls& walls,
                const Aabb& content, std::optional<double> ground_level, const WallStyle& style = {});

}  // namespace ts::preview
