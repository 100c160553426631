#version 450
#extension GL_GOOGLE_include_directive : require
// Scan conversion, geometry stage (thesis 6.2.1 after Erleben & Dohlmann 2006): the triangle's bounding
// prism is split into tetrahedra, each tetrahedron is intersected with the voxel-centre planes z = k
// it spans, and every cross-section (a triangle, or a quad as a 4-vertex strip) is emitted to layer k.
//
// One invocation may emit only 1024 output components, so it cannot cover a large triangle alone:
// each of the INVOCATIONS instances handles LAYERS_PER_INVOCATION consecutive layers, one draw covers
// INVOCATIONS * LAYERS_PER_INVOCATION layers starting at draw_first_layer, and the host issues as many
// draws per slab as the slab has layers. Worst case per layer: a box prism = 6 tetrahedra x 4 vertices.
#include "common/layouts.h"
#include "sdf/bindings.h"

// The host compiles two variants: INVOCATIONS 32 for triangles whose prism spans many layers, and
// INVOCATIONS 4 for the common small ones, so a small triangle does not pay for 28 idle invocations.
#ifndef INVOCATIONS
#define INVOCATIONS 32
#endif
#define LAYERS_PER_INVOCATION 4
layout(lines_adjacency, invocations = INVOCATIONS) in;
layout(triangle_strip, max_vertices = 96) out;

layout(std430, binding = TS_SDF_PRISMS) readonly buffer Prisms { SdfPrism prisms[]; };

#include "common/params.h"
layout(std140, binding = TS_SDF_SCAN_PARAMS) uniform ScanConvertBlock { ScanConvertParams params; };

flat in uint v_triangle[];
flat out uint g_triangle;

void emit(vec3 p, int layer) {
  // Voxel centre i sits at pixel centre i + 0.5.
  gl_Position = vec4((p.xy + 0.5) / params.grid.xy * 2.0 - 1.0, 0.0, 1.0);
  gl_Layer = layer;
  g_triangle = v_triangle[0];
  EmitVertex();
}

// Where the edge from a vertex above the slice plane (signed height sa > 0) to one below (sb <= 0)
// crosses it; sa - sb never vanishes. Always called above-to-below and `precise` (no contraction that
// could differ between call sites), so an edge shared by two tetrahedra gives the bitwise same point
// in both, and their slices meet without a crack a voxel centre could fall into.
vec3 edge_point(vec3 above, vec3 below, float sa, float sb) {
  precise vec3 p = mix(above, below, sa / (sa - sb));
  return p;
}

void slice_tetrahedron(vec3 v0, vec3 v1, vec3 v2, vec3 v3, float z, int layer) {
  vec3 v[4] = vec3[4](v0, v1, v2, v3);
  float s[4] = float[4](v0.z - z, v1.z - z, v2.z - z, v3.z - z);
  int above[4];
  int below[4];
  int na = 0, nb = 0;
  for (int i = 0; i < 4; ++i) {
    if (s[i] > 0.0) above[na++] = i; else below[nb++] = i;
  }
  if (na == 0 || nb == 0) return;
  if (na == 2) {
    int a = above[0], b = above[1], c = below[0], d = below[1];
    // The quad's cycle is ac, ad, bd, bc; as a strip: ac, ad, bc, bd.
    emit(edge_point(v[a], v[c], s[a], s[c]), layer);
    emit(edge_point(v[a], v[d], s[a], s[d]), layer);
    emit(edge_point(v[b], v[c], s[b], s[c]), layer);
    emit(edge_point(v[b], v[d], s[b], s[d]), layer);
  } else {
    int lone = na == 1 ? above[0] : below[0];
    for (int i = 0; i < 4; ++i) {
      if (i == lone) continue;
      if (na == 1) {
        emit(edge_point(v[lone], v[i], s[lone], s[i]), layer);
      } else {
        emit(edge_point(v[i], v[lone], s[i], s[lone]), layer);
      }
    }
  }
  EndPrimitive();
}

void slice_triangular_prism(vec3 a, vec3 b, vec3 c, vec3 a2, vec3 b2, vec3 c2, float z, int layer) {
  // The standard 3-tetrahedron split of prism abc-a2b2c2.
  slice_tetrahedron(a, b, c, a2, z, layer);
  slice_tetrahedron(b, c, a2, b2, z, layer);
  slice_tetrahedron(c, a2, b2, c2, z, layer);
}

void main() {
  SdfPrism prism = prisms[v_triangle[0]];
  int corners = int(prism.corner[0].w);
  vec3 offset = prism.normal_margin.xyz * prism.normal_margin.w;
  vec3 lo[4], hi[4];
  float zmin = 1e30, zmax = -1e30;
  for (int i = 0; i < 4; ++i) {
    lo[i] = prism.corner[i].xyz - offset;
    hi[i] = prism.corner[i].xyz + offset;
    if (i < corners) {
      zmin = min(zmin, min(lo[i].z, hi[i].z));
      zmax = max(zmax, max(lo[i].z, hi[i].z));
    }
  }
  // Invocations start at the prism's own first layer in this draw (not at the draw's first layer):
  // the host sends a triangle to the variant whose INVOCATIONS cover its span.
  int start = max(params.layers.z, int(ceil(zmin)) - params.layers.x);
  int first = start + gl_InvocationID * LAYERS_PER_INVOCATION;
  int last = min(min(first + LAYERS_PER_INVOCATION - 1, params.layers.y - 1), params.layers.z + params.layers.w - 1);
  int layer_lo = first;
  int layer_hi = min(last, int(floor(zmax)) - params.layers.x);
  for (int layer = layer_lo; layer <= layer_hi; ++layer) {
    float z = float(params.layers.x + layer);
    slice_triangular_prism(lo[0], lo[1], lo[2], hi[0], hi[1], hi[2], z, layer);
    if (corners == 4) slice_triangular_prism(lo[0], lo[2], lo[3], hi[0], hi[2], hi[3], z, layer);
  }
}
