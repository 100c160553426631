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
// The contact arithmetic (sim/contact.glsl and the per-contact math of sim/contact_forces.comp):
// float in both pipelines by default. The double pipeline is then mixed precision: positions and
// velocities are differenced in double and the difference rounded to float (exact to float relative
// to the pair's separation), the force law runs in float, and body state and integration stay double.
// TS_CONTACT_FP64 (with TS_FP64) keeps the whole contact kernel in double, the full-double pipeline the
// mixed one is measured against (sim::Precision::FullDouble).
#if defined(TS_FP64) && defined(TS_CONTACT_FP64)
#define creal double
#define creal2 dvec2
#define creal3 dvec3
#else
#define creal float
#define creal2 vec2
#define creal3 vec3
#endif
#endif
