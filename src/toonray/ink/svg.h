#pragma once
/// Strokes as an SVG 1.1 drawing, for plotters and vector editors. Writing the file is the
/// frame layer's (frame/frame_renderer.h): ink, like render, does no file I/O.

#include <span>
#include <string>

#include "toonray/core/math.h"
#include "toonray/ink/strokes.h"

namespace toonray::ink {

struct SvgSettings {
    int width = 1280, height = 720;  ///< the image size: the viewBox, in pixels
    float thickness = 2.0f;          ///< visible stroke width, pixels
    Vec3f colour{0.0f};
    bool hidden = false;  ///< write hidden strokes too (in group "hidden")
    Vec3f hidden_colour{0.5f};
    float hidden_thickness_scale = 0.5f;
};

/// The SVG text: a `<g id="visible">` with one subgroup per line type (`visible-silhouette`,
/// `visible-border`, `visible-crease`, `visible-material`, `visible-intersection`), each
/// stroke a `<path>` in pixel units with round caps and joins; with hidden lines, a
/// `<g id="hidden">` with `hidden-...` subgroups after it. Coordinates have three decimals.
[[nodiscard]] std::string svg_text(std::span<const Stroke> strokes, const SvgSettings& settings);

}  // namespace toonray::ink
