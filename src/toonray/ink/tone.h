#pragma once
/// Tone looks drawn as ink (`--tone hatch|screentone`): how dark each cel band is becomes hatch
/// strokes or screentone dots over the band's full colour. They are made here as ink: hatch
/// strokes are feature segments on the surfaces, cut to where they belong and then through the
/// ink's visibility, chaining, styles, drawing and SVG like every line (ink.h); dots are strokes
/// of one point whose width is their size (docs/looks.md).
///
/// Hatching lays families of parallel slices on the surfaces: the planes u(p) = K s0 of a
/// function u (a world coordinate along a direction, anchored on the object; or an image
/// coordinate, locked to the screen). Each plane K has a rank r(K), the bit-reversed K (the van
/// der Corput radical inverse), and is drawn at a point p where r(K) < q(p), with q(p) = f(p)
/// s0 / (g |grad u(p)|): f the share of the family's full density the band's darkness asks for,
/// g the spacing in pixels and grad u the gradient of u along the surface on the image. The
/// strokes present where q is small stay where it is larger, so a darker band keeps a lighter
/// one's strokes (tonal art maps nest theirs), and since r(2K) = r(K) / 2 a family keeps the same
/// strokes at any s0 and thins out as a surface recedes or turns away: its spacing on the image
/// stays g / f on average, with no level to pop between.

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "toonray/accel/triangle_accel.h"
#include "toonray/core/math.h"
#include "toonray/ink/feature_edges.h"
#include "toonray/ink/screen.h"
#include "toonray/scene/light.h"
#include "toonray/scene/scene.h"

namespace toonray::ink {

/// The look that turns a band's darkness into something (`--tone`).
enum class ToneMode : std::uint8_t {
    Cel,         ///< the ramp's levels scale the colour (the default)
    Hatch,       ///< hatch strokes over the full colour
    Screentone,  ///< dots over the full colour
};

/// What tone strokes and dots are fixed to (`--tone-anchor`).
enum class ToneAnchor : std::uint8_t {
    Object,  ///< the surfaces: they move with the object and the camera
    Screen,  ///< the image
};

/// Which way hatch strokes run on object-anchored surfaces (`--hatch-direction`).
struct HatchDirection {
    enum class Kind : std::uint8_t {
        /// Per object, sections across the direction along which its normals vary least (an
        /// elongated form's axis): strokes run around the form, along its largest curvature.
        Curvature,
        Light,   ///< sections across the light's direction: strokes follow the band boundaries
        Axis,    ///< sections across a world axis (x, y, z or a vector)
        Screen,  ///< sections whose traces on the image run at the tone angle
    };
    Kind kind = Kind::Curvature;
    Vec3f axis{0.0f, 1.0f, 0.0f};  ///< Axis: as given (not zero, finite); used made unit
    bool operator==(const HatchDirection&) const = default;
};

struct ToneSettings {
    ToneMode mode = ToneMode::Cel;
    /// Unset: the mode's own, object for hatching and screen for screentone.
    std::optional<ToneAnchor> anchor;
    HatchDirection direction;
    /// Pixels at 720 lines: for hatching the spacing of one family's strokes where it is
    /// complete; for screentone the side of a dot's cell.
    float spacing = 6.0f;
    /// Degrees, counter-clockwise on the image: the screen's hatch strokes, and the rows of
    /// screentone cells.
    float angle = 45.0f;

