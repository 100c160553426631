// `--backend`: which engine `sim`, `sdf`, `sample` and `preview` run, chosen by the one rule of gpu/backend.h
// (issues 16 and 42: "the fastest path where there is no GPU"): on a software GL device auto takes the CPU
// path and every command says so in the same one line;
// `--backend gpu` forces the GPU, `--cpu` stays an alias of `sim --backend cpu`, and bad combinations are
// usage errors (exit 2).
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <optional>
#include <regex>
#include <string>

#include <nlohmann/json.hpp>

#include "core/atomic_file.h"
#include "gpu/context.h"
#include "tests/test_support.h"

namespace ts {
namespace {

using test::quoted;

// `--device N` of the first software EGL device (llvmpipe), so the choice is tested on a machine with a GPU
// too; nullopt when EGL lists none.
std::optional<std::string> software_device() {
  for (const gpu::DeviceDescription& d : gpu::enumerate_devices(false))
    if (d.software) return "--device " + std::to_string(d.index) + " ";
  return std::nullopt;
}

// `sim` on the two-grain collision for a few hundred steps, with `flags`; the output in *out.
int run_sim(const std::string& device, const std::string& flags, std::string* out) {
  const auto dir = test::temp_dir();
  return test::run_tetrasand(device + "sim " + quoted(test::asset("scenes/two_grain_collision.toml")) +
                                 " -o " + quoted(dir / "out") + " --duration 0.0002 " + flags,
                             out);
}

// The engine the run summary names: "CPU reference" or the GL context's summary.
std::string summary_engine(const std::string& out) {
  static const std::regex line(R"(grain-steps/s, (.*)\)\n)");
  std::smatch m;
  return std::regex_search(out, m, line) ? m[1].str() : "(no summary line)";
}

constexpr const char* kAutoLine =
    "backend: cpu, the CPU reference (auto: the GL device is llvmpipe, a software renderer; --backend gpu "
    "forces the GPU)\n";

TEST(SimBackend, AutoRunsTheCpuReferenceOnASoftwareDeviceAndSaysSoInOneLine) {
  const auto device = software_device();
  if (!device) GTEST_SKIP() << "EGL lists no software device";
  std::string out;
  ASSERT_EQ(run_sim(*device, "", &out), 0) << out;
  EXPECT_NE(out.find(kAutoLine), std::string::npos) << out;
  EXPECT_EQ(summary_engine(out), "CPU reference") << out;
  ASSERT_EQ(run_sim(*device, "--backend auto", &out), 0) << out;
  EXPECT_EQ(summary_engine(out), "CPU reference") << out;
}

TEST(SimBackend, BackendGpuForcesTheGpuPipelineOnASoftwareDevice) {
  const auto device = software_device();
  if (!device) GTEST_SKIP() << "EGL lists no software device";
  for (const std::string flags : {"--backend gpu", "--backend gpu --precision double"}) {
    std::string out;
    ASSERT_EQ(run_sim(*device, flags, &out), 0) << flags << "\n" << out;
    EXPECT_NE(out.find("backend: gpu, the GPU pipeline (asked for)\n"), std::string::npos) << flags << "\n"
                                                                                           << out;
    EXPECT_TRUE(summary_engine(out).starts_with("llvmpipe")) << flags << "\n" << out;
    EXPECT_TRUE(summary_engine(out).ends_with(", software)")) << flags << "\n" << out;
  }
}

// --json: standard output is one JSON object (the backend line and progress go to standard error, the
// log), naming the engine, the steps and every output kind with its count.
TEST(SimBackend, JsonSummaryIsAllOfStandardOutputAndNamesTheEngineAndTheOutputs) {
  const auto dir = test::temp_dir();
  test::run_tetrasand("sim " + quoted(test::asset("scenes/two_grain_collision.toml")) + " -o " + quoted(dir / "out") +
                      " --duration 0.0002 --backend cpu --json 2> " + quoted(dir / "log.txt") + " | cat > " +
                      quoted(dir / "summary.json"));
  const std::string log = read_file(dir / "log.txt");
  std::ifstream in(dir / "summary.json");
  const nlohmann::json summary = nlohmann::json::parse(in, nullptr, false);
  ASSERT_FALSE(summary.is_discarded()) << "standard output is not one JSON object; the log:\n" << log;
  EXPECT_EQ(summary.at("engine"), "cpu reference");
  EXPECT_GT(summary.at("steps").get<int>(), 0);
  EXPECT_TRUE(summary.at("resumed_from").is_null());
  EXPECT_EQ(summary.at("bodies").at("grains"), 2);
  ASSERT_FALSE(summary.at("outputs").empty());
  EXPECT_EQ(summary.at("outputs")[0].at("pattern"), "metrics.csv");
  EXPECT_GT(summary.at("outputs")[0].at("count").get<int>(), 0);
  EXPECT_TRUE(summary.at("last_step").contains("kinetic_translational_J"));
}

// A breakable prop (issue 48) runs on either engine: auto takes the engine of the backend rule (the CPU
// reference on a software renderer), the summary names the bonds and the bound that set the step, and
// --backend gpu steps the same bonds in the GPU pipeline.
TEST(SimBackend, AWorldWithBondsRunsOnTheEngineTheBackendRulePicksAndOnTheGpu) {
  const auto dir = test::temp_dir();
  const std::string scene = quoted(test::asset("scenes/crumble.toml"));
  for (const std::string backend : {"auto", "gpu"}) {
    test::run_tetrasand("sim " + scene + " -o " + quoted(dir / backend) + " --duration 0.0001 --backend " + backend +
                        " --json 2> " + quoted(dir / (backend + ".log")) + " | cat > " +
                        quoted(dir / (backend + ".json")));
    const std::string log = read_file(dir / (backend + ".log"));
    std::ifstream in(dir / (backend + ".json"));
    const nlohmann::json summary = nlohmann::json::parse(in, nullptr, false);
    ASSERT_FALSE(summary.is_discarded()) << backend << "\n" << log;
    if (backend == "gpu") {
      EXPECT_EQ(summary.at("engine").get<std::string>().rfind("gpu", 0), 0u) << summary.at("engine");
    } else if (log.find("a software renderer") != std::string::npos) {
      EXPECT_EQ(summary.at("engine"), "cpu reference") << log;
    }
    EXPECT_EQ(summary.at("dt_set_by"), "bonds") << backend;
    EXPECT_EQ(summary.at("bonds").at("at_start"), 1913) << backend;
    EXPECT_EQ(summary.at("bonds").at("fragments"), 1) << backend;
  }
}

TEST(SimBackend, CpuFlagIsAnAliasOfBackendCpu) {
  for (const std::string flags : {"--cpu", "--backend cpu"}) {
    std::string out;
    ASSERT_EQ(run_sim("", flags, &out), 0) << flags << "\n" << out;
    EXPECT_EQ(summary_engine(out), "CPU reference") << flags << "\n" << out;
    EXPECT_NE(out.find("backend: cpu, the CPU reference (asked for)\n"), std::string::npos) << flags << "\n"
                                                                                            << out;
  }
  std::string out;
  EXPECT_EQ(run_sim("", "--cpu --backend gpu", &out), 2) << out;
  EXPECT_NE(out.find("excludes"), std::string::npos) << out;
}

TEST(SimBackend, BadBackendAndPrecisionWithTheCpuReferenceAreRefused) {
  std::string out;
  EXPECT_EQ(run_sim("", "--backend tpu", &out), 2) << out;
  EXPECT_NE(out.find("--backend"), std::string::npos) << out;
  EXPECT_NE(out.find("tpu"), std::string::npos) << out;
  for (const std::string flags : {"--cpu --precision float", "--backend cpu --precision double"}) {
    EXPECT_EQ(run_sim("", flags, &out), 2) << flags << "\n" << out;
    EXPECT_NE(out.find("the CPU reference (--backend cpu) computes in double only"), std::string::npos)
        << flags << "\n"
        << out;
    EXPECT_EQ(out.find("grain-steps/s"), std::string::npos) << flags << "\n"
                                                            << out;  // refused before the run
  }
}

// auto on a software device with --precision: the CPU reference still runs, and the one line says that
// --precision is the GPU pipeline's.
TEST(SimBackend, AutoOnASoftwareDeviceNotesThatPrecisionIsTheGpus) {
  const auto device = software_device();
  if (!device) GTEST_SKIP() << "EGL lists no software device";
  std::string out;
  ASSERT_EQ(run_sim(*device, "--precision double", &out), 0) << out;
  EXPECT_NE(out.find("backend: cpu, the CPU reference (auto: the GL device is llvmpipe, a software renderer; "
                     "--backend gpu forces the GPU; --precision applies to the GPU pipeline only, the CPU "
                     "reference computes in double)\n"),
            std::string::npos)
      << out;
  EXPECT_EQ(summary_engine(out), "CPU reference") << out;
}

// [output] frames = true still renders through a GL context when auto runs the steps on the CPU.
TEST(SimBackend, AutoOnASoftwareDeviceStillWritesFrames) {
  const auto device = software_device();
  if (!device) GTEST_SKIP() << "EGL lists no software device";
  const auto dir = test::temp_dir();
  write_file_atomically(dir / "fall.toml",
                        read_file(test::asset("scenes/free_fall.toml")) + "frames = true\n");
  std::string out;
  ASSERT_EQ(test::run_tetrasand(*device + "sim " + quoted(dir / "fall.toml") + " -o " + quoted(dir / "out") +
                                    " --duration 0.002",
                                &out),
            0)
      << out;
  EXPECT_NE(out.find(kAutoLine), std::string::npos) << out;
  EXPECT_EQ(summary_engine(out), "CPU reference") << out;
  EXPECT_TRUE(std::filesystem::exists(dir / "out" / "frame_000000.png")) << out;
}

// A checkpoint names its engine: resuming it under another backend is refused with the flags to give.
TEST(SimBackend, ResumeUnderAnotherBackendNamesTheFlagsOfTheRunThatWroteIt) {
  const auto dir = test::temp_dir();
  write_file_atomically(dir / "two.toml", read_file(test::asset("scenes/two_grain_collision.toml")) +
                                              "checkpoint_every = 50\n");
  const std::string scene = quoted(dir / "two.toml"), out_dir = quoted(dir / "out");
  std::string out;
  ASSERT_EQ(test::run_tetrasand("sim " + scene + " -o " + out_dir + " --duration 0.0001 --backend cpu", &out),
            0)
      << out;
  EXPECT_EQ(test::run_tetrasand("sim " + scene + " --resume " + out_dir + " --backend gpu", &out), 1) << out;
  EXPECT_NE(out.find("written by the cpu reference engine, and this run uses the gpu float (resume with "
                     "--backend cpu, as the run that wrote it)"),
            std::string::npos)
      << out;
}

// The band voxel count of `sdf`'s first line.
long band_voxels(const std::string& out) {
  static const std::regex count(R"(, (\d+) band voxels\))");
  std::smatch m;
  return std::regex_search(out, m, count) ? std::stol(m[1].str()) : -1;
}

TEST(SdfBackend, NamesTheDeviceAndTheTimeAndTheCpuPathGivesTheSameBand) {
  const auto dir = test::temp_dir();
  const std::string bunny = quoted(test::asset("bunny.obj"));
  std::string gpu, cpu;
  ASSERT_EQ(test::run_tetrasand(
                "sdf " + bunny + " -o " + quoted(dir / "gpu.vdb") + " --resolution 24 --backend gpu", &gpu),
            0)
      << gpu;
  // --scan auto: whichever method this device's calibration (sdf/scan_calibration.h) found faster.
  EXPECT_TRUE(std::regex_search(
      gpu, std::regex(R"(backend: gpu, scan conversion by (compute shaders|geometry shader) \(asked for; )"
                      R"(--scan auto: calibrated [0-9.e+]+x geometry's speed(, cached)?\)\n)")))
      << gpu;
  EXPECT_TRUE(std::regex_search(
      gpu, std::regex(R"(\ndevice: .+ \(device \d+(, software)?\); scan (compute|geometry) \(calibrated )"
                      R"([0-9.e+]+x geometry's speed(, cached)?\) \d+\.\d{3} s\n)")))
      << gpu;
  ASSERT_EQ(test::run_tetrasand(
                "sdf " + bunny + " -o " + quoted(dir / "cpu.vdb") + " --resolution 24 --backend cpu", &cpu),
            0)
      << cpu;
  EXPECT_NE(cpu.find("backend: cpu, exact SDF (asked for)\n"), std::string::npos) << cpu;
  EXPECT_TRUE(
      std::regex_search(cpu, std::regex(R"(\ndevice: CPU exact SDF \(triangle sweep, double precision, \d+ )"
                                        R"(TBB threads\); exact SDF \d+\.\d{3} s\n)")))
      << cpu;
  EXPECT_TRUE(std::filesystem::exists(dir / "cpu.vdb"));
  // The GPU field is within 1.2e-4 voxel of exact (docs/benchmarks.md): the same voxels lie in the band but
  // for the few whose distance is within that of the band's edge.
  const long g = band_voxels(gpu), c = band_voxels(cpu);
  ASSERT_GT(g, 1000) << gpu;
  EXPECT_NEAR(static_cast<double>(c), static_cast<double>(g), 0.001 * static_cast<double>(g)) << cpu;
}

// Points TETRASAND_SCAN_CACHE (sdf/scan_calibration.h) at a file of the test's own for its lifetime.
class ScopedScanCache {
 public:
  explicit ScopedScanCache(const std::filesystem::path& file) {
    if (const char* old = std::getenv("TETRASAND_SCAN_CACHE")) old_ = old;
    ::setenv("TETRASAND_SCAN_CACHE", file.c_str(), 1);
  }
  ~ScopedScanCache() {
    if (old_) {
      ::setenv("TETRASAND_SCAN_CACHE", old_->c_str(), 1);
    } else {
      ::unsetenv("TETRASAND_SCAN_CACHE");
    }
  }
  ScopedScanCache(const ScopedScanCache&) = delete;
  ScopedScanCache& operator=(const ScopedScanCache&) = delete;

