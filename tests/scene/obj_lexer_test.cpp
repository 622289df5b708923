// The text level of the OBJ and MTL readers: logical lines, tokens, numbers and indices.

#include "toonray/scene/obj_lexer.h"

#include <gtest/gtest.h>

#include <charconv>
#include <cstring>
#include <random>
#include <string>
#include <utility>
#include <vector>

using namespace toonray;
using namespace toonray::wavefront;

namespace {

std::vector<std::pair<std::size_t, std::string>> lines_of(std::string_view text,
                                                          std::uint64_t max_line = 1000) {
    LineReader reader(text, "t.obj", max_line);
    std::vector<std::pair<std::size_t, std::string>> out;
    std::string_view line;
    std::size_t number = 0;
    while (reader.next(line, number)) out.emplace_back(number, std::string(line));
    return out;
}

std::uint32_t bits(float f) {
    std::uint32_t u;
    std::memcpy(&u, &f, 4);
    return u;
}

}  // namespace

TEST(LineReader, EndingsContinuationsAndLineNumbers) {
    using Lines = std::vector<std::pair<std::size_t, std::string>>;
    EXPECT_EQ(lines_of("a\nb\r\nc\rd"), (Lines{{1, "a"}, {2, "b"}, {3, "c"}, {4, "d"}}));
    // A continuation joins with a space; the next line is numbered past the joined ones.
    EXPECT_EQ(lines_of("f 1 \\\n2 3\\\r\n 4\nv"), (Lines{{1, "f 1  2 3  4"}, {4, "v"}}));
    // A comment ending in a backslash does not swallow the next line.
    EXPECT_EQ(lines_of("# C:\\models\\\nv 1"), (Lines{{1, "# C:\\models\\"}, {2, "v 1"}}));
    // A byte-order mark is skipped.
    EXPECT_EQ(lines_of("\xEF\xBB\xBFv 1\n"), (Lines{{1, "v 1"}}));
}

TEST(LineReader, LongLinesAreLimitErrors) {
    try {
        lines_of("v 1\n" + std::string(11, 'x') + "\n", 10);
        FAIL() << "no error";
    } catch (const LimitError& e) {
        EXPECT_EQ(e.limit(), Limit::LineBytes);
        EXPECT_STREQ(e.what(), "t.obj:2: line longer than the limit of 10 bytes");
    }
}

TEST(Tokens, RestKeepsHashesInsideNames) {
    Tokens t("usemtl  Mat#2  # a comment ");
    EXPECT_EQ(t.next(), "usemtl");
    EXPECT_EQ(t.rest(), "Mat#2");
    Tokens c("v 1 2 # three");
    c.next();
    c.next();
    c.next();
    EXPECT_TRUE(c.at_end());
}

TEST(ScanShortDecimal, BitForBitFromChars) {
    std::mt19937 rng(5);
    std::uniform_int_distribution<int> digits(1, 15), pick(0, 9);
    int declined = 0;
    for (int i = 0; i < 200'000; ++i) {
        std::string s = rng() % 2 ? "-" : "";
        const int n = digits(rng);
        const int point = static_cast<int>(rng() % (n + 1));
        for (int k = 0; k < n; ++k) {
            if (k == point && k > 0) s += '.';
            s += static_cast<char>('0' + pick(rng));
        }
        const char* p = s.data();
        float fast;
        float reference;
        std::from_chars(s.data(), s.data() + s.size(), reference);
        // Declined only where the double lands halfway between two floats (nearest_float):
        // mostly integers above 2^24, where every odd integer is such a midpoint.
        if (!scan_short_decimal(p, s.data() + s.size(), fast)) {
            ++declined;
            continue;
        }
        ASSERT_EQ(p, s.data() + s.size()) << s;
        ASSERT_EQ(bits(fast), bits(reference)) << s;
    }
    EXPECT_LT(declined, 2000);
    // Not the short form: left to from_chars.
    for (const char* s : {"1e5", "1234567890123456", "", "-", "."}) {
        const char* p = s;
        float v;
        EXPECT_FALSE(scan_short_decimal(p, s + std::strlen(s), v) && p == s + std::strlen(s)) << s;
    }
}

TEST(ScanShortDecimal, DeclinesDecimalsJustOffAMidpointBetweenFloats) {
    // Rounded to double, these land exactly halfway between two floats, and rounding that
    // again to float would go the wrong way: the decimal lies just past the midpoint.
    for (const char* s : {"0.83888378739357", "0.92586949467659", "0.85585156083107"}) {
        const char* p = s;
        float v;
        EXPECT_FALSE(scan_short_decimal(p, s + std::strlen(s), v)) << s;
        float reference;
        std::from_chars(s, s + std::strlen(s), reference);
        Tokens t(s);
        EXPECT_EQ(bits(LineParser("t.obj", 1).number(t, "v")), bits(reference)) << s;
    }
}

TEST(LineParser, NumbersAndLocatedErrors) {
    const LineParser parse("t.obj", 7);
    Tokens t("+1.5 1e-50 2e5");
    EXPECT_EQ(parse.number(t, "v"), 1.5f);
    EXPECT_EQ(parse.number(t, "v"), 0.0f);  // too small for a float reads as zero
    EXPECT_EQ(parse.number(t, "v"), 2e5f);
    Tokens bad("1e39 x");
    try {
        (void)parse.number(bad, "v");
        FAIL() << "no error";
    } catch (const Error& e) {
        EXPECT_STREQ(e.what(), "t.obj:7: number '1e39' out of range in 'v' statement");
    }
}

TEST(ParseIndex, SignsAndLength) {
    auto index = [](std::string_view s, long long& v) {
        const char* p = s.data();
        return parse_index(p, s.data() + s.size(), v) && p == s.data() + s.size();
    };
    long long v = 0;
    EXPECT_TRUE(index("+12", v));
    EXPECT_EQ(v, 12);
    EXPECT_TRUE(index("-3", v));
    EXPECT_EQ(v, -3);
    EXPECT_TRUE(index("999999999999999999", v));    // 18 digits
    EXPECT_FALSE(index("1000000000000000000", v));  // 19: refused
    EXPECT_FALSE(index("-", v));
}
