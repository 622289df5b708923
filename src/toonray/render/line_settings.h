#pragma once
/// How a frame's lines are drawn: the settings every line mode shares (which lines, how wide,
/// what colour), and one group of its own per mode.

#include <string>
#include <string_view>

#include "toonray/core/math.h"
#include "toonray/ink/line_style.h"

namespace toonray {

/// The line modes (`--edges`).
enum class LineMode {
    /// The default: lines found on the geometry, cut where ray-traced visibility changes,
    /// chained into strokes and drawn with exact coverage over the colours (ink/ink.h).
    Ink,
    /// Lines found between the samples of a supersampled grid by plane-aware tests, with a
    /// width that follows the resolution (render/robust.h).
    Robust,
    /// The seed's pipeline, exactly: Sobel filters on 8-bit depth and normal maps
    /// (render/classic.h).
    Classic,
};

/// "ink", "robust" or "classic".
[[nodiscard]] std::string_view line_mode_name(LineMode mode);
/// The mode of line_mode_name; throws Error ("WHAT: unknown line mode 'x' (ink, robust or
/// classic)").
[[nodiscard]] LineMode parse_line_mode(std::string_view text, std::string_view what);

/// Line types, combinable as bits (`--lines silhouette,crease,depth,object,material`). The ink
/// lines find them on the geometry: silhouette (with borders), crease, material, and object as
/// the intersection lines between objects; depth is a step between samples, which only the
/// robust lines have.
enum LineType : unsigned {
    kLineSilhouette =
        1u << 0,  ///< surface next to background, or in front of something much farther
    kLineCrease =
        1u << 1,           ///< geometric normals of neighbours differ by more than the crease angle
    kLineDepth = 1u << 2,  ///< a step in depth where the surface is not a continuous plane or slope
    kLineObject = 1u << 3,    ///< neighbours belong to different objects
    kLineMaterial = 1u << 4,  ///< neighbours have different materials
    /// The types of the geometry, every one the default draws: "all".
    kLineAll = 31u,
    /// Boundaries between cel bands on the surfaces, the terminator included (the ink lines
    /// only; not in "all": the bands show them, and the default look stays as it was).
    kLineBand = 1u << 5,
    /// Boundaries of toon shadows on the surfaces receiving them (the ink lines, with
    /// shadows on).
    kLineShadow = 1u << 6,
};

/// Parses "silhouette,crease,depth,object,material,band,shadow" (any subset; "all" for the
/// first five, also in a list: "all,band"; or "none"). Throws Error ("unknown line type '...'
/// ...").
[[nodiscard]] unsigned parse_line_types(const std::string& text);
/// The text parse_line_types reads back as `types`: "all" (and ",band", ",shadow" when set),
/// "none" or the names in order.
[[nodiscard]] std::string format_line_types(unsigned types);

/// `--edges classic`: the Sobel thresholds.
struct ClassicLineSettings {
    float depth_threshold = 8.0f;   ///< Sobel magnitude on the 8-bit depth map
    float normal_threshold = 4.0f;  ///< Sobel magnitude on the 8-bit normal map
    bool operator==(const ClassicLineSettings&) const = default;
};

/// `--edges robust`: the depth tests between samples.
struct RobustLineSettings {
    /// Depth lines where |second difference of 1/z| / (1/z) exceeds this. 1/z is linear in
    /// screen space across any plane, so planes never cross it however steep the view.
    float depth_step = 0.02f;
    /// A depth discontinuity larger than this fraction of the nearer depth is a silhouette
    /// (one thing in front of another) rather than a depth line (a fold of one surface).
    float silhouette_ratio = 0.1f;
    bool operator==(const RobustLineSettings&) const = default;
};

/// Strokes (the ink lines, and the strokes every mode keeps for SVG and draws for polylines):
/// their default pen beyond width and colour, and the line sets that style them.
struct InkLineSettings {
    float taper = 0.0f;  ///< open strokes thin to nothing over this many pixels at 720 lines
    /// Lines thinner farther away: full width at the distance of the scene's centre, scaled by
    /// it over the line's distance, within 0.25x-2x.
    bool width_by_depth = false;
    ink::LineStyleSet styles;  ///< line sets and styles (ink/line_style.h)
};

struct LineSettings {
    LineMode mode = LineMode::Ink;
    unsigned types = kLineAll;   ///< LineType bits
    float crease_angle = 40.0f;  ///< degrees between neighbouring surfaces
    float width = 2.0f;          ///< pixels at 720 lines; scales with the image height
    Vec3f colour{0.0f};
    ClassicLineSettings classic;
    RobustLineSettings robust;
    InkLineSettings ink;
};

/// Throws Error for line types a mode cannot draw when they are asked for by name: depth lines
/// with the ink lines ("the ink mode finds no depth lines ..."), band and shadow lines with the
/// others.
void check_line_settings(const LineSettings& lines);

}  // namespace toonray
