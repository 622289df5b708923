// The kernels and argument reductions follow fdlibm (Sun Microsystems, 1993; the version in
// musl), whose polynomial coefficients are minimax fits on the reduced ranges. fdlibm itself
// is written with IEEE operations only, which is what makes it portable: any compiler that does
// not contract a * b + c into a fused multiply-add (the project builds with -ffp-contract=off)
// computes the same bits on every CPU.
#include "toonray/core/portable_math.h"

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>

namespace toonray::portable {
namespace {

// sin(x) on [-pi/4, pi/4] (fdlibm __kernel_sin with a zero tail).
double kernel_sin(double x) {
    constexpr double S1 = -1.66666666666666324348e-01, S2 = 8.33333333332248946124e-03,
                     S3 = -1.98412698298579493134e-04, S4 = 2.75573137070700676789e-06,
                     S5 = -2.50507602534068634195e-08, S6 = 1.58969099521155010221e-10;
    if (std::fabs(x) < 0x1p-27) return x;  // sin x = x to within half an ulp (keeps -0)
    const double z = x * x;
    const double v = z * x;
    const double r = S2 + z * (S3 + z * (S4 + z * (S5 + z * S6)));
    return x + v * (S1 + z * r);
}

// cos(x) on [-pi/4, pi/4] (fdlibm __kernel_cos with a zero tail).
double kernel_cos(double x) {
    constexpr double C1 = 4.16666666666666019037e-02, C2 = -1.38888888888741095749e-03,
                     C3 = 2.48015872894767294178e-05, C4 = -2.75573143513906633035e-07,
                     C5 = 2.08757232129817482790e-09, C6 = -1.13596475577881948265e-11;
    const double z = x * x;
    const double w = z * z;
    const double r = z * (C1 + z * (C2 + z * C3)) + w * w * (C4 + z * (C5 + z * C6));
    const double hz = 0.5 * z;
    const double one_minus = 1.0 - hz;
    return one_minus + (((1.0 - one_minus) - hz) + z * r);
}

// x = n pi/2 + r with |r| <= pi/4 (about): pi/2 in three parts, the first two with 33
// significant bits so that n * part is exact for |n| < 2^20 (Cody and Waite).
struct Reduced {
    double r;
    int n;  // the quadrant, n mod 4
};
Reduced reduce(double x) {
    constexpr double inv_pio2 = 6.36619772367581382433e-01;  // 0x3FE45F306DC9C883
    constexpr double pio2_1 = 0x1.921fb544p+0, pio2_2 = 0x1.0b4611a6p-34,
                     pio2_2t = 0x1.3198a2e037073p-69;
    if (std::fabs(x) <= 0x1.921fb54442d18p-1) return {x, 0};  // |x| <= pi/4
    // Round to the nearest integer (ties to even) by adding 1.5 * 2^52 (exact IEEE rounding).
    constexpr double to_int = 6755399441055744.0;
    const double fn = (x * inv_pio2 + to_int) - to_int;
    const double r = ((x - fn * pio2_1) - fn * pio2_2) - fn * pio2_2t;
    const auto n = static_cast<std::int64_t>(fn);
    return {r, static_cast<int>(n & 3)};
}

bool finite(double x) { return std::fabs(x) <= std::numeric_limits<double>::max(); }

}  // namespace

double sin(double x) {
    if (!finite(x)) return std::numeric_limits<double>::quiet_NaN();
    const Reduced a = reduce(x);
    switch (a.n) {
        case 0: return kernel_sin(a.r);
        case 1: return kernel_cos(a.r);
        case 2: return -kernel_sin(a.r);
        default: return -kernel_cos(a.r);
    }
}

double cos(double x) {
    if (!finite(x)) return std::numeric_limits<double>::quiet_NaN();
    const Reduced a = reduce(x);
    switch (a.n) {
        case 0: return kernel_cos(a.r);
        case 1: return -kernel_sin(a.r);
        case 2: return -kernel_cos(a.r);
        default: return kernel_sin(a.r);
    }
}

double tan(double x) {
    if (!finite(x)) return std::numeric_limits<double>::quiet_NaN();
    const Reduced a = reduce(x);
    const double s = kernel_sin(a.r), c = kernel_cos(a.r);
    return (a.n & 1) ? -c / s : s / c;
}

float sin(float x) { return static_cast<float>(sin(static_cast<double>(x))); }
float cos(float x) { return static_cast<float>(cos(static_cast<double>(x))); }
float tan(float x) { return static_cast<float>(tan(static_cast<double>(x))); }

// fdlibm __ieee754_exp: x = k ln2 + r, |r| <= ln2 / 2, and a rational approximation of e^r.
double exp(double x) {
    constexpr double ln2_hi = 6.93147180369123816490e-01, ln2_lo = 1.90821492927058770002e-10,
                     inv_ln2 = 1.44269504088896338700e+00;
    constexpr double P1 = 1.66666666666666019037e-01, P2 = -2.77777777770155933842e-03,
                     P3 = 6.61375632143793436117e-05, P4 = -1.65339022054652515390e-06,
                     P5 = 4.13813679705723846039e-08;
    if (x != x) return x;
    if (x > 709.782712893383973096) return std::numeric_limits<double>::infinity();
    if (x < -745.13321910194110842) return 0.0;
    double hi, lo;
    int k;
    const double ax = std::fabs(x);
    if (ax > 0.5 * 0.6931471805599453) {
        if (ax >= 1.5 * 0.6931471805599453)
            k = static_cast<int>(inv_ln2 * x +
                                 (x < 0 ? -0.5 : 0.5));  // truncation: round half away
        else k = x < 0 ? -1 : 1;
        hi = x - k * ln2_hi;  // exact: k ln2_hi has few bits
        lo = k * ln2_lo;
        x = hi - lo;
    } else if (ax > 0x1p-28) {
        k = 0;
        hi = x;
        lo = 0;
    } else {
        return 1.0 + x;
    }
    const double xx = x * x;
    const double c = x - xx * (P1 + xx * (P2 + xx * (P3 + xx * (P4 + xx * P5))));
    const double y = 1.0 + (x * c / (2.0 - c) - lo + hi);
    return k == 0 ? y : std::ldexp(y, k);
}

// fdlibm __ieee754_log: x = 2^k m with sqrt(2)/2 < m < sqrt(2), log(m) from s = f / (2 + f),
// f = m - 1, by a polynomial in s^2.
double log(double x) {
    constexpr double ln2_hi = 6.93147180369123816490e-01, ln2_lo = 1.90821492927058770002e-10;
    constexpr double Lg1 = 6.666666666666735130e-01, Lg2 = 3.999999999940941908e-01,
                     Lg3 = 2.857142874366239149e-01, Lg4 = 2.222219843214978396e-01,
                     Lg5 = 1.818357216161805012e-01, Lg6 = 1.531383769920937332e-01,
                     Lg7 = 1.479819860511658591e-01;
    if (x != x) return x;
    if (x < 0) return std::numeric_limits<double>::quiet_NaN();
    if (x == 0) return -std::numeric_limits<double>::infinity();
    if (x == std::numeric_limits<double>::infinity()) return x;
    int k = 0;
    if (x < std::numeric_limits<double>::min()) {  // subnormal: scale into the normal range
        x *= 0x1p54;
        k = -54;
    }
    std::uint64_t bits;
    std::memcpy(&bits, &x, 8);
    // Shift the exponent so that the mantissa lands in [sqrt(2)/2, sqrt(2)).
    std::uint32_t hx = static_cast<std::uint32_t>(bits >> 32);
    hx += 0x3ff00000 - 0x3fe6a09e;
    k += static_cast<int>(hx >> 20) - 0x3ff;
    hx = (hx & 0x000fffff) + 0x3fe6a09e;
    bits = (static_cast<std::uint64_t>(hx) << 32) | (bits & 0xffffffffu);
    double m;
    std::memcpy(&m, &bits, 8);
    const double f = m - 1.0;
    const double hfsq = 0.5 * f * f;
    const double s = f / (2.0 + f);
    const double z = s * s;
    const double w = z * z;
    const double t1 = w * (Lg2 + w * (Lg4 + w * Lg6));
    const double t2 = z * (Lg1 + w * (Lg3 + w * (Lg5 + w * Lg7)));
    const double r = t2 + t1;
    const double dk = k;
    return s * (hfsq + r) + dk * ln2_lo - hfsq + f + dk * ln2_hi;
}

float pow(float x, float y) {
    const float inf = std::numeric_limits<float>::infinity();
    if (y == 0.0f || x == 1.0f) return 1.0f;
    if (x != x || y != y) return std::numeric_limits<float>::quiet_NaN();
    if (y == 1.0f) return x;
    const bool y_integer = std::floor(y) == y;
    // |y| >= 2^24 is an even integer in float.
    const bool y_odd = y_integer && std::fabs(y) < 0x1p24f && std::fmod(y, 2.0f) != 0.0f;
    if (x == 0.0f) {
        if (y > 0) return y_odd ? x : 0.0f;
        return y_odd ? std::copysign(inf, x) : inf;
    }
    if (std::fabs(y) == inf) {
        const float ax = std::fabs(x);
        if (ax == 1.0f) return 1.0f;
        return (ax > 1.0f) == (y > 0) ? inf : 0.0f;
    }
    if (x < 0) {
        if (!y_integer) return std::numeric_limits<float>::quiet_NaN();
        const float p = pow(-x, y);
        return y_odd ? -p : p;
    }
    if (x == inf) return y > 0 ? inf : 0.0f;
    // e^(y log x) in double: the product's relative error is about |y log x| 2^-53, at most
    // about 2^-46 where the float result is finite and normal, far below float's 2^-24.
    return static_cast<float>(exp(static_cast<double>(y) * log(static_cast<double>(x))));
}

}  // namespace toonray::portable
