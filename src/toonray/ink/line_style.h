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
/// and drawn, only where a rule says so). Attributes: the rows of style_attributes() (draw,
/// color or colour, width, opacity, dash, taper, width_by_depth). Every rule whose matchers all
/// match a stroke applies in file order, each attribute it sets overriding the earlier value of
/// that attribute only.
///
/// The same keys and value texts serve any other document that holds rules (a settings file's
/// rule tables): make_line_style_rule builds a rule from (key, value) pairs and
/// line_style_rule_entries gives them back.

#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <variant>
#include <vector>

#include "toonray/core/math.h"
#include "toonray/ink/feature_edges.h"

namespace toonray::ink {

/// How one stroke is drawn: one field per row of style_attributes(). Lengths are in pixels at
/// 720 lines here; a StrokePen (draw.h) is the same in pixels of one image.
struct LineStyle {
    bool draw = true;
    Vec3f colour{0.0f};
    float width = 2.0f;    ///< pixels at 720 lines; scales with the image height
    float opacity = 1.0f;  ///< in [0, 1]
    /// Dash pattern in pixels along the stroke: on, off, on, off, ...; empty = solid.
    std::vector<float> dash;
    float taper = 0.0f;     ///< pixels at 720 lines over which open strokes thin to 0 at their ends
    bool by_depth = false;  ///< width scaled by depth (draw.h, StrokePen::depth_reference)
    /// A pressure profile: factors on the width at evenly spaced points from the stroke's first
    /// point to its last, linear between them; empty = 1 throughout.
    std::vector<float> pressure;
    /// A broad nib held at `nib_angle`: a stroke drawn along the nib is this fraction of the
    /// width, across it the whole width, sin-weighted between; 1 = a round pen.
    float calligraphy = 1.0f;
    float nib_angle = 45.0f;  ///< degrees, counter-clockwise on the image
    /// A brush: a PNG image whose darkness (1 - luma) is the ink across (its rows) and along
    /// (its columns) the stroke; empty = none. Read by the frame layer (InkSettings::brushes).
    std::string brush;
    /// The brush stretched once along the whole stroke; else stamped, repeating every width
    /// times the image's aspect.
    bool brush_stretch = false;
    /// Sketchy strokes: this many overdrawn copies, each moved across the stroke by up to
    /// `sketch_offset` by a noise anchored on the surface (0 or 1: the stroke itself).
    float sketch = 0.0f;
    float sketch_offset = 2.0f;   ///< pixels at 720 lines
    float sketch_period = 40.0f;  ///< pixels at 720 lines: the noise's wavelength
    float sketch_seed = 0.0f;     ///< a whole number: another seed, other copies
    float boil = 0.0f;  ///< a whole number: the noise changes every this many frames; 0 = never
    bool operator==(const LineStyle&) const = default;
};

/// What an attribute's value is, which decides how its text is read and written back and
/// whether it scales with the image height.
enum class StyleValueKind {
    YesNo,     ///< `yes` or `no`
    Colour,    ///< `#rrggbb` or `r,g,b` in [0, 1] (core/parse.h, parse_colour)
    Length,    ///< pixels at 720 lines in [0, max]; scales with the image height
    Fraction,  ///< a number in [0, 1]
    Dash,      ///< lengths in pixels at 720 lines in [0, max], on,off,...; `none`; scales
    Profile,   ///< 2 to 16 factors in [0, max], comma-separated; `none`
    Degrees,   ///< an angle in [-max, max]
    Count,     ///< a whole number in [0, max]
    Path,      ///< a file name (no blanks); `none`
};

/// How an attribute reaches the SVG (svg.h).
enum class SvgMapping {
    LeaveOut,  ///< `draw`: visible strokes whose pen does not draw are not written
    /// A presentation attribute of the stroke's path (svg_stroke), written where it differs
    /// from the group's; on a filled outline, svg_fill (or nothing: the outline has the shape).
    PathAttribute,
    /// The width varies along the stroke: the path is the filled outline of the stroke
    /// (draw.h, varies_width); svg_stroke and svg_fill hold nothing.
    Outline,
};

/// The LineStyle field of an attribute.
using StyleField = std::variant<bool LineStyle::*, Vec3f LineStyle::*, float LineStyle::*,
                                std::vector<float> LineStyle::*, std::string LineStyle::*>;

/// One row of the table of style attributes: everything the parser, the resolver, the pen in
/// pixels and the SVG need to know of it. Adding an attribute is adding a field to LineStyle,
/// a row to the table and its drawing.
struct StyleAttribute {
    std::string_view name;                      ///< as written in .style files
    std::span<const std::string_view> aliases;  ///< other spellings accepted
    StyleValueKind kind;
    StyleField field;  ///< must hold the type `kind` reads
    float max = 0.0f;  ///< Length: the largest value; Dash: the largest length
    std::string_view help;
    SvgMapping svg = SvgMapping::PathAttribute;
    std::string_view svg_stroke;  ///< the attribute on a stroked path (PathAttribute)
    std::string_view svg_fill;    ///< the attribute on a filled outline, if any
    float min = 0.0f;             ///< Profile: at least this many values
    /// Whether the value is in pixels at 720 lines and so scales with the image height.
    [[nodiscard]] bool scales() const {
        return kind == StyleValueKind::Length || kind == StyleValueKind::Dash;
    }
    /// Whether `key` names it (its name or an alias).
    [[nodiscard]] bool named(std::string_view key) const;
};

/// The attributes, in the order of LineStyle and of the SVG's path attributes.
[[nodiscard]] std::span<const StyleAttribute> style_attributes();

/// Reads `text` (the value of `attribute`, as in a .style file) into `style`'s field. Throws
/// Error saying what was wrong, without key or place ("expected a number, got 'x'").
void parse_style_value(const StyleAttribute& attribute, std::string_view text, LineStyle& style);

/// The text of `style`'s value of `attribute`, as in a .style file; parse_style_value reads it
/// back to the same value, bit for bit.
[[nodiscard]] std::string format_style_value(const StyleAttribute& attribute,
                                             const LineStyle& style);

/// `style` with every attribute that scales (StyleAttribute::scales) converted from pixels at
/// 720 lines to pixels of an image `height` pixels tall (draw.h, stroke_thickness).
[[nodiscard]] LineStyle scale_line_style(const LineStyle& style, int height);

/// One rule (a `match` line of a style file): matchers and the attributes it sets.
struct LineStyleRule {
    std::vector<std::string> objects{"*"}, materials{"*"};  ///< globs, any may match
    unsigned types = (1u << kEdgeTypeCount) - 1;      ///< bit (1 << EdgeType) per matched type
    bool match_visible = true, match_hidden = false;  ///< `lines=`: visible by default
    /// The values of the attributes it sets; the others keep LineStyle's defaults (so that
    /// rules setting the same values compare equal).
    LineStyle values;
    std::uint32_t sets = 0;  ///< bit i: sets style_attributes()[i]
    int line = 0;            ///< where it was written, for messages
    /// Whether the rule sets the attribute of this LineStyle field.
    [[nodiscard]] bool sets_field(const StyleField& field) const;
    bool operator==(const LineStyleRule&) const = default;
};

/// One of a rule's matchers: its key and what it matches.
struct RuleMatcher {
    std::string_view name;
    std::string_view help;
};

/// The matchers (object, material, type, lines), in the order of their documentation.
[[nodiscard]] std::span<const RuleMatcher> rule_matchers();

/// Every key a rule may hold: the matchers, then each attribute's name and its aliases.
[[nodiscard]] std::vector<std::string_view> line_rule_keys();

/// Where a rule was written, for its error messages: "WHERE: what" about the rule as a whole
/// and "WHERE<key_separator>KEY: what" about the value of one key. A .style file's rule is
/// {"lines.style:3", ": ", 3}: "lines.style:3: width: expected a number, got 'x'"; a settings
/// table {"settings.toml: lines.rule[2]", "."}: "settings.toml: lines.rule[2].width: ...".
struct RuleLocation {
    std::string where;
    std::string key_separator = ": ";
    int line = 0;  ///< kept as LineStyleRule::line
};

/// A key and its value's text, as after `match` in a .style file (`width=1.5` is
/// {"width", "1.5"}).
using RuleEntry = std::pair<std::string, std::string>;

/// Builds a rule from its entries in order, as a .style file's `match` line with those
/// key=value words. Throws Error naming `at`: an unknown key, a key given twice (as written:
/// `color` and `colour` are two keys, the later wins), or a bad value.
[[nodiscard]] LineStyleRule make_line_style_rule(std::span<const RuleEntry> entries,
                                                 const RuleLocation& at);

/// The entries of a rule: each matcher that differs from its default, then each attribute
/// the rule sets, by its name, in table order. make_line_style_rule of them (with the rule's
/// line) gives an equal rule.
[[nodiscard]] std::vector<RuleEntry> line_style_rule_entries(const LineStyleRule& rule);

struct LineStyleSet {
    std::vector<LineStyleRule> rules;
    [[nodiscard]] bool empty() const { return rules.empty(); }
    /// Whether some rule turns drawing on for hidden lines (so they must be found).
    [[nodiscard]] bool draws_hidden() const {
        for (const LineStyleRule& r : rules)
            if (r.match_hidden && r.sets_field(&LineStyle::draw) && r.values.draw) return true;
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
