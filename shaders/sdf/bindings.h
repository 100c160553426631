// Buffer bindings and image units of the sdf passes, shared by GLSL and C++ (sdf/scan_convert.cpp).
//
// Slots per pass (program):
//   scan conversion (scan_convert.vert + scan_convert.geom + scan_convert.frag):
//     buffers TS_SDF_PRISMS (geometry stage), TS_SDF_TRIANGLES (fragment stage)
//   finish texture (finish_texture.comp):
//     buffer TS_SDF_INSIDE_BITS, image unit TS_SDF_FIELD_IMAGE
//
// The finishing pass runs after the last scan-conversion draw and both bind their slots before they
// run, so the two passes may share slot numbers.
#ifndef TETRASAND_SDF_BINDINGS_H
#define TETRASAND_SDF_BINDINGS_H

#define TS_SDF_TRIANGLES 0    // SdfTriangle[]: the triangles in grid-local voxel units
#define TS_SDF_PRISMS 1       // SdfPrism[]: each triangle's bounding prism
#define TS_SDF_INSIDE_BITS 0  // uint[]: bit v set for an inside voxel off the band (linear index v)

#define TS_SDF_FIELD_IMAGE 0  // image3D rgba32f: the SDF texture, finished in place

#endif
