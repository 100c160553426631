// The SDF as the sampler reads it: a 3D texture (xyz: unit gradient, w: signed distance [m]) with
// hardware trilinear filtering. Particle positions are relative to voxel (0,0,0)'s centre, in metres,
// so float precision does not depend on where the mesh sits.
#ifndef TETRASAND_SAMPLER_SDF_SAMPLE_GLSL
#define TETRASAND_SAMPLER_SDF_SAMPLE_GLSL

layout(binding = TS_SAMPLER_UNIT_SDF) uniform sampler3D sdf;  // the including kernel includes sampler/bindings.h
uniform float voxel_size;  // [m]
uniform vec3 sdf_dims;     // voxels along x, y, z

// xyz: unit gradient (zero where undefined), w: signed distance [m].
vec4 sample_sdf(vec3 p) {
  vec4 s = texture(sdf, (p / voxel_size + 0.5) / sdf_dims);
  float len = length(s.xyz);
  return vec4(len > 1e-6 ? s.xyz / len : vec3(0.0), s.w);
}

#endif
