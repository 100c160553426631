#include "tests/sdf/field_probe.h"

#include <string>

#include "gpu/context.h"
#include "gpu/gl.h"
#include "gpu/params.h"
#include "shaders/test/bindings.h"

namespace ts::test {

std::vector<Eigen::Vector4f> probe_field(const sdf::GpuField& field,
                                         const std::vector<Eigen::Vector4f>& points, int mode) {
  gpu::ShaderLibrary library;
  std::vector<std::string> defines = field.shader_defines();
  defines.push_back("TS_PROBE_MODE " + std::to_string(mode));
  gpu::Program program = gpu::Program::compute(library, "test/sparse_field_probe.comp", defines);
  gpu::Buffer in = gpu::Buffer::from<Eigen::Vector4f>(points);
  gpu::Buffer out(points.size() * sizeof(Eigen::Vector4f));
  field.bind({TS_TEST_FIELD_GRID,
              {TS_TEST_FIELD_CHUNK_1, TS_TEST_FIELD_CHUNK_2, TS_TEST_FIELD_CHUNK_3, TS_TEST_FIELD_CHUNK_4,
               TS_TEST_FIELD_CHUNK_5, TS_TEST_FIELD_CHUNK_6, TS_TEST_FIELD_CHUNK_7},
              TS_TEST_FIELD_PARAMS,
              TS_TEST_FIELD_ROOTS});
  in.bind(TS_TEST_FIELD_POINTS);
  out.bind(TS_TEST_FIELD_VALUES);
  gpu::ParamBlock<gpu::params::FieldProbeParams> params;
  params.values.count.x = static_cast<unsigned>(points.size());
  params.values.mode.x = mode;
  params.bind(TS_TEST_PARAMS);
  gpu::Queue queue(false, true);
  queue.dispatch_items(program, points.size(), GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
  return out.read<Eigen::Vector4f>(points.size());
}

}  // namespace ts::test
