#pragma once
// `tetrasand sample --preview`: NAME.preview.png beside the body, the mesh's SDF ray-cast with the
// particles over it (the thesis's figure 6.13), from the iso view, +z up unless told otherwise.
#include <filesystem>
#include <string>
#include <vector>

#include "body/particle_body.h"
#include "core/mesh.h"
#include "gpu/context.h"
#include "sdf/settings.h"

namespace ts::preview {

struct BodyPreviewSettings {
  int width = 800, height = 800;  // pixels
  int resolution = 192;           // SDF voxels along the mesh's longest side
  Eigen::Vector3d up = Eigen::Vector3d::UnitZ();  // the mesh's up (sample --up), +z by convention
  // The body's own sign method (sample --sign): an open mesh sampled by winding number previews by it too.
  sdf::SignMethod sign = sdf::SignMethod::Pseudonormal;
};

// What the picture showed, for the command's report.
struct BodyPreviewReport {
  bool field_drawn = true;  // false: the field read inside at its box's corner (SdfVolume::inside_out), not drawn
  double seconds = 0.0;     // s, wall time: the field, the drawing and the PNG
  std::string gpu_path;     // on the GPU: the path taken and why (preview/path_calibration.h); empty on the CPU
};

// Scan-converts `mesh` on `context`'s device and renders it there with `body`'s particles, or with a
// null context builds the exact SDF and renders on the CPU (preview/cpu_renderer.h); on the GPU the
// shadow map and G-buffer take the calibrated --gpu-path auto choice (preview/path_calibration.h); writes `png`
// atomically, never over one of `inputs`. A field whose signs flood its box is left out (the particles
// alone), never drawn as a box.
BodyPreviewReport write_body_preview(gpu::Context* context, const TriangleMesh& mesh, const body::ParticleBody& body,
                        const std::filesystem::path& png, const std::vector<std::filesystem::path>& inputs = {},
                        const BodyPreviewSettings& settings = {});

}  // namespace ts::preview