 private:
  std::optional<std::string> old_;
};

// --scan auto end to end: the first run calibrates and writes the cache, the next reads it (", cached"),
// and a corrupt cache costs a warning and a new calibration, never the run.
TEST(SdfBackend, ScanAutoCalibratesOnceThenReadsTheCacheAndSurvivesACorruptOne) {
  const auto dir = test::temp_dir();
  const std::filesystem::path cache = dir / "calibration" / "scan.json";
  const ScopedScanCache scoped(cache);
  const std::string run = "sdf " + quoted(test::asset("cube.obj")) + " -o " + quoted(dir / "c.vdb") +
                          " --resolution 16 --backend gpu";
  const std::regex calibrated(R"(\ndevice: .+; scan (compute|geometry) )"
                              R"(\(calibrated [0-9.e+]+x geometry's speed\) )");
  const std::regex cached(R"(\ndevice: .+; scan (compute|geometry) )"
                          R"(\(calibrated [0-9.e+]+x geometry's speed, cached\) )");
  std::string first, second, third;
  ASSERT_EQ(test::run_tetrasand(run, &first), 0) << first;
  EXPECT_TRUE(std::regex_search(first, calibrated)) << first;
  ASSERT_TRUE(std::filesystem::exists(cache));
  ASSERT_EQ(test::run_tetrasand(run, &second), 0) << second;
  EXPECT_TRUE(std::regex_search(second, cached)) << second;
  std::ofstream(cache, std::ios::trunc) << "not json";
  ASSERT_EQ(test::run_tetrasand(run, &third), 0) << third;
  EXPECT_NE(third.find("unreadable scan calibration cache"), std::string::npos) << third;
  EXPECT_TRUE(std::regex_search(third, calibrated)) << third;
}

// Issue 42: plain `sdf` follows the rule of every command, so on llvmpipe (where the exact CPU path is 4-7x
// faster) it takes the CPU path and says why; --backend gpu still runs the scan conversion there.
TEST(SdfBackend, AutoTakesTheExactCpuPathOnASoftwareDeviceAndSaysSo) {
  const auto device = software_device();
  if (!device) GTEST_SKIP() << "EGL lists no software device";
  const auto dir = test::temp_dir();
  const std::string bunny = quoted(test::asset("bunny.obj"));
  std::string out;
  ASSERT_EQ(test::run_tetrasand(*device + "sdf " + bunny + " -o " + quoted(dir / "auto.vdb"), &out), 0)
      << out;
  EXPECT_NE(out.find("backend: cpu, exact SDF (auto: the GL device is llvmpipe, a software renderer; "
                     "--backend gpu forces the GPU)\n"),
            std::string::npos)
      << out;
  EXPECT_NE(out.find("\ndevice: CPU exact SDF ("), std::string::npos) << out;
  EXPECT_TRUE(std::filesystem::exists(dir / "auto.vdb"));
  ASSERT_EQ(
      test::run_tetrasand(*device + "sdf " + bunny + " -o " + quoted(dir / "auto.vdb") + " --json", &out), 0)
      << out;
  EXPECT_EQ(nlohmann::json::parse(out.substr(out.find("{\n"))).at("backend"), "cpu") << out;

  ASSERT_EQ(test::run_tetrasand(
                *device + "sdf " + bunny + " -o " + quoted(dir / "gpu.vdb") + " --backend gpu", &out),
            0)
      << out;
  EXPECT_TRUE(std::regex_search(
      out, std::regex(R"(backend: gpu, scan conversion by (compute shaders|geometry shader) \(asked for; )"
                      R"(--scan auto: calibrated )")))
      << out;
  EXPECT_TRUE(std::regex_search(
      out, std::regex(R"(\ndevice: llvmpipe.*; scan (compute|geometry) \(calibrated .*\) \d+\.\d{3} s\n)")))
      << out;
}

// --scan picks the GPU path's method, named on the backend line, the device line and in --json; both
// methods give the same band; a bad spelling is a usage error.
TEST(SdfBackend, ScanComputeAndGeometryAreNamedEverywhereAndGiveTheSameBand) {
  const auto dir = test::temp_dir();
  const std::string bunny = quoted(test::asset("bunny.obj"));
  std::string compute, geometry, json;
  const std::string common = " --resolution 24 --backend gpu --scan ";
  ASSERT_EQ(
      test::run_tetrasand("sdf " + bunny + " -o " + quoted(dir / "c.vdb") + common + "compute", &compute), 0)
      << compute;
  EXPECT_NE(compute.find(
                "backend: gpu, scan conversion by compute shaders (asked for; --scan compute asked for)\n"),
            std::string::npos)
      << compute;
  EXPECT_NE(compute.find("; scan compute (--scan) "), std::string::npos) << compute;
  ASSERT_EQ(
      test::run_tetrasand("sdf " + bunny + " -o " + quoted(dir / "g.vdb") + common + "geometry", &geometry),
      0)
      << geometry;
  EXPECT_NE(geometry.find(
                "backend: gpu, scan conversion by geometry shader (asked for; --scan geometry asked for)\n"),
            std::string::npos)
      << geometry;
  EXPECT_NE(geometry.find("; scan geometry (--scan) "), std::string::npos) << geometry;
  EXPECT_EQ(band_voxels(compute), band_voxels(geometry)) << compute << geometry;
  ASSERT_EQ(test::run_tetrasand("sdf " + bunny + " -o " + quoted(dir / "j.vdb") + common + "geometry --json",
                                &json),
            0)
      << json;
  const auto report = nlohmann::json::parse(json.substr(json.find("{\n")));
  EXPECT_EQ(report.at("scan"), "geometry") << json;
  EXPECT_EQ(test::run_tetrasand("sdf " + bunny + " -o " + quoted(dir / "x.vdb") + common + "raster", &json),
            2)
      << json;
  EXPECT_NE(json.find("--scan"), std::string::npos) << json;
  EXPECT_FALSE(std::filesystem::exists(dir / "x.vdb"));
}

// --sign winding re-signs the compute path's band as it does the geometry path's: the same file.
TEST(SdfBackend, WindingSignsWorkOnTheComputePath) {
  const auto dir = test::temp_dir();
  const std::string cube = quoted(test::asset("cube.obj"));
  std::string out;
  const std::string common = " --resolution 16 --backend gpu --sign winding --json --scan ";
  ASSERT_EQ(test::run_tetrasand("sdf " + cube + " -o " + quoted(dir / "c.vdb") + common + "compute", &out), 0)
      << out;
  const auto compute = nlohmann::json::parse(out.substr(out.find("{\n")));
  ASSERT_EQ(test::run_tetrasand("sdf " + cube + " -o " + quoted(dir / "g.vdb") + common + "geometry", &out),
            0)
      << out;
  const auto geometry = nlohmann::json::parse(out.substr(out.find("{\n")));
  EXPECT_EQ(compute.at("scan"), "compute");
  EXPECT_EQ(compute.at("band_voxels"), geometry.at("band_voxels"));
  EXPECT_GT(compute.at("band_voxels").get<long>(), 100);
}

TEST(SdfBackend, BadBackendAndCompareWithTheCpuPathAreRefused) {
  const auto dir = test::temp_dir();
  const std::string cube = quoted(test::asset("cube.obj"));
  std::string out;
  EXPECT_EQ(test::run_tetrasand("sdf " + cube + " -o " + quoted(dir / "a.vdb") + " --backend tpu", &out), 2)
      << out;
  EXPECT_NE(out.find("--backend"), std::string::npos) << out;
  EXPECT_EQ(test::run_tetrasand(
                "sdf " + cube + " -o " + quoted(dir / "a.vdb") + " --backend cpu --compare-openvdb", &out),
            2)
      << out;
  EXPECT_NE(out.find("with --backend cpu the field is the exact one"), std::string::npos) << out;
  EXPECT_FALSE(std::filesystem::exists(dir / "a.vdb"));
}

// `sample` on the sphere, small and quick, with `flags`; the output in *out.
int run_sample(const std::string& device, const std::string& flags, std::string* out) {
  return test::run_tetrasand(device + "sample " + quoted(test::asset("sphere.obj")) + " -o " +
                                 quoted(test::temp_dir()) + " --count 150 --probes 20000 --rounds 2 " + flags,
                             out);
}

// The device line's tail: where the relaxation and the certificate ran, and why.
std::string sample_backend(const std::string& out) {
  static const std::regex line(R"(  device           .*certificate [0-9.]+ s; (.*)\n)");
  std::smatch m;
  return std::regex_search(out, m, line) ? m[1].str() : "(no device line)";
}

TEST(CliSampleBackend, AutoRelaxesOnTheCpuOnASoftwareDeviceAndSaysSoOnTheDeviceLine) {
  const auto device = software_device();
  if (!device) GTEST_SKIP() << "EGL lists no software device";
  std::string out;
  ASSERT_EQ(run_sample(*device, "", &out), 0) << out;
  EXPECT_EQ(sample_backend(out),
            "relaxation and certificate on the CPU (auto: the GL device is llvmpipe, a software renderer; "
            "--backend gpu forces the GPU)")
      << out;
  EXPECT_NE(out.find("backend: cpu, relaxation and certificate (auto: the GL device is llvmpipe, a software "
                     "renderer; --backend gpu forces the GPU; SDF: by exact distance on the CPU, auto)\n"),
            std::string::npos)
      << out;
  ASSERT_EQ(run_sample(*device, "--backend auto --json", &out), 0) << out;
  const auto json = nlohmann::json::parse(out.substr(out.find("{\n")));
  EXPECT_EQ(json.at("run").at("relax_backend"), "cpu") << out;
  EXPECT_EQ(json.at("run").at("certificate_backend"), "cpu") << out;
  EXPECT_EQ(json.at("run").at("software_device"), true) << out;
}

// --scan picks the method of a field built on the GPU (auto: the calibrated one); run.scan names it,
// null for a field built on the CPU.
TEST(CliSampleBackend, ScanPicksTheGpuFieldsMethodAndTheJsonNamesIt) {
  std::string out;
  ASSERT_EQ(run_sample("", "--sdf-backend gpu --scan geometry --json", &out), 0) << out;
  EXPECT_EQ(nlohmann::json::parse(out.substr(out.find("{\n"))).at("run").at("scan"), "geometry") << out;
  ASSERT_EQ(run_sample("", "--sdf-backend gpu", &out), 0) << out;
  EXPECT_TRUE(std::regex_search(
      out, std::regex(R"(SDF: by GPU scan (compute|geometry) \(calibrated [^)]*\), asked for\))")))
      << out;
  ASSERT_EQ(run_sample("", "--sdf-backend cpu --backend cpu --json", &out), 0) << out;
  EXPECT_TRUE(nlohmann::json::parse(out.substr(out.find("{\n"))).at("run").at("scan").is_null()) << out;
  EXPECT_EQ(run_sample("", "--scan raster", &out), 2) << out;
}

TEST(CliSampleBackend, BackendGpuForcesTheGpuRelaxationOnASoftwareDevice) {
  const auto device = software_device();
  if (!device) GTEST_SKIP() << "EGL lists no software device";
  std::string out;
  ASSERT_EQ(run_sample(*device, "--backend gpu --timings", &out), 0) << out;
  EXPECT_EQ(sample_backend(out), "relaxation and certificate on the GPU (asked for)") << out;
  EXPECT_NE(out.find("sampler/relax.comp"), std::string::npos) << out;  // the kernels ran
  ASSERT_EQ(run_sample(*device, "--backend gpu --json", &out), 0) << out;
  const auto json = nlohmann::json::parse(out.substr(out.find("{\n")));
  EXPECT_EQ(json.at("run").at("relax_backend"), "gpu") << out;
  EXPECT_EQ(json.at("run").at("certificate_backend"), "gpu") << out;
}

TEST(CliSampleBackend, BackendCpuRelaxesOnTheCpuWithNoRoundTrip) {
  std::string out;
  ASSERT_EQ(run_sample("", "--backend cpu --timings", &out), 0) << out;
  EXPECT_EQ(sample_backend(out), "relaxation and certificate on the CPU (asked for)") << out;
  EXPECT_EQ(out.find("sampler/relax.comp"), std::string::npos) << out;
  EXPECT_TRUE(std::regex_search(out, std::regex(R"(CPU relaxation \(\d+ threads\): \d+ iterations)"))) << out;
  EXPECT_TRUE(std::regex_search(out, std::regex(R"(relaxation iterations between checks \(\d+\) +0 )")))
      << out;
}

// --backend cpu opens no GL context: a device that does not exist stops auto and --backend gpu (exit 3), not
// it, --preview included (drawn on the CPU).
TEST(CliSampleBackend, BackendCpuRunsWithoutAGlContext) {
  std::string out;
  ASSERT_EQ(run_sample("--device 99 ", "--backend cpu", &out), 0) << out;
  EXPECT_NE(out.find("  device           the CPU (no GL context): SDF by exact distance on the CPU"),
            std::string::npos)
      << out;
  EXPECT_NE(
      out.find(
          "backend: cpu, relaxation and certificate (asked for; SDF: by exact distance on the CPU, auto)\n"),
      std::string::npos)
      << out;
  EXPECT_NE(out.find("certificate      certified"), std::string::npos) << out;
  for (const std::string flags : {"--backend auto", "--backend gpu"}) {
    EXPECT_EQ(run_sample("--device 99 ", flags, &out), 3) << flags << "\n" << out;
    EXPECT_NE(out.find("device 99 does not exist"), std::string::npos) << flags << "\n" << out;
  }
}

TEST(CliSampleBackend, BadBackendIsAUsageError) {
  std::string out;
  EXPECT_EQ(run_sample("", "--backend tpu", &out), 2) << out;
  EXPECT_NE(out.find("--backend"), std::string::npos) << out;
  EXPECT_NE(out.find("tpu"), std::string::npos) << out;
  EXPECT_EQ(out.find("certificate"), std::string::npos) << out;  // refused before any work
}

// The preview: auto draws on the CPU on a software device and names why; --backend cpu needs no GL
// context (a device that does not exist does not stop it); --backend gpu draws on the device.
TEST(PreviewBackend, AutoDrawsOnTheCpuOnASoftwareDeviceAndCpuNeedsNoContext) {
  const auto device = software_device();
  if (!device) GTEST_SKIP() << "EGL lists no software device";
  const auto dir = test::temp_dir();
  const std::string preview =
      "preview " + quoted(test::asset("cube.obj")) + " --size 64x48 --resolution 24 -o ";
  std::string out;
  ASSERT_EQ(test::run_tetrasand(*device + preview + quoted(dir / "auto.png"), &out), 0) << out;
  EXPECT_NE(out.find("backend: cpu, renderer (auto: the GL device is llvmpipe, a software renderer; --backend "
                     "gpu forces the GPU)\n"),
            std::string::npos)
      << out;
  EXPECT_TRUE(std::filesystem::exists(dir / "auto.png"));
  ASSERT_EQ(test::run_tetrasand("--device 99 " + preview + quoted(dir / "cpu.png") + " --backend cpu", &out), 0)
      << out;
  EXPECT_NE(out.find("backend: cpu, renderer (asked for)\n"), std::string::npos) << out;
  EXPECT_TRUE(std::filesystem::exists(dir / "cpu.png"));
  ASSERT_EQ(test::run_tetrasand(*device + preview + quoted(dir / "gpu.png") + " --backend gpu", &out), 0) << out;
  EXPECT_NE(out.find("backend: gpu, renderer (asked for)\n"), std::string::npos) << out;
}

}  // namespace
}  // namespace ts
