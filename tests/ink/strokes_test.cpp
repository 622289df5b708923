#include "toonray/ink/strokes.h"

#include <gtest/gtest.h>

namespace toonray {
namespace {

using ink::EdgePiece;
using ink::EdgeType;
using ink::EndpointKey;
using ink::Point2;

// A piece of its own segment from a to b between welded vertices ka and kb.
EdgePiece piece(std::uint32_t segment, Point2 a, Point2 b, std::uint32_t ka, std::uint32_t kb,
                EdgeType type = EdgeType::Crease, int invisibility = 0) {
    EdgePiece p;
    p.segment = segment;
    p.s0 = a;
    p.s1 = b;
    p.key0 = {ka, kNoIndex, kNoIndex};
    p.key1 = {kb, kNoIndex, kNoIndex};
    p.type = type;
    p.invisibility = invisibility;
    return p;
}

ink::ChainSettings plain() {
    ink::ChainSettings s;
    s.simplify = 0;
    s.min_spacing = 0;
    return s;
}

TEST(ChainPieces, SquareLoopBecomesOneClosedStroke) {
    // Pieces in any direction and order.
    const std::vector<EdgePiece> pieces{
        piece(0, {0, 0}, {10, 0}, 0, 1), piece(1, {10, 10}, {0, 10}, 2, 3),
        piece(2, {10, 10}, {10, 0}, 2, 1), piece(3, {0, 0}, {0, 10}, 0, 3)};
    const auto strokes = ink::chain_pieces(pieces, plain());
    ASSERT_EQ(strokes.size(), 1u);
    EXPECT_TRUE(strokes[0].closed);
    ASSERT_EQ(strokes[0].points.size(), 5u);
    EXPECT_EQ(strokes[0].points.front(), strokes[0].points.back());
    EXPECT_FLOAT_EQ(ink::polyline_length(strokes[0].points), 40.0f);
}

TEST(ChainPieces, TypesAndVisibilityDoNotMix) {
    const std::vector<EdgePiece> pieces{piece(0, {0, 0}, {10, 0}, 0, 1),
                                        piece(1, {10, 0}, {20, 0}, 1, 2, EdgeType::Border),
                                        piece(2, {20, 0}, {30, 0}, 2, 3, EdgeType::Border, 1)};
    auto settings = plain();
    EXPECT_EQ(ink::chain_pieces(pieces, settings).size(), 2u);  // the hidden piece is left out
    settings.hidden = true;
    const auto strokes = ink::chain_pieces(pieces, settings);
    ASSERT_EQ(strokes.size(), 3u);
    EXPECT_FALSE(strokes[2].visible);
}

TEST(ChainPieces, StrokesNameTheSegmentTheyStartedFrom) {
    // Segments 7 and 8 chain into one stroke started from the first piece; 9 is of another type.
    const std::vector<EdgePiece> pieces{piece(7, {0, 0}, {10, 0}, 0, 1),
                                        piece(8, {10, 0}, {20, 0}, 1, 2),
                                        piece(9, {20, 0}, {30, 0}, 2, 3, EdgeType::Border)};
    const auto strokes = ink::chain_pieces(pieces, plain());
    ASSERT_EQ(strokes.size(), 2u);
    EXPECT_EQ(strokes[0].segment, 7u);
    EXPECT_EQ(strokes[1].segment, 9u);
    EXPECT_EQ(strokes[1].type, EdgeType::Border);
}

TEST(ChainPieces, JunctionContinuesWithTheStraightestPiece) {
    // A line through vertex 1 with a branch leaving it at 90 degrees.
    const std::vector<EdgePiece> pieces{piece(0, {0, 0}, {10, 0}, 0, 1),
                                        piece(1, {10, 0}, {10, 10}, 1, 2),
                                        piece(2, {10, 0}, {20, 1}, 1, 3)};
    const auto strokes = ink::chain_pieces(pieces, plain());
    ASSERT_EQ(strokes.size(), 2u);
    ASSERT_EQ(strokes[0].points.size(), 3u);
    EXPECT_EQ(strokes[0].points[2], (Point2{20, 1}));
    // With only sharp turns on offer at a junction, the stroke stops there; the two branches
    // then make one straight stroke.
    const std::vector<EdgePiece> fork{piece(0, {0, 0}, {10, 0}, 0, 1),
                                      piece(1, {10, 0}, {10, 10}, 1, 2),
                                      piece(2, {10, 0}, {10, -10}, 1, 3)};
    const auto forked = ink::chain_pieces(fork, plain());
    ASSERT_EQ(forked.size(), 2u);
    EXPECT_EQ(forked[0].points.size(), 2u);
    EXPECT_EQ(forked[1].points.size(), 3u);
    // A corner with no other choice is followed whatever the angle.
    const std::vector<EdgePiece> corner{piece(0, {0, 0}, {10, 0}, 0, 1),
                                        piece(1, {10, 0}, {1, 1}, 1, 2)};
    EXPECT_EQ(ink::chain_pieces(corner, plain()).size(), 1u);
}

TEST(ChainPieces, SubPixelVisibilityFlickerIsAbsorbed) {
    // One segment: visible, hidden for 0.5 px, visible.
    std::vector<EdgePiece> pieces{piece(0, {0, 0}, {10, 0}, 0, kNoIndex),
                                  piece(0, {10, 0}, {10.5f, 0}, kNoIndex, kNoIndex),
                                  piece(0, {10.5f, 0}, {20, 0}, kNoIndex, 1)};
    pieces[1].invisibility = 1;
    pieces[0].t0 = 0, pieces[0].t1 = 0.5f, pieces[1].t0 = 0.5f, pieces[1].t1 = 0.525f,
    pieces[2].t0 = 0.525f;
    const auto strokes = ink::chain_pieces(pieces, plain());
    ASSERT_EQ(strokes.size(), 1u);
    EXPECT_EQ(strokes[0].points.front(), (Point2{0, 0}));
    EXPECT_EQ(strokes[0].points.back(), (Point2{20, 0}));
    // A hidden gap of 2 px stays.
    pieces[1].s1 = pieces[2].s0 = {12, 0};
    EXPECT_EQ(ink::chain_pieces(pieces, plain()).size(), 2u);
}

TEST(SimplifyPolyline, DropsPointsWithinTheTolerance) {
    std::vector<Point2> pts;
    for (int i = 0; i <= 100; ++i)
        pts.push_back({static_cast<float>(i), 0.05f * ((i % 2) ? 1.0f : -1.0f)});
    pts.push_back({100, 20});
    const auto simple = ink::simplify_polyline(pts, 0.1f);
    ASSERT_EQ(simple.size(), 3u);
    EXPECT_EQ(simple.front(), pts.front());
    EXPECT_EQ(simple[1], pts[100]);
    EXPECT_EQ(simple.back(), pts.back());
    EXPECT_EQ(ink::simplify_polyline(pts, 0.04f).size(), pts.size());
}

TEST(ChainPieces, ShortStrokesCanBeDropped) {
    const std::vector<EdgePiece> pieces{piece(0, {0, 0}, {1.5f, 0}, 0, 1),
                                        piece(1, {5, 5}, {15, 5}, 2, 3)};
    auto settings = plain();
    settings.min_length = 2.0f;
    const auto strokes = ink::chain_pieces(pieces, settings);
    ASSERT_EQ(strokes.size(), 1u);
    EXPECT_EQ(strokes[0].points.front(), (Point2{5, 5}));
}

}  // namespace
}  // namespace toonray
