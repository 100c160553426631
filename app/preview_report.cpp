#include "app/preview_report.h"

namespace ts::app {
namespace {

nlohmann::ordered_json or_null(const std::string& text) {
  return text.empty() ? nlohmann::ordered_json(nullptr) : nlohmann::ordered_json(text);
}

nlohmann::ordered_json drawn_json(const PreviewReport& r) {
  nlohmann::ordered_json particles = nullptr;
  if (r.particles > 0) {
    particles = {{"count", r.particles}, {"radius_m", r.particle_radius}, {"radius_source", r.radius_source}};
  }
  nlohmann::ordered_json field = nullptr;
  if (!r.field.empty()) field = {{"description", r.field}, {"voxel_size_m", r.voxel_size}};
  nlohmann::ordered_json colour = nullptr;
  if (r.colour_pixels > 0) {
    colour = {{"by", r.colour_by},
              {"pixels", r.colour_pixels},
              {"mean", r.colour_mean / static_cast<double>(r.colour_pixels)},
              {"max", r.colour_max},
              {"map_max", r.colour_map_max}};
  }
  return {{"field", field}, {"particles", particles}, {"colour", colour}};
}

}  // namespace

nlohmann::ordered_json preview_report_json(const PreviewReport& r) {
  nlohmann::ordered_json outputs = nlohmann::ordered_json::array();
  for (const std::filesystem::path& p : r.outputs) outputs.push_back(p.string());
  nlohmann::ordered_json passes = nlohmann::ordered_json::array();
  for (const preview::PassTime& p : r.passes) {
    passes.push_back({{"name", p.name}, {"calls", p.calls}, {"milliseconds", p.milliseconds}});
  }
  return {
      {"inputs", {{"field", or_null(r.field_input)}, {"particles", or_null(r.particles_input)}}},
      {"outputs", outputs},
      {"image",
       {{"width", r.width}, {"height", r.height}, {"views", r.views}, {"contact_sheet", r.contact_sheet}}},
      {"backend",
       {{"requested", r.requested_backend},
        {"chosen", r.backend},
        {"device", r.device},
        {"gpu_path", or_null(r.gpu_path)}}},
      {"drawn", drawn_json(r)},
      {"render_seconds", r.render_seconds},
      {"passes", passes},
  };
}

}  // namespace ts::app
