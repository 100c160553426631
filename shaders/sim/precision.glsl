// Float by default; TS_FP64 switches the simulator's state and arithmetic to double (GLSL fp64) so the
// precision trade can be measured (double is core in GLSL 4.00+; transcendental functions stay
// float). The hashed grid always works on a float copy of the positions.
#ifndef TETRASAND_SIM_PRECISION_GLSL
#define TETRASAND_SIM_PRECISION_GLSL
#ifdef TS_FP64
#define real double
#define real2 dvec2
#define real3 dvec3
#define real4 dvec4
#else
#define real float
#define real2 vec2
#define real3 vec3
#define real4 vec4
#endif
#endif
