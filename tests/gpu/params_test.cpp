// The C++ structs of gpu/params.h and the GLSL compiler must agree on every kernel parameter block:
// each real program is compiled and every uniform block it declares is read back by reflection (its
// size and each member's offset) and compared with the struct the host uploads into it.
#include <gtest/gtest.h>

#include <cstddef>
#include <string>
#include <vector>

#include "gpu/context.h"
#include "gpu/gl.h"
#include "gpu/params.h"

namespace ts::gpu {
namespace {

using namespace params;

struct Member {
  std::string name;  // GLSL name, "<block member>.<struct member>"
  std::size_t offset;
};

// One uniform block as the host sees it.
struct BlockSpec {
  std::string block;  // GLSL block name
  std::size_t size;   // sizeof the C++ struct
  std::vector<Member> members;
};

#define TS_MEMBER(instance, Type, member) \
  Member { #instance "." #member, offsetof(Type, member) }

BlockSpec item_count(const std::string& block) {
  return {block, sizeof(ItemCount), {TS_MEMBER(params, ItemCount, count)}};
}
BlockSpec grid(const std::string& block) {
  return {
      block, sizeof(GridParams), {TS_MEMBER(params, GridParams, sizes), TS_MEMBER(params, GridParams, cell)}};
}
BlockSpec field() {
  return {"FieldBlock",
          sizeof(FieldParams),
          {TS_MEMBER(field_params, FieldParams, index_offset), TS_MEMBER(field_params, FieldParams, scale),
           TS_MEMBER(field_params, FieldParams, root_first), TS_MEMBER(field_params, FieldParams, roots)}};
}
BlockSpec camera() {
  return {"CameraBlock",
          sizeof(CameraParams),
          {TS_MEMBER(camera, CameraParams, view_projection),
           TS_MEMBER(camera, CameraParams, inverse_view_projection), TS_MEMBER(camera, CameraParams, eye),
           TS_MEMBER(camera, CameraParams, forward), TS_MEMBER(camera, CameraParams, right),
           TS_MEMBER(camera, CameraParams, up), TS_MEMBER(camera, CameraParams, lens),
           TS_MEMBER(camera, CameraParams, viewport)}};
}
BlockSpec volume() {
  return {"VolumeBlock",
          sizeof(VolumeParams),
          {TS_MEMBER(volume, VolumeParams, origin_voxel), TS_MEMBER(volume, VolumeParams, dims_band)}};
}
template <typename Contact>
BlockSpec contact() {
  return {"ContactBlock",
          sizeof(Contact),
          {TS_MEMBER(params, Contact, sizes), TS_MEMBER(params, Contact, materials),
           TS_MEMBER(params, Contact, limits), TS_MEMBER(params, Contact, step), TS_MEMBER(params, Contact, lists)}};
}
template <typename Integrate>
BlockSpec integrate() {
  return {"IntegrateBlock",
          sizeof(Integrate),
          {TS_MEMBER(params, Integrate, sizes), TS_MEMBER(params, Integrate, models),
           TS_MEMBER(params, Integrate, limits), TS_MEMBER(params, Integrate, gravity_dt),
           TS_MEMBER(params, Integrate, time)}};
}

// Reads `spec.block` of `program` back and compares it with the C++ struct.
void expect_block_matches(const Program& program, const BlockSpec& spec) {
  const GLuint id = program.id();
  const GLuint block = glGetProgramResourceIndex(id, GL_UNIFORM_BLOCK, spec.block.c_str());
  ASSERT_NE(block, GL_INVALID_INDEX) << program.name() << ": no uniform block " << spec.block;
  const GLenum size_prop = GL_BUFFER_DATA_SIZE;
  GLint size = -1;
  glGetProgramResourceiv(id, GL_UNIFORM_BLOCK, block, 1, &size_prop, 1, nullptr, &size);
  EXPECT_EQ(size, static_cast<GLint>(spec.size)) << program.name() << ": " << spec.block;
  for (const Member& m : spec.members) {
    const GLuint index = glGetProgramResourceIndex(id, GL_UNIFORM, m.name.c_str());
    EXPECT_NE(index, GL_INVALID_INDEX) << program.name() << ": no member " << m.name;
    if (index == GL_INVALID_INDEX) continue;
    const GLenum props[] = {GL_OFFSET, GL_BLOCK_INDEX};
    GLint values[2] = {-1, -1};
    glGetProgramResourceiv(id, GL_UNIFORM, index, 2, props, 2, nullptr, values);
    EXPECT_EQ(values[0], static_cast<GLint>(m.offset)) << program.name() << ": " << m.name;
    EXPECT_EQ(values[1], static_cast<GLint>(block)) << program.name() << ": " << m.name;
  }
}

// Every uniform block of `program` is one of `specs`, and every other uniform is a sampler or an
// image: a block the table does not know, or a loose uniform, would go unchecked.
void expect_only_checked_blocks(const Program& program, const std::vector<BlockSpec>& specs) {
  const GLuint id = program.id();
  GLint blocks = 0, uniforms = 0;
  glGetProgramInterfaceiv(id, GL_UNIFORM_BLOCK, GL_ACTIVE_RESOURCES, &blocks);
  glGetProgramInterfaceiv(id, GL_UNIFORM, GL_ACTIVE_RESOURCES, &uniforms);
  for (GLint b = 0; b < blocks; ++b) {
    char name[256] = {};
    glGetProgramResourceName(id, GL_UNIFORM_BLOCK, static_cast<GLuint>(b), sizeof(name), nullptr, name);
    bool known = false;
    for (const BlockSpec& s : specs) known = known || s.block == name;
    EXPECT_TRUE(known) << program.name() << ": uniform block " << name << " is not checked here";
  }
  for (GLint u = 0; u < uniforms; ++u) {
    const GLenum props[] = {GL_BLOCK_INDEX, GL_TYPE};
    GLint values[2] = {0, 0};
    glGetProgramResourceiv(id, GL_UNIFORM, static_cast<GLuint>(u), 2, props, 2, nullptr, values);
    if (values[0] != -1) continue;
    char name[256] = {};
    glGetProgramResourceName(id, GL_UNIFORM, static_cast<GLuint>(u), sizeof(name), nullptr, name);
    const std::string type = std::to_string(values[1]);
    const bool opaque = (values[1] >= GL_SAMPLER_1D && values[1] <= GL_SAMPLER_2D_SHADOW) ||
                        values[1] == GL_SAMPLER_2D_ARRAY || values[1] == GL_SAMPLER_2D_ARRAY_SHADOW ||
                        values[1] == GL_IMAGE_2D || values[1] == GL_IMAGE_3D ||
                        values[1] == GL_IMAGE_2D_ARRAY;
    EXPECT_TRUE(opaque) << program.name() << ": loose uniform " << name << " (GL type " << type << ")";
  }
}

void check(const Program& program, const std::vector<BlockSpec>& specs) {
  for (const BlockSpec& s : specs) expect_block_matches(program, s);
  expect_only_checked_blocks(program, specs);
}

class GpuParams : public ::testing::Test {
 protected:
  Program compute(const std::string& file, const std::vector<std::string>& defines = {}) {
    return Program::compute(library, file, defines);
  }
  Context context;
  ShaderLibrary library;
};

TEST_F(GpuParams, CommonKernelsMatchCpp) {
  check(compute("common/scan_blocks.comp"), {item_count("ScanBlock")});
  check(compute("common/scan_add.comp"), {item_count("ScanBlock")});
  check(compute("common/zero_uints.comp"), {item_count("FillBlock")});
  check(compute("common/copy_uints.comp"), {item_count("FillBlock")});
  for (const char* kernel :
       {"common/grid_count.comp", "common/grid_scatter.comp", "common/grid_sort_cells.comp"}) {
    check(compute(kernel), {grid("GridBlock")});
  }
}

TEST_F(GpuParams, SamplerKernelsMatchCpp) {
  check(compute("sampler/project.comp"), {item_count("ProjectBlock"), field()});
  check(compute("sampler/reduce_steps.comp"), {item_count("ReduceBlock")});
  check(compute("sampler/certify_scatter.comp"), {item_count("ScatterBlock")});
  check(compute("sampler/relax.comp"),
        {{"RelaxBlock",
          sizeof(RelaxParams),
          {TS_MEMBER(params, RelaxParams, sizes), TS_MEMBER(params, RelaxParams, kernel),
           TS_MEMBER(params, RelaxParams, limits)}},
         field()});
  check(compute("sampler/certify_evaluate.comp"),
        {{"CertifyBlock",
          sizeof(CertifyParams),
          {TS_MEMBER(params, CertifyParams, sizes), TS_MEMBER(params, CertifyParams, search),
           TS_MEMBER(params, CertifyParams, lengths), TS_MEMBER(params, CertifyParams, refine)}}});
}

TEST_F(GpuParams, SdfProgramsMatchCpp) {
  const Program scan = Program::graphics(library, "sdf/scan_convert.vert", "sdf/scan_convert.geom",
                                         "sdf/scan_convert.frag", {"INVOCATIONS 4"});
  check(scan, {{"ScanConvertBlock",
                sizeof(ScanConvertParams),
                {TS_MEMBER(params, ScanConvertParams, layers), TS_MEMBER(params, ScanConvertParams, grid)}}});
  const BlockSpec band{"BandBlock",
                       sizeof(BandParams),
                       {TS_MEMBER(params, BandParams, layer_size), TS_MEMBER(params, BandParams, voxels),
                        TS_MEMBER(params, BandParams, band)}};
  check(compute("sdf/band_flags.comp"), {band});
  check(compute("sdf/band_scatter.comp"), {band});
  const BlockSpec compute_scan{"ComputeScanBlock",
                       sizeof(ComputeScanParams),
                       {TS_MEMBER(params, ComputeScanParams, grid), TS_MEMBER(params, ComputeScanParams, slab),
                        TS_MEMBER(params, ComputeScanParams, pairs), TS_MEMBER(params, ComputeScanParams, band)}};
  check(compute("sdf/scan_bricks.comp"), {compute_scan});
  check(compute("sdf/scan_bricks.comp", {"BRICK_COUNT 1"}), {compute_scan});
  check(compute("sdf/scan_bricks.comp", {"BRICK_SCATTER 1"}), {compute_scan});
  const BlockSpec brick_pairs{"BrickPairBlock",
                              sizeof(BrickPairParams),
                              {TS_MEMBER(params, BrickPairParams, grid), TS_MEMBER(params, BrickPairParams, bricks),
                               TS_MEMBER(params, BrickPairParams, counts), TS_MEMBER(params, BrickPairParams, reach)}};
  for (const char* pass : {"ROW_SPANS 1", "COUNT 1", "SCATTER 1"}) {
    check(compute("sdf/brick_pairs.comp", {pass}), {brick_pairs});
  }
  const BlockSpec leaf{"LeafBlock",
                       sizeof(LeafBuildParams),
                       {TS_MEMBER(params, LeafBuildParams, grid), TS_MEMBER(params, LeafBuildParams, leaves),
                        TS_MEMBER(params, LeafBuildParams, cells), TS_MEMBER(params, LeafBuildParams, band)}};
  for (const char* kernel : {"sdf/leaf_flags.comp", "sdf/leaf_assign.comp", "sdf/leaf_fill.comp", "sdf/leaf_signs.comp"}) {
    check(compute(kernel), {leaf});
  }
  // The sampler's kernels compiled for the GPU-resident leaf field read the same FieldParams.
  check(compute("sampler/project.comp", {"TS_FIELD_LEAVES 1"}), {item_count("ProjectBlock"), field()});
}

TEST_F(GpuParams, SimKernelsMatchCppInBothPrecisions) {
  check(compute("sim/contact_forces.comp"), {contact<SimContactParams>()});
  check(compute("sim/contact_forces.comp", {"TS_FP64 1"}), {contact<SimContactParams64>()});
  check(compute("sim/contact_forces.comp", {"TS_FP64 1", "TS_CONTACT_FP64 1"}), {contact<SimContactParams64>()});
  // The leanest specialisation still reads the whole block (std140 keeps every member).
  const std::vector<std::string> lean{"TS_CONTACT_SPRINGS 0", "TS_CONTACT_DAMPING 1", "TS_CONTACT_WALLS 0",
                                      "TS_CONTACT_PENETRATION 0", "TS_CONTACT_BONDS 0"};
  check(compute("sim/contact_forces.comp", lean), {contact<SimContactParams>()});
  check(compute("sim/integrate_bodies.comp"), {integrate<SimIntegrateParams>()});
  check(compute("sim/integrate_bodies.comp", {"TS_FP64 1"}), {integrate<SimIntegrateParams64>()});
  check(compute("sim/update_particles.comp"), {item_count("UpdateBlock")});
  const BlockSpec lists{"ListBlock",
                        sizeof(SimListParams),
                        {TS_MEMBER(params, SimListParams, sizes), TS_MEMBER(params, SimListParams, lengths)}};
  check(compute("sim/list_decide.comp"), {lists});
  check(compute("sim/list_build.comp"), {lists});
  check(compute("sim/list_build.comp", {"TS_FP64 1"}), {lists});
  check(compute("sim/reduce_particle_stats.comp"), {item_count("StatsBlock")});
  check(compute("sim/resort_ranges.comp"), {item_count("RangesBlock")});
  check(compute("sim/resort_particles.comp"), {item_count("ParticlesBlock")});
  check(compute("sim/resort_keys.comp"), {grid("KeysBlock")});
  check(compute("sim/reduce_metrics.comp"),
        {{"MetricsBlock",
          sizeof(SimMetricsParams),
          {TS_MEMBER(params, SimMetricsParams, sizes), TS_MEMBER(params, SimMetricsParams, gravity)}}});
  check(compute("sim/resort_fixup.comp"),
        {{"FixupBlock",
          sizeof(SimFixupParams),
          {TS_MEMBER(params, SimFixupParams, sizes), TS_MEMBER(params, SimFixupParams, models)}}});
  const BlockSpec bonds{"BondBlock",
                        sizeof(SimBondParams),
                        {TS_MEMBER(params, SimBondParams, sizes), TS_MEMBER(params, SimBondParams, step)}};
  const BlockSpec bonds64{"BondBlock",
                          sizeof(SimBondParams64),
                          {TS_MEMBER(params, SimBondParams64, sizes), TS_MEMBER(params, SimBondParams64, step)}};
  for (const char* kernel : {"sim/bond_forces.comp", "sim/bond_sums.comp"}) {
    check(compute(kernel), {bonds});
    check(compute(kernel, {"TS_FP64 1"}), {bonds64});
    check(compute(kernel, {"TS_FP64 1", "TS_CONTACT_FP64 1"}), {bonds64});
  }
  check(compute("sim/resort_bonds.comp"), {item_count("BondsBlock")});
  check(compute("sim/gather_rows.comp"),
        {{"GatherBlock", sizeof(SimGatherParams), {TS_MEMBER(params, SimGatherParams, shape)}}});
}

TEST_F(GpuParams, PreviewProgramsMatchCpp) {
  check(Program::graphics(library, "preview/particles.vert", "", "preview/particles.frag"),
        {camera(),
         {"ParticleBlock",
          sizeof(ParticleParams),
          {TS_MEMBER(params, ParticleParams, flags), TS_MEMBER(params, ParticleParams, color)}}});
  check(Program::graphics(library, "preview/raycast.vert", "", "preview/raycast.frag"),
        {camera(),
         volume(),
         field(),
         {"RaycastBlock",
          sizeof(RaycastParams),
          {TS_MEMBER(params, RaycastParams, flags), TS_MEMBER(params, RaycastParams, steps),
           TS_MEMBER(params, RaycastParams, surface_color)}}});
  check(Program::graphics(library, "preview/shade.vert", "", "preview/shade.frag"),
        {camera(),
         volume(),
         field(),
         {"ShadeBlock",
          sizeof(ShadeParams),
          {TS_MEMBER(params, ShadeParams, light_view_projection), TS_MEMBER(params, ShadeParams, flags),
           TS_MEMBER(params, ShadeParams, shadow), TS_MEMBER(params, ShadeParams, light_dir),
           TS_MEMBER(params, ShadeParams, world_up), TS_MEMBER(params, ShadeParams, ground),
           TS_MEMBER(params, ShadeParams, ground_color), TS_MEMBER(params, ShadeParams, background_top),
           TS_MEMBER(params, ShadeParams, background_bottom)}}});
}

BlockSpec preview_compute() {
  return {"ComputeBlock",
          sizeof(PreviewComputeParams),
          {TS_MEMBER(params, PreviewComputeParams, flags), TS_MEMBER(params, PreviewComputeParams, sizes),
           TS_MEMBER(params, PreviewComputeParams, steps), TS_MEMBER(params, PreviewComputeParams, surface_color),
           TS_MEMBER(params, PreviewComputeParams, particle_color), TS_MEMBER(params, PreviewComputeParams, mode)}};
}

TEST_F(GpuParams, PreviewComputeKernelsMatchCpp) {
  check(compute("preview/splat.comp"), {camera(), preview_compute()});
  check(compute("preview/trace.comp"), {camera(), volume(), field(), preview_compute()});
}

TEST_F(GpuParams, TestKernelsMatchCpp) {
  check(compute("test/saxpy.comp"),
        {{"SaxpyBlock",
          sizeof(SaxpyParams),
          {TS_MEMBER(params, SaxpyParams, count), TS_MEMBER(params, SaxpyParams, scale)}}});
  check(Program::graphics(library, "preview/shade.vert", "", "test/solid_color.frag"),
        {{"SolidColorBlock", sizeof(SolidColorParams), {TS_MEMBER(params, SolidColorParams, color)}}});
  check(compute("test/sparse_field_probe.comp"),
        {field(),
         {"ProbeBlock",
          sizeof(FieldProbeParams),
          {TS_MEMBER(params, FieldProbeParams, count), TS_MEMBER(params, FieldProbeParams, mode)}}});
}

}  // namespace
}  // namespace ts::gpu
