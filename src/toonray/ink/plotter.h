#pragma once
/// Plotter-ready SVG (`--svg-plotter`): the strokes as a pen plotter draws them. One Inkscape
/// layer per pen (colour and width), which AxiDraw's software and vpype take as layers; paths
/// that touch merged into one; each layer's paths ordered, and turned, to cut the pen-up travel
/// between them (greedy nearest neighbour, then 2-opt moves with turned paths, from the page's
/// corner); centrelines only (a plotter's pen has one width); screentone dots as concentric
/// circles a pen width apart; hidden strokes only when hidden lines are asked for.

#include <span>
#include <string>
#include <vector>

#include "toonray/ink/screen.h"
#include "toonray/ink/strokes.h"
#include "toonray/ink/svg.h"

namespace toonray::ink {

/// One path a pen draws: a polyline, or a circle (a dot's ring) when `radius` > 0, whose one
/// point is its centre.
struct PlotPath {
    std::vector<Point2> points;
    float radius = 0.0f;

    /// Where the pen lands to draw it and where it lifts: a circle's rightmost point for both.
    [[nodiscard]] Point2 start() const;
    [[nodiscard]] Point2 end() const;
};

/// Joins paths whose ends touch (equal to 1/1000 px, the SVG's precision), turning them as
/// needed; circles and closed paths are left alone. In a fixed order: each path grows from its
/// end, then from its start, with the first unjoined path that touches it.
[[nodiscard]] std::vector<PlotPath> merge_touching(std::vector<PlotPath> paths);

/// The paths in drawing order, each possibly turned, from `home`: nearest neighbour, then
/// 2-opt moves between each path's end and the ends of its nearest neighbours until none
/// shortens the travel.
[[nodiscard]] std::vector<PlotPath> order_paths(std::vector<PlotPath> paths, Point2 home);

/// The pen-up travel drawing the paths in order from `home`: the sum of the distances from
/// each path's end (home first) to the next one's start.
[[nodiscard]] double pen_up_travel(std::span<const PlotPath> paths, Point2 home);

/// The plotter SVG of the strokes (svg_text with SvgSettings::plotter).
[[nodiscard]] std::string plotter_svg_text(std::span<const Stroke> strokes,
                                           const SvgSettings& settings);

}  // namespace toonray::ink
