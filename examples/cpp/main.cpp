// A program of another project using tetrasand as a library: a mesh becomes a particle rigid body,
// and the body's particle count and mass are printed.
//   sample_mesh MESH [COUNT]     (COUNT: particles wanted, default 500)
#include <cstdio>
#include <cstdlib>
#include <string>

#include <tetrasand/tetrasand.h>

int main(int argc, char** argv) {
  if (argc < 2 || argc > 3) {
    std::fprintf(stderr, "usage: %s MESH [COUNT]\n", argv[0]);
    return 2;
  }
  try {
    const ts::TriangleMesh mesh = ts::load_mesh(argv[1]);  // throws ts::InputError naming the file

    ts::sampler::SampleSettings settings;
    settings.count = argc == 3 ? std::stoul(argv[2]) : 500;
    settings.density = 1000.0;  // kg/m^3
    // Every stage on the CPU, so no GL context is needed (nullptr below). With a ts::gpu::Context
    // and gpu::Backend::Auto the GPU runs the stages where one is present (gpu/backend.h).
    settings.sdf_backend = ts::gpu::Backend::Cpu;
    settings.backend = ts::gpu::Backend::Cpu;

    const ts::sampler::SampleResult result = ts::sampler::sample_mesh(nullptr, mesh, settings);
    std::printf("particles: %zu\n", result.body.positions.size());
    std::printf("mass: %.9g kg\n", result.body.mass);
    std::printf("volume: %.9g m^3\n", result.body.volume);
    return 0;
  } catch (const ts::Error& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return static_cast<int>(e.code());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 1;
  }
}
