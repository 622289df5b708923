#pragma once
/// Elementary functions that give the same bits on every platform. The C library's sin, cos,
/// tan, pow, exp and log are not exact IEEE operations: their results depend on the libm (glibc
/// version, CPU-specific code paths, other C libraries), so a frame computed with them could
/// differ between the machines of a render cluster. These are written with IEEE operations only
/// (+, -, *, /, conversions, ldexp; the project compiles with -ffp-contract=off, so nothing is
/// fused), and therefore round identically wherever they run.
///
/// Accuracy: the double versions are within 2 ulp of the exact result (sin, cos, exp, log within
/// 1 ulp; tan, a quotient of the two kernels, within 2) for |x| < 2^19 pi/2 (angles; beyond that
/// the argument reduction loses accuracy but stays deterministic). The float versions evaluate in
/// double and round once, so they are correctly rounded except in rare cases within 2^-40
/// relative of a halfway point. (glibc 2.36's sinf, cosf and tanf are within 1 ulp but not
/// correctly rounded: they differ from these for 1 to 4 % of arguments, by 1 ulp.)
///
/// std::sqrt, std::fabs, std::floor, std::ceil, std::round, std::fmin, std::fmax, std::fmod and
/// std::ldexp are exact IEEE operations and need no replacement.

#include <cmath>

namespace toonray::portable {

/// Sine, cosine and tangent of an angle in radians.
double sin(double x);
double cos(double x);
double tan(double x);
float sin(float x);
float cos(float x);
float tan(float x);

/// e^x and the natural logarithm (log(x < 0) is NaN, log(0) is -inf).
double exp(double x);
double log(double x);

/// x^y with C's special cases (pow(x, 0) = 1, pow(1, y) = 1, negative x only for integer y, ...).
float pow(float x, float y);

/// sqrt(x^2 + y^2) in float, with two roundings before the square root (std::hypot avoids
/// overflow at the cost of a libm-specific algorithm; screen-space lengths never come near it).
inline float hypot(float x, float y) { return std::sqrt(x * x + y * y); }

}  // namespace toonray::portable
