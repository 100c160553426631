#pragma once
// What `tetrasand preview --json` prints: the inputs, the PNGs written, the image, where it was drawn
// and the renderer's per-pass times, as one JSON object (docs/schemas/preview-report.schema.json).
// app/cmd_preview.cpp fills a PreviewReport from its run; the JSON is made here.
#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "preview/image_renderer.h"

namespace ts::app {

struct PreviewReport {
  std::string field_input;                     // the MESH, SDF.vdb or SDF.nvdb given; empty: none
  std::string particles_input;                 // --particles; empty: none
  std::vector<std::filesystem::path> outputs;  // every PNG written, in view order
  int width = 0, height = 0;                   // pixels of one view
  int views = 1;                               // --turntable
  bool contact_sheet = false;
  std::string requested_backend, backend, device;  // --backend, the one chosen, the renderer's device
  std::string gpu_path;  // on the GPU: the --gpu-path taken and why ("compute (asked for)"); empty on the CPU
  std::string field;        // what the SDF is (dimensions, voxel, band); empty without one
  double voxel_size = 0.0;  // m, of the SDF (0 without one)
  std::size_t particles = 0;
  double particle_radius = 0.0;  // m, as drawn (0 without particles)
  std::string radius_source;     // where that radius came from
  std::string colour_by = "none";
  std::size_t colour_pixels = 0;  // surface pixels coloured, all views
  double colour_mean = 0.0, colour_max = 0.0, colour_map_max = 0.0;
  double render_seconds = 0.0;  // wall time of every view's render
  std::vector<preview::PassTime> passes;  // the renderer's per-pass times (ImageRenderer::pass_times)
};

nlohmann::ordered_json preview_report_json(const PreviewReport& report);

}  // namespace ts::app
