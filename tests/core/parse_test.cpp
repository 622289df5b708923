#include "toonray/core/parse.h"

#include <gtest/gtest.h>

#include "toonray/core/error.h"

using namespace toonray;

TEST(ParseImageSize, AcceptsWidthByHeight) {
    ImageSize s = parse_image_size("1920x1080", "--size");
    EXPECT_EQ(s.width, 1920);
    EXPECT_EQ(s.height, 1080);
}

TEST(ParseImageSize, RejectsMalformedAndOutOfRange) {
    for (const char* bad :
         {"1920", "1920x", "x1080", "0x10", "10x0", "-5x5", "100000x10", "12x12x", "a x b"})
        EXPECT_THROW(parse_image_size(bad, "--size"), Error) << bad;
}

TEST(ParseVec3, ParsesCommaSeparatedNumbers) {
    Vec3f v = parse_vec3("4,-6.5,+1e1", "--light");
    EXPECT_EQ(v, Vec3f(4.0f, -6.5f, 10.0f));
}

TEST(ParseVec3, RejectsWrongCountAndNonFinite) {
    for (const char* bad : {"1,2", "1,2,3,4", "1,,3", "nan,1,2", "inf,0,0", "1;2;3", ""})
        EXPECT_THROW(parse_vec3(bad, "--light"), Error) << bad;
}

TEST(ParseColour, AcceptsHexAndUnitTriples) {
    EXPECT_EQ(parse_colour("#ff0080", "--background"), Vec3f(1.0f, 0.0f, 128 / 255.0f));
    EXPECT_EQ(parse_colour("0.5,0.25,1", "--background"), Vec3f(0.5f, 0.25f, 1.0f));
    EXPECT_THROW(parse_colour("1.5,0,0", "--background"), Error);
    EXPECT_THROW(parse_colour("#ff00", "--background"), Error);
    EXPECT_THROW(parse_colour("#gg0000", "--background"), Error);
}

TEST(ParseErrors, NameTheOption) {
    try {
        parse_vec3("1,2", "--light");
        FAIL();
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("--light"), std::string::npos);
    }
}
