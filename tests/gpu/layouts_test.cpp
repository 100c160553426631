// The C++ structs in gpu/layouts.h and the GLSL compiler must agree on every offset and stride.
#include <gtest/gtest.h>

#include <cstddef>
#include <string>

#include "gpu/context.h"
#include "gpu/gl.h"
#include "gpu/layouts.h"

namespace ts::gpu {
namespace {

struct Probe {
  GLint offset = -1;
  GLint top_level_stride = -1;
};

Probe query(const Program& program, const std::string& name) {
  const GLuint index = glGetProgramResourceIndex(program.id(), GL_BUFFER_VARIABLE, name.c_str());
  EXPECT_NE(index, GL_INVALID_INDEX) << name;
  Probe p;
  if (index == GL_INVALID_INDEX) return p;
  const GLenum props[] = {GL_OFFSET, GL_TOP_LEVEL_ARRAY_STRIDE};
  GLint values[2] = {-1, -1};
  glGetProgramResourceiv(program.id(), GL_BUFFER_VARIABLE, index, 2, props, 2, nullptr, values);
  p.offset = values[0];
  p.top_level_stride = values[1];
  return p;
}

class GpuLayouts : public ::testing::Test {
 protected:
  Context context;
  ShaderLibrary library;
  Program probe = Program::compute(library, "test/layout_probe.comp");
};

TEST_F(GpuLayouts, SdfTriangleMatchesCpp) {
  using layout::SdfTriangle;
  EXPECT_EQ(query(probe, "sdf_triangles[0].vertex[0]").top_level_stride, static_cast<GLint>(sizeof(SdfTriangle)));
  EXPECT_EQ(query(probe, "sdf_triangles[0].vertex[0]").offset, static_cast<GLint>(offsetof(SdfTriangle, vertex)));
  EXPECT_EQ(query(probe, "sdf_triangles[0].face_normal").offset, static_cast<GLint>(offsetof(SdfTriangle, face_normal)));
  EXPECT_EQ(query(probe, "sdf_triangles[0].edge_normal[0]").offset,
            static_cast<GLint>(offsetof(SdfTriangle, edge_normal)));
  EXPECT_EQ(query(probe, "sdf_triangles[0].vertex_normal[0]").offset,
            static_cast<GLint>(offsetof(SdfTriangle, vertex_normal)));
}

TEST_F(GpuLayouts, SdfPrismMatchesCpp) {
  using layout::SdfPrism;
  EXPECT_EQ(query(probe, "sdf_prisms[0].corner[0]").top_level_stride, static_cast<GLint>(sizeof(SdfPrism)));
  EXPECT_EQ(query(probe, "sdf_prisms[0].normal_margin").offset, static_cast<GLint>(offsetof(SdfPrism, normal_margin)));
}

TEST_F(GpuLayouts, FieldRootTileMatchesCpp) {
  using layout::FieldRootTile;
  EXPECT_EQ(query(probe, "field_roots[0].origin").top_level_stride, static_cast<GLint>(sizeof(FieldRootTile)));
  EXPECT_EQ(query(probe, "field_roots[0].address").offset, static_cast<GLint>(offsetof(FieldRootTile, address)));
}

TEST_F(GpuLayouts, SamplerGridMatchesCpp) {
  using layout::SamplerGrid;
  EXPECT_EQ(query(probe, "sampler_grids[0].origin_cell").top_level_stride, static_cast<GLint>(sizeof(SamplerGrid)));
  EXPECT_EQ(query(probe, "sampler_grids[0].dims").offset, static_cast<GLint>(offsetof(SamplerGrid, dims)));
}

TEST_F(GpuLayouts, CertificateStructsMatchCpp) {
  using layout::CertLeaf;
  using layout::CertTriangle;
  EXPECT_EQ(query(probe, "cert_triangles[0].corner").top_level_stride,
            static_cast<GLint>(sizeof(CertTriangle)));
  EXPECT_EQ(query(probe, "cert_triangles[0].edge1").offset,
            static_cast<GLint>(offsetof(CertTriangle, edge1)));
  EXPECT_EQ(query(probe, "cert_triangles[0].edge2").offset,
            static_cast<GLint>(offsetof(CertTriangle, edge2)));
  EXPECT_EQ(query(probe, "cert_leaves[0].id").top_level_stride, static_cast<GLint>(sizeof(CertLeaf)));
  EXPECT_EQ(query(probe, "cert_leaves[0].bounds").offset, static_cast<GLint>(offsetof(CertLeaf, bounds)));
}

TEST_F(GpuLayouts, SimStructsMatchCpp) {
  using layout::SimPair;
  using layout::SimPlane;
  EXPECT_EQ(query(probe, "sim_pairs[0].coefficients").top_level_stride, static_cast<GLint>(sizeof(SimPair)));
  EXPECT_EQ(query(probe, "sim_pairs[0].extra").offset, static_cast<GLint>(offsetof(SimPair, extra)));
  EXPECT_EQ(query(probe, "sim_planes[0].normal_offset").top_level_stride, static_cast<GLint>(sizeof(SimPlane)));
  EXPECT_EQ(query(probe, "sim_planes[0].extent").offset, static_cast<GLint>(offsetof(SimPlane, extent)));
  EXPECT_EQ(query(probe, "sim_planes[0].material").offset, static_cast<GLint>(offsetof(SimPlane, material)));
  using layout::SimCylinder;
  EXPECT_EQ(query(probe, "sim_cylinders[0].axis_radius").top_level_stride, static_cast<GLint>(sizeof(SimCylinder)));
  EXPECT_EQ(query(probe, "sim_cylinders[0].material").offset, static_cast<GLint>(offsetof(SimCylinder, material)));
  using layout::SimSpringSlots;
  using layout::SimSpringSlots64;
  EXPECT_EQ(query(probe, "sim_springs[0].partner[0]").top_level_stride, static_cast<GLint>(sizeof(SimSpringSlots)));
  EXPECT_EQ(query(probe, "sim_springs[0].displacement[0]").offset,
            static_cast<GLint>(offsetof(SimSpringSlots, displacement)));
  EXPECT_EQ(query(probe, "sim_springs64[0].partner[0]").top_level_stride,
            static_cast<GLint>(sizeof(SimSpringSlots64)));
  EXPECT_EQ(query(probe, "sim_springs64[0].displacement[0]").offset,
            static_cast<GLint>(offsetof(SimSpringSlots64, displacement)));
}

}  // namespace
}  // namespace ts::gpu
