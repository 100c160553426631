#pragma once
// The preview camera: a pinhole (vertical field of view) or orthographic lens looking from `eye` at
// `target`, named views relative to a world up axis, automatic framing of a bounding box, and the
// OpenGL view and projection matrices (double precision; the renderer converts them to float
// relative to the scene centre, so large coordinates cost no precision).
#include <Eigen/Core>
#include <string>
#include <vector>

#include "core/mesh.h"

namespace ts::preview {

enum class View { Front, Side, Top, Iso };

// "front", "side", "top", "iso"; ts::InputError otherwise.
View parse_view(const std::string& name);

// Views relative to the world up axis u. Front looks from the front axis f (+z for a y-up world, -y
// for a z-up world; in general the world axis among +z, -y most perpendicular to u, made
// perpendicular to it); side from s = u x f; top from u, with f at the bottom of the image; iso from
// f + s + u. Returns the unit direction from the target towards the eye.
Eigen::Vector3d view_direction(View view, const Eigen::Vector3d& up);
// The image's up direction for a view (the world up, except for top: -f).
Eigen::Vector3d view_image_up(View view, const Eigen::Vector3d& up);
// The unit direction from the target towards the eye, `azimuth` degrees from the front axis f towards
// the side axis s (those of view_direction) and `elevation` degrees above the horizon of the world up
// axis u. The iso view is azimuth 45, elevation atan(1 / sqrt 2) = 35.26 degrees.
Eigen::Vector3d view_direction(double azimuth, double elevation, const Eigen::Vector3d& up);

struct Camera {
  Eigen::Vector3d eye{0.0, 0.0, 1.0};     // m
  Eigen::Vector3d target{0.0, 0.0, 0.0};  // m
  Eigen::Vector3d up{0.0, 1.0, 0.0};      // image up, need not be perpendicular to the view
  double fov_y = 30.0;                    // degrees, vertical field of view (perspective)
  bool ortho = false;
  double ortho_height = 1.0;  // m, the visible height (orthographic)

  Eigen::Vector3d forward() const;   // unit, eye -> target
  Eigen::Vector3d right() const;     // unit
  Eigen::Vector3d image_up() const;  // unit, perpendicular to forward
};

// Checks a user's camera: finite values, eye != target, up not parallel to the view, 0 < fov < 180,
// ortho_height > 0. ts::InputError naming the problem.
void validate(const Camera& camera);

// Looks at the box's centre from direction `from` (unit, target -> eye) with image up `up`, as close
// as it can while every corner of the box stays inside the image (times `margin`). With
// turntable_frames > 1 the distance fits all the orbits about `orbit_axis` that orbit() makes.
Camera frame_box(const Aabb& box, const Eigen::Vector3d& from, const Eigen::Vector3d& up, double aspect,
                 bool ortho, double fov_y, int turntable_frames = 1,
                 const Eigen::Vector3d& orbit_axis = Eigen::Vector3d::UnitZ(), double margin = 1.08);

// A perspective camera looking along -from with image up `up` that holds every point of `points` inside
// the image (times `margin`) as closely as it can: unlike frame_box, the target need not be the box's
// centre, so a near corner that projects larger does not leave the far side empty. The eye's distance
// is solved exactly (the nearest the frustum's side planes allow, per image axis); across the view the
// eye is then placed so that the points' projections are centred in both image axes.
Camera frame_points(const std::vector<Eigen::Vector3d>& points, const Eigen::Vector3d& from,
                    const Eigen::Vector3d& up, double aspect, double fov_y, double margin = 1.08);
// Its corners, framed by frame_points.
Camera frame_box_tightly(const Aabb& box, const Eigen::Vector3d& from, const Eigen::Vector3d& up,
                         double aspect, double fov_y, double margin = 1.08);

// The camera rotated about the axis through its target (right-handed, radians): turntables.
Camera orbit(const Camera& camera, const Eigen::Vector3d& axis, double angle);

struct ViewMatrices {
  Eigen::Matrix4d view = Eigen::Matrix4d::Identity();        // world -> eye space (OpenGL: looks down -z)
  Eigen::Matrix4d projection = Eigen::Matrix4d::Identity();  // eye -> clip, depth -1..1
  double near = 0.0, far = 1.0;                              // m, along forward
};

// Matrices for an image of aspect width / height, with near and far planes hugging the sphere
// (center, radius) that bounds everything drawn.
ViewMatrices view_matrices(const Camera& camera, double aspect, const Eigen::Vector3d& center, double radius);

}  // namespace ts::preview
