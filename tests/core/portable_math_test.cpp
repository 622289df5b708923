#include "toonray/core/portable_math.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>

namespace toonray {
namespace {

// Distance in units in the last place between two finite doubles of the same sign.
std::int64_t ulps(double a, double b) {
    std::int64_t ia, ib;
    std::memcpy(&ia, &a, 8);
    std::memcpy(&ib, &b, 8);
    if (ia < 0) ia = std::numeric_limits<std::int64_t>::min() - ia;
    if (ib < 0) ib = std::numeric_limits<std::int64_t>::min() - ib;
    return ia > ib ? ia - ib : ib - ia;
}
std::int64_t ulps(float a, float b) {
    std::int32_t ia, ib;
    std::memcpy(&ia, &a, 4);
    std::memcpy(&ib, &b, 4);
    if (ia < 0) ia = std::numeric_limits<std::int32_t>::min() - ia;
    if (ib < 0) ib = std::numeric_limits<std::int32_t>::min() - ib;
    return ia > ib ? std::int64_t{ia} - ib : std::int64_t{ib} - ia;
}

// A deterministic sweep of arguments: small, around multiples of pi/2, and up to 1000.
template <class F>
void sweep(double lo, double hi, int n, F check) {
    for (int i = 0; i <= n; ++i) check(lo + (hi - lo) * i / n);
}

TEST(PortableMath, ExactValues) {
    EXPECT_EQ(portable::sin(0.0), 0.0);
    EXPECT_TRUE(std::signbit(portable::sin(-0.0)));
    EXPECT_EQ(portable::cos(0.0), 1.0);
    EXPECT_EQ(portable::tan(0.0), 0.0);
    EXPECT_EQ(portable::sin(0.0f), 0.0f);
    EXPECT_EQ(portable::cos(0.0f), 1.0f);
    EXPECT_EQ(portable::exp(0.0), 1.0);
    EXPECT_EQ(portable::log(1.0), 0.0);
    EXPECT_EQ(portable::log(0.0), -std::numeric_limits<double>::infinity());
    EXPECT_TRUE(std::isnan(portable::log(-1.0)));
    EXPECT_EQ(portable::exp(-1000.0), 0.0);
    EXPECT_EQ(portable::exp(1000.0), std::numeric_limits<double>::infinity());
    EXPECT_TRUE(std::isnan(portable::sin(std::numeric_limits<double>::infinity())));
    EXPECT_TRUE(std::isnan(portable::cos(std::numeric_limits<double>::quiet_NaN())));
    // Correctly rounded float results of well-known values.
    EXPECT_EQ(portable::cos(0.0f), 1.0f);
    EXPECT_EQ(portable::sin(static_cast<float>(M_PI / 6)), 0.5f);
    EXPECT_EQ(portable::tan(static_cast<float>(M_PI / 4)), 1.0f);
    EXPECT_EQ(portable::cos(static_cast<float>(M_PI / 3)),
              0x1.fffffep-2f);  // the float below pi/3 is above it
    EXPECT_EQ(portable::pow(2.0f, 10.0f), 1024.0f);
    EXPECT_EQ(portable::pow(4.0f, 0.5f), 2.0f);
    EXPECT_EQ(portable::pow(10.0f, 3.0f), 1000.0f);
    EXPECT_EQ(portable::pow(0.5f, 2.0f), 0.25f);
    EXPECT_EQ(portable::pow(7.0f, 1.0f), 7.0f);
    EXPECT_EQ(portable::pow(7.0f, 0.0f), 1.0f);
    EXPECT_EQ(portable::pow(1.0f, std::numeric_limits<float>::quiet_NaN()), 1.0f);
    EXPECT_EQ(portable::pow(-2.0f, 3.0f), -8.0f);
    EXPECT_EQ(portable::pow(-2.0f, 2.0f), 4.0f);
    EXPECT_TRUE(std::isnan(portable::pow(-2.0f, 0.5f)));
    EXPECT_EQ(portable::pow(0.0f, 2.5f), 0.0f);
    EXPECT_EQ(portable::pow(0.0f, -1.0f), std::numeric_limits<float>::infinity());
    EXPECT_EQ(portable::pow(-0.0f, -1.0f), -std::numeric_limits<float>::infinity());
    EXPECT_EQ(portable::pow(0.5f, std::numeric_limits<float>::infinity()), 0.0f);
    EXPECT_EQ(portable::pow(2.0f, -std::numeric_limits<float>::infinity()), 0.0f);
    EXPECT_EQ(portable::pow(2.0f, 200.0f), std::numeric_limits<float>::infinity());
}

TEST(PortableMath, DoubleWithinTwoUlpOfLibm) {
    // glibc's double sin, cos, exp and log are within 1 ulp of the exact result, so two
    // correctly implemented functions differ by at most 2 (tan: 3).
    std::int64_t worst_sin = 0, worst_cos = 0, worst_tan = 0;
    auto angles = [&](double x) {
        worst_sin = std::max(worst_sin, ulps(portable::sin(x), std::sin(x)));
        worst_cos = std::max(worst_cos, ulps(portable::cos(x), std::cos(x)));
        worst_tan = std::max(worst_tan, ulps(portable::tan(x), std::tan(x)));
    };
    sweep(-10.0, 10.0, 200001, angles);
    sweep(-1000.0, 1000.0, 100001, angles);
    for (int k = -64; k <= 64; ++k) {  // near multiples of pi/4, away from the zeros themselves
        for (double d : {-1e-3, -1e-6, 1e-6, 1e-3}) angles(k * M_PI / 4 + d);
    }
    EXPECT_LE(worst_sin, 2);
    EXPECT_LE(worst_cos, 2);
    EXPECT_LE(worst_tan, 3);
    std::int64_t worst_exp = 0, worst_log = 0;
    sweep(-740.0, 709.0, 200001,
          [&](double x) { worst_exp = std::max(worst_exp, ulps(portable::exp(x), std::exp(x))); });
    sweep(1e-300, 1e300, 10001,
          [&](double x) { worst_log = std::max(worst_log, ulps(portable::log(x), std::log(x))); });
    sweep(0.01, 100.0, 200001,
          [&](double x) { worst_log = std::max(worst_log, ulps(portable::log(x), std::log(x))); });
    EXPECT_LE(worst_exp, 2);
    EXPECT_LE(worst_log, 2);
    EXPECT_EQ(ulps(portable::log(4.9e-324), std::log(4.9e-324)), 0);  // subnormal input
}

TEST(PortableMath, FloatCorrectlyRounded) {
    // Float results round a nearly exact double once, so they are the correctly rounded value
    // (here: the long double result rounded to float) but in rare halfway cases. glibc's float
    // functions are within 1 ulp of it.
    std::int64_t worst_libm = 0;
    int misrounded = 0, total = 0;
    auto check = [&](float got, long double exact, float libm) {
        worst_libm = std::max(worst_libm, ulps(got, libm));
        misrounded += got != static_cast<float>(exact);
        ++total;
    };
    sweep(-20.0, 20.0, 400001, [&](double xd) {
        const float x = static_cast<float>(xd);
        const long double xl = x;
        check(portable::sin(x), std::sin(xl), std::sin(x));
        check(portable::cos(x), std::cos(xl), std::cos(x));
        if (std::fabs(std::cos(x)) > 1e-3f) check(portable::tan(x), std::tan(xl), std::tan(x));
    });
    sweep(1e-3, 1.0, 100001, [&](double xd) {
        const float x = static_cast<float>(xd);
        for (float y : {0.62f, 1.4f, 2.0f, 10.0f, 32.0f, 100.0f, 1000.0f})
            check(portable::pow(x, y),
                  std::pow(static_cast<long double>(x), static_cast<long double>(y)),
                  std::pow(x, y));
    });
    EXPECT_LE(worst_libm, 1);
    EXPECT_LT(misrounded, total / 100000)
        << misrounded << " of " << total << " not correctly rounded";
}

TEST(PortableMath, Deterministic) {
    // Known bits, computed once: any platform must give exactly these.
    EXPECT_EQ(portable::cos(1.0), 0x1.14a280fb5068cp-1);
    EXPECT_EQ(portable::sin(1.0), 0x1.aed548f090ceep-1);
    EXPECT_EQ(portable::tan(1.0), 0x1.8eb245cbee3a5p+0);
    EXPECT_EQ(portable::exp(1.0), 0x1.5bf0a8b14576ap+1);  // 1 ulp above e's nearest double
    EXPECT_EQ(portable::log(10.0), 0x1.26bb1bbb55516p+1);
    EXPECT_EQ(portable::pow(0.9f, 50.0f), 0x1.51c1e2p-8f);
    EXPECT_EQ(portable::tan(0.5f), 0x1.17b4f6p-1f);
}

}  // namespace
}  // namespace toonray
