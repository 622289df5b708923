#pragma once
/// Line sets and styles for ink lines: rules that match strokes by object, material, line type
/// and visibility, and set how they are drawn (docs/ink.md, "Line styles").
///
/// The text format: one rule a line (it must start with `match`); '#' at the start of a line
/// or after a blank starts a comment:
///
///     match object=w*,b* material=* type=crease,silhouette lines=hidden  draw=yes
///           color=#808080 width=1.0 opacity=0.5 dash=4,2
///
/// Matchers: object, material (comma-separated globs with * and ?), type (line types or
/// `all`), lines (visible, hidden or all; visible when not given, so hidden lines are styled,
/// and drawn, only where a rule says so). Attributes: draw (yes/no), color or colour (#rrggbb
/// or r,g,b in [0, 1]), width (pixels at 720 lines), opacity ([0, 1]), dash (lengths in pixels
/// at 720 lines, on,off,... or `none`), taper (pixels at 720 lines along the stroke over which
/// open strokes thin to nothing at their ends; 0 = none), width_by_depth (yes/no). Every rule
/// whose matchers all match a stroke applies in file order, each attribute it sets overriding
/// the earlier value of that attribute only.

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "toonray/core/math.h"
#include "toonray/ink/feature_edges.h"

namespace toonray::ink {

/// How one stroke is drawn.
struct LineStyle {
    bool draw = true;
    Vec3f colour{0.0f};
    float width = 2.0f;    ///< pixels at 720 lines; scales with the image height
    float opacity = 1.0f;  ///< in [0, 1]
    /// Dash pattern in pixels along the stroke: on, off, on, off, ...; empty = solid.
    std::vector<float> dash;
    float taper = 0.0f;     ///< pixels at 720 lines over which open strokes thin to 0 at their ends
    bool by_depth = false;  ///< width scaled by depth (draw.h, StrokePen::depth_reference)
    bool operator==(const LineStyle&) const = default;
};

/// One `match` line of a style file: matchers and the attributes it sets.
struct LineStyleRule {
    std::vector<std::string> objects{"*"}, materials{"*"};  ///< globs, any may match
    unsigned types = (1u << kEdgeTypeCount) - 1;      ///< bit (1 << EdgeType) per matched type
    bool match_visible = true, match_hidden = false;  ///< `lines=`: visible by default
    std::optional<bool> draw, by_depth;
    std::optional<Vec3f> colour;
    std::optional<float> width, opacity, taper;
    std::optional<std::vector<float>> dash;
    int line = 0;  ///< where it was written, for messages
};

struct LineStyleSet {
    std::vector<LineStyleRule> rules;
    [[nodiscard]] bool empty() const { return rules.empty(); }
    /// Whether some rule turns drawing on for hidden lines (so they must be found).
    [[nodiscard]] bool draws_hidden() const {
        for (const LineStyleRule& r : rules)
            if (r.match_hidden && r.draw.value_or(false)) return true;
        return false;
    }
};

/// Parses a style file's text. Throws Error "NAME:LINE: what was wrong" naming `source` (the
/// file name) and the 1-based line.
[[nodiscard]] LineStyleSet parse_line_styles(std::string_view text, std::string_view source);

/// `*` matches any run of characters, `?` any one; everything else itself.
[[nodiscard]] bool glob_match(std::string_view pattern, std::string_view name);

/// The style of a stroke: `base` for visible lines (hidden lines start from it with draw off),
/// then every matching rule in order.
[[nodiscard]] LineStyle resolve_line_style(const LineStyleSet& set, const LineStyle& base,
                                           std::string_view object, std::string_view material,
                                           EdgeType type, bool visible);

}  // namespace toonray::ink
