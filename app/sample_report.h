#pragma once
// What `tetrasand sample` prints of one mesh's run: the body report (particles, evenness, the coverage
// certificate, probes, thin features, device and work, mass properties), the --json document (the written
// body.json with the verdict, the thin features and the run's own figures), and the --timings figures (the
// sparse SDF's memory, the kernels, the stage table).
#include <filesystem>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "gpu/context.h"
#include "sampler/body_verdict.h"
#include "sampler/sample_mesh.h"

namespace ts::app {

// Wall time of the command's own stages of one mesh [s]; sample_mesh's are in SampleResult::stages.
struct CommandSeconds {
  double context = 0.0, load = 0.0, write = 0.0, total = 0.0;
  std::optional<double> preview;  // --preview: its field, drawing and PNG
};

// What the report says beside the result: the mesh, whether the inside was filled, and why the relaxation and
// the certificate ran where they did (gpu::backend_reason).
struct ReportFacts {
  std::string mesh;
  bool fill = false;
  std::string backend_reason;
  std::string scan;  // a field scanned on the GPU: its method and why ("scan compute (--scan)")
};

// The human report of one mesh, ending before the verdict line.
void print_body_report(const ReportFacts& facts, const sampler::SampleResult& result,
                       const std::filesystem::path& json, const gpu::Context* context);
// What this run cost and where it ran: the device, the SDF's path, the probes and each stage's seconds.
nlohmann::json run_json(const sampler::SampleResult& result, const CommandSeconds& c,
                        const gpu::Context* context);
// The written body.json with the verdict, the thin features and `run`; one line each in a batch (JSON Lines).
void print_json(const std::filesystem::path& json, const sampler::BodyVerdict& verdict,
                const sampler::ThinFeatures& thin, const nlohmann::json& run, bool one_line);
// --timings: the sparse SDF's memory, the kernels' times and the stage table.
void print_timings(const sampler::SampleResult& result, const CommandSeconds& c);

}  // namespace ts::app
