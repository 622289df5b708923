#include "toonray/ink/svg.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "toonray/core/error.h"
#include "toonray/ink/draw.h"

namespace toonray {
namespace {

using ink::Point2;
using ink::Stroke;

Stroke polyline(std::vector<Point2> points, std::uint16_t style = 0) {
    Stroke s;
    s.points = std::move(points);
    s.style = style;
    return s;
}

TEST(InkSvg, AStyleWithoutAPenThrows) {
    std::vector<Stroke> strokes{polyline({{1.0f, 2.0f}, {3.0f, 4.0f}}, 0),
                                polyline({{1.0f, 2.0f}, {3.0f, 4.0f}}, 3)};
    strokes[1].visible = false;  // not even written: the hidden layer is off
    const std::vector<ink::StrokePen> pens(2);
    ink::SvgSettings svg;
    svg.pens = pens;
    try {
        (void)ink::svg_text(strokes, svg);
        ADD_FAILURE() << "no error";
    } catch (const Error& e) {
        EXPECT_EQ(std::string(e.what()), "ink: stroke 1 has style 3 but there are 2 pens");
    }
    // Without pens every stroke has the group's defaults.
    svg.pens = {};
    EXPECT_NE(ink::svg_text(strokes, svg).find("<path d="), std::string::npos);
}

}  // namespace
}  // namespace toonray
