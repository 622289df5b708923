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

TEST(ChainPieces, PartsThatShareNoKeyChainAsTheWhole) {
    // The rest (before and after the parts) chains across them: a path of the own triangles
    // from (0, 0) runs on into a piece after the parts. Three instances' pieces, whose keys
    // name them, come between: a loop, a path and a fork; the last piece after the parts is a
    // crossing between two instances (its keys name both) that meets nothing.
    auto on = [](EdgePiece p, std::uint32_t instance, std::uint32_t other = kNoIndex) {
        p.key0.instance = p.key1.instance = instance;
        p.key0.c_instance = p.key1.c_instance = other;
        return p;
    };
    std::vector<EdgePiece> pieces{piece(0, {0, 0}, {10, 0}, 0, 1), piece(1, {10, 0}, {20, 0}, 1, 2),
                                  piece(2, {50, 50}, {60, 50}, 7, 8)};
    const std::size_t first = pieces.size();
    for (const EdgePiece& p :
         {piece(3, {0, 20}, {10, 20}, 0, 1), piece(4, {10, 20}, {10, 30}, 1, 2),
          piece(5, {10, 30}, {0, 30}, 2, 3), piece(6, {0, 30}, {0, 20}, 3, 0)})
        pieces.push_back(on(p, 0));
    const std::size_t second = pieces.size();
    for (const EdgePiece& p :
         {piece(7, {20, 20}, {30, 20}, 0, 1), piece(8, {30, 20}, {40, 25}, 1, 2)})
        pieces.push_back(on(p, 1));
    const std::size_t third = pieces.size();
    for (const EdgePiece& p :
         {piece(9, {0, 40}, {10, 40}, 0, 1), piece(10, {10, 40}, {20, 40}, 1, 2),
          piece(11, {10, 40}, {10, 50}, 1, 3)})
        pieces.push_back(on(p, 2));
    const std::size_t last = pieces.size();
    pieces.push_back(piece(12, {20, 0}, {30, 0}, 2, 4));
    pieces.push_back(on(piece(13, {40, 40}, {45, 45}, 0, 1), 0, 1));
    const std::vector<std::size_t> cuts{first, second, third, last};
    const auto whole = ink::chain_pieces(pieces, plain());
    ASSERT_EQ(whole.size(), 7u);  // own path, the other own piece, loop, path, fork's 2, crossing
    EXPECT_EQ(whole[0].points.back(), (Point2{30, 0}));  // the own path took the piece after
    for (int threads : {1, 2}) {
        const auto parts = ink::chain_pieces_in_parts(pieces, cuts, plain(), {}, threads);
        ASSERT_EQ(parts.size(), whole.size()) << threads;
        for (std::size_t i = 0; i < whole.size(); ++i) {
            EXPECT_EQ(parts[i].points, whole[i].points) << threads << " " << i;
            EXPECT_EQ(parts[i].segment, whole[i].segment) << threads << " " << i;
            EXPECT_EQ(parts[i].closed, whole[i].closed) << threads << " " << i;
        }
    }
    // No parts: the whole.
    const std::vector<std::size_t> none{pieces.size()};
    EXPECT_EQ(ink::chain_pieces_in_parts(pieces, none, plain(), {}, 2).size(), whole.size());
}

}  // namespace
}  // namespace toonray