    [[nodiscard]] ToneAnchor anchored() const {
        return anchor ? *anchor
                      : (mode == ToneMode::Screentone ? ToneAnchor::Screen : ToneAnchor::Object);
    }
    bool operator==(const ToneSettings&) const = default;
};

/// "cel", "hatch", "screentone".
[[nodiscard]] std::string_view tone_mode_name(ToneMode mode);
/// Throws Error ("unknown tone 'x' (cel, hatch or screentone)").
[[nodiscard]] ToneMode parse_tone_mode(std::string_view text);
/// "object", "screen".
[[nodiscard]] std::string_view tone_anchor_name(ToneAnchor anchor);
/// Throws Error ("unknown tone anchor 'x' (object or screen)").
[[nodiscard]] ToneAnchor parse_tone_anchor(std::string_view text);
/// "curvature", "light", "screen", "x", "y", "z" or "X,Y,Z" (any finite non-zero vector).
/// Throws Error saying what was wrong.
[[nodiscard]] HatchDirection parse_hatch_direction(std::string_view text);
/// The text parse_hatch_direction reads back to the same direction.
[[nodiscard]] std::string format_hatch_direction(const HatchDirection& direction);

/// What the tone needs of shading: the ramp band of a point of a surface as the picture shades
/// it (render implements it with the frame's light terms, toon shadows included).
class ToneShading {
public:
    virtual ~ToneShading() = default;
    /// The band of point `p` of triangle `prim` at barycentric (u, v) (of corners 1 and 2),
    /// seen from the eye. Called from any thread.
    [[nodiscard]] virtual std::uint8_t band(std::uint32_t prim, float u, float v,
                                            const Vec3f& p) const = 0;
    /// Whether the band follows the diffuse term alone (no toon shadows): hatch_segments then
    /// interpolates a small triangle's diffuse term from its corners, as band lines do
    /// (light_lines.h), rather than finding each point's band.
    [[nodiscard]] virtual bool bands_follow_corners() const { return false; }
};

/// The most hatch families: the direction, the crossing one, then the two diagonals.
inline constexpr int kHatchFamilies = 4;

/// How one tone pen covers: its width and opacity in pixels of the image (the resolved style of
/// tone strokes, line_style.h), and the share of each family's full density each band needs.
struct TonePen {
    bool draw = false;
    float width = 0.0f;  ///< pixels of the image
    /// Per band, per family: the share f of the family's full density (spacing g); a family is
    /// complete (f = 1) before the next one starts.
    std::vector<std::array<float, kHatchFamilies>> share;
};

/// The shares of the families for darkness `darkness` (0 to 1) drawn with a pen covering
/// `coverage` = width / spacing of the surface when a family is complete, at opacity `opacity`:
/// family k covers c_k = clamp(1 - (1 - D) / prod_{j<k} (1 - c_j), 0, coverage) with D =
/// darkness / opacity, so that 1 - prod (1 - c_k) = D while the families last. Shares are c_k /
/// coverage; all 0 without coverage.
[[nodiscard]] std::array<float, kHatchFamilies> hatch_shares(float darkness, float coverage,
                                                             float opacity);

/// The radical inverse of K in base 2 (its 64 bits reversed, as a fraction in [0, 1)).
[[nodiscard]] double plane_rank(std::int64_t k);

/// Everything tone strokes are made from for one view.
struct ToneContext {
    const Scene& scene;
    const WeldedMesh& mesh;
    const TriangleAccel& accel;
    const ScreenProjection& view;
    const ViewPlane& plane;
    const ToneShading& shading;
    std::span<const Light> lights;
    std::span<const float> band_thresholds;  ///< the ramp's, for bands of diffuse terms
    const ToneSettings& settings;
    /// Per triangle, the index of its pen in `pens` (its object's and material's tone style).
    std::span<const std::uint16_t> pen_of_triangle;
    std::span<const TonePen> pens;
    int width, height;  ///< of the image
    /// Per object, whether it is closed (feature_edges.h, closed_objects): when it has a volume
    /// and does not hold the eye, its triangles turned away from the eye are hidden, and get no
    /// tone. Shorter or empty: none is.
    std::span<const std::uint8_t> closed = {};
};

/// The hatch strokes of the view as feature segments of type Tone on the surfaces, each cut to
/// where its plane is drawn (r(K) < q, with the band found by `shading` at samples at most a
/// pixel apart on the image, and changes bisected to 1/16 px), before visibility. In a fixed
/// order, whatever the thread count.
[[nodiscard]] std::vector<FeatureSegment> hatch_segments(const ToneContext& context, int threads);

/// A screentone dot: its centre on the image and its radius in pixels (its area is the band's
/// darkness times its cell's area), from triangle `prim`.
struct ToneDot {
    Point2 centre;
    float radius = 0.0f;
    std::uint32_t prim = kNoIndex;
};

/// The visible screentone dots of the view, in a fixed order whatever the thread count:
/// screen-locked, one per cell of a grid of spacing g at the tone angle, centred where the
/// cell's centre ray hits; object-anchored, where the planes of the first two hatch families
/// cross on the surfaces (each thinned as hatching is, so cells stay about g wide on the image),
/// kept where a ray from the eye reaches them.
[[nodiscard]] std::vector<ToneDot> screentone_dots(const ToneContext& context, int threads);

/// The radius of a disc the drawing (draw.h) covers by `area` square pixels in all: it covers
/// pixels at distance d from the centre by clamp(r + 0.5 - d, 0, 1), which sums to pi (r^2 +
/// 1/12) for r >= 1/2 and pi (r + 1/2)^3 / 3 below.
[[nodiscard]] float drawn_disc_radius(float area);

}  // namespace toonray::ink
