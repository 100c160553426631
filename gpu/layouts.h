#pragma once
// C++ view of the GPU buffer layouts defined once in shaders/common/layouts.h, pinned here so a
// layout change that breaks std430 agreement fails the build; tests/gpu/layouts_test.cpp checks
// the same numbers against what the GLSL compiler reports.
#include <cstddef>

#include "shaders/common/layouts.h"

namespace ts::gpu::layout {

static_assert(sizeof(vec4) == 16 && alignof(vec4) == 16);
static_assert(sizeof(SdfTriangle) == 160);
static_assert(offsetof(SdfTriangle, face_normal) == 48);
static_assert(offsetof(SdfTriangle, edge_normal) == 64);
static_assert(offsetof(SdfTriangle, vertex_normal) == 112);
static_assert(sizeof(SdfPrism) == 80);
static_assert(offsetof(SdfPrism, normal_margin) == 64);
static_assert(sizeof(FieldRootTile) == 32);
static_assert(offsetof(FieldRootTile, address) == 16);
static_assert(sizeof(SamplerGrid) == 32);
static_assert(offsetof(SamplerGrid, dims) == 16);
static_assert(sizeof(CertTriangle) == 48);
static_assert(offsetof(CertTriangle, edge2) == 32);
static_assert(sizeof(CertLeaf) == 32);
static_assert(offsetof(CertLeaf, bounds) == 16);
static_assert(sizeof(SimPair) == 32);
static_assert(offsetof(SimPair, extra) == 16);
static_assert(sizeof(SimPlane) == 48);
static_assert(offsetof(SimPlane, extent) == 16);
static_assert(offsetof(SimPlane, material) == 32);
static_assert(sizeof(SimCylinder) == 48);
static_assert(offsetof(SimCylinder, material) == 32);
static_assert(sizeof(SimSpringSlots) == 240);
static_assert(offsetof(SimSpringSlots, displacement) == 48);
static_assert(sizeof(dvec4) == 32 && alignof(dvec4) == 32);
static_assert(sizeof(SimSpringSlots64) == 448);
static_assert(offsetof(SimSpringSlots64, displacement) == 64);

}  // namespace ts::gpu::layout
