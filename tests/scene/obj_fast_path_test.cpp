// The fast path's readers (obj_fast_path.h): numbers and face indices read 8 characters at a
// time from the padded zone must read exactly as the general path (from_chars) reads them, or
// decline.

#include "toonray/scene/obj_fast_path.h"

#include <gtest/gtest.h>

#include <charconv>
#include <cstring>
#include <random>
#include <string>

using namespace toonray;
using namespace toonray::wavefront;

namespace {

std::uint32_t bits(float f) {
    std::uint32_t u;
    std::memcpy(&u, &f, 4);
    return u;
}

// A token as it sits in the padded zone: followed by a space and the padding.
struct Padded {
    std::string text;
    explicit Padded(std::string_view token)
        : text(std::string(token) + " " + std::string(kFastPathPadding, '#')) {}
    const char* begin() const { return text.data(); }
    const char* token_end() const { return text.data() + text.size() - kFastPathPadding - 1; }
    const char* end() const { return text.data() + text.size(); }
};

// What the general path reads for a whole token: from_chars, or nothing.
bool reference(std::string_view token, float& out) {
    const auto [ptr, ec] = std::from_chars(token.data(), token.data() + token.size(), out);
    return ec == std::errc() && ptr == token.data() + token.size();
}

std::string random_digits(std::mt19937& rng, int count) {
    std::string s;
    for (int k = 0; k < count; ++k) s += static_cast<char>('0' + rng() % 10);
    return s;
}

}  // namespace

TEST(ReadNumber, BitForBitFromCharsOrDeclined) {
    std::mt19937 rng(11);
    int short_read = 0, short_decimals = 0;
    for (int i = 0; i < 200'000; ++i) {
        // [-]digits[.digits][e[+-]digits], 0 to 17 digits in all.
        const int whole = static_cast<int>(rng() % 10), fraction = static_cast<int>(rng() % 10);
        std::string token = rng() % 2 ? "-" : "";
        token += random_digits(rng, whole);
        const bool point = fraction > 0 || rng() % 4 == 0;
        if (point) token += "." + random_digits(rng, fraction);
        const bool exponent = rng() % 5 == 0;
        if (exponent) {
            token += rng() % 2 ? "e" : "E";
            const unsigned sign = rng() % 3;
            token += sign == 0 ? "" : sign == 1 ? "-" : "+";
            token += random_digits(rng, static_cast<int>(rng() % 5));
        }
        const Padded padded(token);
        const char* p = padded.begin();
        float fast;
        const bool read = read_number(p, padded.end(), fast);
        float expect;
        if (read && p != padded.token_end()) {
            // Stopped inside the token (an integer part of 8 digits or more goes to
            // scan_short_decimal, which stops at an exponent): the caller sees no separator
            // there and leaves the line to the general path.
            ASSERT_LT(p, padded.token_end()) << token;
            ASSERT_FALSE(is_blank(*p)) << token;
            continue;
        }
        if (read) {
            ASSERT_TRUE(reference(token, expect) && std::isfinite(expect)) << token;
            ASSERT_EQ(bits(fast), bits(expect)) << token;
        }
        // The common short decimals are read, bar those that are or lie next to a midpoint
        // between floats (nearest_float; most are integers above 2^24, where every odd integer
        // is one).
        if (!exponent && whole + fraction >= 1 && whole + fraction <= 15 && whole < 8) {
            ++short_decimals;
            short_read += read;
        }
    }
    EXPECT_GT(short_read, short_decimals - short_decimals / 100);
}

