#pragma once
/// Chaining: visible (or hidden) edge pieces joined into strokes, the polylines that are drawn
/// and written to SVG.

#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "toonray/ink/visibility.h"

namespace toonray::ink {

struct Stroke {
    EdgeType type = EdgeType::Silhouette;
    bool visible = true;
    std::vector<Point2> points;  ///< on the image, in pixels; at least two
    bool closed = false;         ///< the last point is the first (a loop)
    std::uint16_t style = 0;     ///< index into the frame's resolved line styles (ink.h)
    /// Per point, its distance from the eye (world units) when ChainSettings::eye is set,
    /// else empty: for widths by depth.
    std::vector<float> depth;
    /// Per point, where it lies in the world when ChainSettings::world is set, else empty:
    /// for noise anchored on the surfaces (sketchy strokes).
    std::vector<Vec3f> world;
    /// The pen's width times this: a screentone dot (a tone stroke of one point) is as wide as
    /// its darkness asks (ink/tone.h).
    float scale = 1.0f;
    /// The segment of the piece the stroke was started from: its object and material
    /// (style_source, ink.h), which the Python module reports per stroke.
    std::uint32_t segment = 0;
};

/// Per segment, the style index of its visible pieces [0] and of its hidden pieces [1].
using SegmentStyles = std::array<std::uint16_t, 2>;

struct ChainSettings {
    /// A piece whose image is shorter than this (pixels), between pieces of the other
    /// visibility on the same segment (or at its end), takes its neighbours' visibility: a
    /// visibility change that flickers on and off within a pixel draws no dot and no gap.
    float min_piece = 1.0f;
    /// At a junction (more than one unused piece to continue with), a stroke goes on with the
    /// straightest piece only if it turns by at most this many degrees.
    float max_turn = 60.0f;
    /// Points closer than this (pixels) to the previous kept point are dropped (ends are kept).
    float min_spacing = 1.0f;
    /// Douglas-Peucker tolerance in pixels; 0 keeps every point.
    float simplify = 0.1f;
    /// Visible strokes shorter than this (pixels, along the polyline) are dropped; 0 keeps all.
    float min_length = 0.0f;
    bool hidden = false;  ///< also chain the hidden pieces (into strokes with visible = false)
    /// When set, strokes keep each point's distance from this eye (Stroke::depth).
    std::optional<Vec3f> eye;
    /// Strokes keep each point's place in the world (Stroke::world).
    bool world = false;
};

/// Chains pieces into strokes. The rule: pieces chain when they have the same type and the
/// same visibility (visible, or hidden at any depth) and meet at the same endpoint key (a
/// welded vertex, or the same point on a welded edge). A stroke is started from each unused
/// piece in order, and grown at its end and then at its start: at a key with exactly one other
/// unused matching piece it continues with it, whatever the angle; with several, it continues
/// with the straightest on the image if that turns by at most max_turn, else it stops. A
/// stroke that comes back to its start is closed. Strokes come out in the order of their
/// first pieces (so deterministic). With `segment_styles` (one entry per segment), pieces
/// also chain only when they have the same style, and strokes carry it; without, every
/// stroke has style 0.
[[nodiscard]] std::vector<Stroke> chain_pieces(std::span<const EdgePiece> pieces,
                                               const ChainSettings& settings,
                                               std::span<const SegmentStyles> segment_styles = {});

/// chain_pieces' strokes, with the pieces [cuts.front(), cuts.back()) chained in the parts the
/// cuts make, apart from the rest and from each other and on `threads` threads; the rest (the
/// pieces before and after) is chained as one. The strokes are chain_pieces' over all the
/// pieces, in the same order (by their first piece), when no piece of a part shares an
/// endpoint key with a piece outside it and no segment's pieces are cut apart: that is the
/// caller's to know (pieces of different instances never meet, ink.cpp). The pieces are in
/// segment order, as visibility gives them; `cuts` are increasing, at least one.
[[nodiscard]] std::vector<Stroke> chain_pieces_in_parts(
    std::span<const EdgePiece> pieces, std::span<const std::size_t> cuts,
    const ChainSettings& settings, std::span<const SegmentStyles> segment_styles, int threads);

/// Douglas-Peucker: the fewest points of `points` (ends kept) such that every dropped point
/// is within `tolerance` of the simplified polyline.
[[nodiscard]] std::vector<Point2> simplify_polyline(std::span<const Point2> points,
                                                    float tolerance);

/// Length of a polyline in pixels.
[[nodiscard]] float polyline_length(std::span<const Point2> points);

}  // namespace toonray::ink
