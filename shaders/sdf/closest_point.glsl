// Exact closest point on a triangle with the feature that holds it (Ericson, Real-Time Collision
// Detection, 5.1.5): the feature picks the pseudonormal that decides the sign (Baerentzen & Aanaes 2005).
#ifndef TETRASAND_SDF_CLOSEST_POINT_GLSL
#define TETRASAND_SDF_CLOSEST_POINT_GLSL

const int FEATURE_FACE = 0;
const int FEATURE_EDGE = 1;    // + edge index 0..2 (edge e runs from vertex e to vertex e+1)
const int FEATURE_VERTEX = 4;  // + vertex index 0..2

// Returns the closest point; `feature` receives FEATURE_* + index. `n` is the unit face normal: in
// the face region the point is projected along it, because the barycentric route (products of
// squared lengths, then differences) loses float precision on triangles hundreds of voxels long.
vec3 closest_point_on_triangle(vec3 p, vec3 a, vec3 b, vec3 c, vec3 n, out int feature) {
  vec3 ab = b - a, ac = c - a, ap = p - a;
  float d1 = dot(ab, ap), d2 = dot(ac, ap);
  if (d1 <= 0.0 && d2 <= 0.0) { feature = FEATURE_VERTEX + 0; return a; }
  vec3 bp = p - b;
  float d3 = dot(ab, bp), d4 = dot(ac, bp);
  if (d3 >= 0.0 && d4 <= d3) { feature = FEATURE_VERTEX + 1; return b; }
  float vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) { feature = FEATURE_EDGE + 0; return a + ab * (d1 / (d1 - d3)); }
  vec3 cp = p - c;
  float d5 = dot(ab, cp), d6 = dot(ac, cp);
  if (d6 >= 0.0 && d5 <= d6) { feature = FEATURE_VERTEX + 2; return c; }
  float vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) { feature = FEATURE_EDGE + 2; return a + ac * (d2 / (d2 - d6)); }
  float va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0) {
    feature = FEATURE_EDGE + 1;
    return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
  }
  feature = FEATURE_FACE;
  return p - dot(ap, n) * n;
}

#endif
