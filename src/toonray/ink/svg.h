#pragma once
/// Strokes as an SVG 1.1 drawing, for plotters and vector editors. Writing the file is the
/// frame layer's (frame/frame_renderer.h): ink, like render, does no file I/O.

#include <span>
#include <string>
#include <string_view>

#include "toonray/core/math.h"
#include "toonray/ink/draw.h"
#include "toonray/ink/strokes.h"

namespace toonray::ink {

struct SvgSettings {
    int width = 1280, height = 720;  ///< the image size: the viewBox, in pixels
    float thickness = 2.0f;          ///< visible stroke width, pixels
    Vec3f colour{0.0f};
    bool hidden = false;  ///< write hidden strokes too (in group "hidden")
    Vec3f hidden_colour{0.5f};
    float hidden_thickness_scale = 0.5f;
    /// The frame's pens (InkLines::pens), indexed by Stroke::style; a stroke whose style has
    /// no pen throws Error (draw.h, pen_of_stroke). A path whose pen differs from its group's
    /// defaults carries its own stroke, stroke-width, stroke-opacity and stroke-dasharray (the
    /// table's svg_stroke attributes, line_style.h); visible strokes whose pen does not draw
    /// are left out, hidden ones whose pen does not draw keep the hidden layer's defaults.
    /// A stroke whose width varies (taper, width by depth: draw.h, varies_width) is written as
    /// its filled outline instead: `stroke="none"`, `fill` and `fill-opacity`, and path data
    /// of shapes whose union is what the drawing covers by more than half, dashes cut out
    /// (svg.cpp, outline_data). Empty: group defaults only.
    std::span<const StrokePen> pens;
    /// When not empty, an `<image id="fill">` of the whole view under the lines with this
    /// href (a data: URI of the cel-shaded picture).
    std::string fill_href;
    /// When not empty, a `<metadata id="toonray">` first in the drawing with the software that
    /// wrote it (its `data-software` attribute) and this text (the settings that made it),
    /// escaped as XML character data.
    std::string software, metadata;
    /// For a pen plotter instead (ink/plotter.h): one Inkscape layer per pen, paths merged and
    /// ordered to cut pen-up travel, centrelines only; no fill image.
    bool plotter = false;
};

/// `#rrggbb` of a colour (each channel clamped to [0, 1]).
[[nodiscard]] std::string svg_colour(const Vec3f& colour);

/// A coordinate or length with three decimals, "-0.000" written as "0.000".
[[nodiscard]] std::string svg_coordinate(float v);

/// `text` with &, <, > and " escaped, for XML character data and attribute values.
[[nodiscard]] std::string xml_escaped(std::string_view text);

/// `data:image/png;base64,...` for PNG bytes.
[[nodiscard]] std::string png_data_uri(std::span<const std::uint8_t> png);

/// The SVG text: with a tone look first a `<g id="tone">` of its strokes (paths) and dots
/// (filled circles), under the lines; then a `<g id="visible">` with one subgroup per line type
/// (`visible-silhouette`, `visible-border`, `visible-crease`, `visible-material`,
/// `visible-intersection`, `visible-polyline`, `visible-band`, `visible-shadow`), each stroke a
/// `<path>` in pixel units with round caps and joins (or a filled outline, above); with hidden
/// lines, a `<g id="hidden">` with `hidden-...` subgroups after it. Coordinates have three
/// decimals. With `plotter`, plotter_svg_text's drawing instead (ink/plotter.h).
[[nodiscard]] std::string svg_text(std::span<const Stroke> strokes, const SvgSettings& settings);

}  // namespace toonray::ink