TEST(ReadNumber, DecimalsNextToMidpointsBetweenFloats) {
    // For random midpoints m = (2a + 1) / 2^25 between the floats in [0.5, 1), the 14-decimal
    // numbers nearest them (exact integer arithmetic: m * 10^14 = (2a + 1) * 5^14 / 2^11): the
    // hard cases of rounding twice, once to double and then to float.
    std::mt19937 rng(3);
    constexpr std::uint64_t kFive14 = 6103515625;
    int declined = 0;
    for (int i = 0; i < 20'000; ++i) {
        const std::uint64_t odd = 2 * (std::uint64_t{1} << 23 | (rng() & 0x7FFFFF)) + 1;
        for (const std::uint64_t m : {(odd * kFive14) >> 11, ((odd * kFive14) >> 11) + 1}) {
            std::string token = "0." + std::to_string(m);
            token.insert(2, 16 - token.size(), '0');
            const Padded padded(token);
            const char* p = padded.begin();
            float fast, expect;
            ASSERT_TRUE(reference(token, expect));
            if (!read_number(p, padded.end(), fast)) {
                ++declined;
                continue;
            }
            ASSERT_EQ(bits(fast), bits(expect)) << token;
            const char* q = token.data();
            if (scan_short_decimal(q, token.data() + token.size(), fast)) {
                ASSERT_EQ(bits(fast), bits(expect)) << token;
            }
        }
    }
    EXPECT_GT(declined, 0);  // the cases nearest_float exists for do occur
}

TEST(ReadNumber, FormsAndWhereTheyEnd) {
    struct Case {
        const char* token;
        bool read;
    };
    for (const Case c : {Case{"0", true},
                         {"-0", true},
                         {"5.", true},
                         {".5", true},
                         {"-.5", true},
                         {"1e5", true},
                         {"1E-05", true},
                         {"1.5e+3", true},
                         {"12345678.25", true},
                         {"12345678.5", false},
                         {"123456789012345", true},
                         {"1234567890123456", false},
                         {"0.1234567890123456", false},
                         {"+1", false},
                         {".", false},
                         {"-", false},
                         {"e5", false},
                         {"1e", false},
                         {"1e1234", false},
                         {"1e-50", false},
                         {"nan", false}}) {
        const Padded padded(c.token);
        const char* p = padded.begin();
        float v;
        const bool read = read_number(p, padded.end(), v);
        EXPECT_EQ(read, c.read) << c.token;
        if (!read) continue;
        float expect;
        ASSERT_TRUE(reference(c.token, expect)) << c.token;
        EXPECT_EQ(bits(v), bits(expect)) << c.token;
        EXPECT_EQ(p, padded.token_end()) << c.token;
    }
}

TEST(ReadIndex, ResolvedLikeTheGeneralPath) {
    std::mt19937 rng(2);
    for (int i = 0; i < 100'000; ++i) {
        std::string token = rng() % 8 == 0 ? (rng() % 2 ? "-" : "+") : "";
        token += random_digits(rng, 1 + static_cast<int>(rng() % 20));
        const std::size_t count = rng() % 2 ? rng() % 100 : rng();
        const bool relative = rng() % 2;  // negative indices read, or refused
        const Padded padded(token);
        const char* p = padded.begin();
        std::uint32_t fast = 0;
        const bool read = read_index(p, padded.end(), count, relative, fast);
        const char* q = token.data();
        long long index;
        std::uint32_t expect = 0;
        const bool valid = parse_index(q, token.data() + token.size(), index) &&
                           q == token.data() + token.size() && (relative || index > 0) &&
                           resolve_index(index, count, expect);
        ASSERT_EQ(read, valid) << token << " of " << count;
        if (!valid) continue;
        EXPECT_EQ(fast, expect) << token;
        EXPECT_EQ(p, padded.token_end()) << token;
    }
}

TEST(PaddedZone, EndsAfterTheLastLineEndFollowedByThePadding) {
    const std::string pad(kFastPathPadding, 'x');
    EXPECT_EQ(padded_zone_end(pad), pad.data());
    const std::string two = "v 1 2 3\r\nf 1 1 1\n" + pad;
    EXPECT_EQ(padded_zone_end(two), two.data() + two.size() - pad.size());
    const std::string cr = "v 1 2 3\rv 4 5 6\r" + pad + "\n";
    EXPECT_EQ(padded_zone_end(cr), cr.data() + 16);
}
