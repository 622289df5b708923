// The ink line step (ink/ink.h): the lines are found on the geometry and drawn before the
// buckets (Renderer::render), so a pixel they cover completely needs no more than one sample;
// each bucket resolves its colours, and the lines are composited over them at the end.

#include <algorithm>

#include "toonray/ink/draw.h"
#include "toonray/render/line_step.h"
#include "toonray/render/renderer.h"

namespace toonray {

ink::InkSettings ink_settings(const RenderSettings& settings) {
    ink::InkSettings s;
    const LineSettings& lines = settings.lines;
    const bool ink = lines.mode == LineMode::Ink;
    // Outside the ink mode the geometry's lines are strokes only for an SVG.
    const unsigned types = ink || settings.strokes ? lines.types : 0u;
    s.edges.silhouettes = (types & kLineSilhouette) != 0;
    s.edges.borders = (types & kLineSilhouette) != 0;
    s.edges.creases = (types & kLineCrease) != 0;
    s.edges.materials = (types & kLineMaterial) != 0;
    s.edges.intersections = (types & kLineObject) != 0;
    s.bands = (types & kLineBand) != 0;
    s.shadows = (types & kLineShadow) != 0 && settings.shading.shadows;
    s.band_thresholds = settings.shading.ramp.thresholds;
    s.edges.crease_angle = lines.crease_angle;
    s.width = lines.width;
    s.colour = lines.colour;
    s.taper = lines.ink.taper;
    s.width_by_depth = lines.ink.width_by_depth;
    s.styles = lines.ink.styles;
    s.brushes = settings.brushes;
    s.frame = settings.frame;
    s.chain.hidden = settings.strokes && settings.hidden_lines;
    if (ink) s.tone = settings.tone;
    for (float level : settings.shading.ramp.levels)
        s.band_darkness.push_back(std::clamp(1.0f - level, 0.0f, 1.0f));
    // The other modes draw their own lines: of the strokes only the polylines go over them.
    if (!ink) s.drawn_types = 1u << static_cast<unsigned>(ink::EdgeType::Polyline);
    return s;
}

namespace {

class InkLines : public LineStep {
public:
    void begin(const FrameContext& frame, FrameLayers& out) override {
        // Where the lines cover a pixel completely its colour cannot show, so it needs no more
        // than one sample; not with the layers, whose cel image shows the colours under them.
        covered_.reshape(0, 0);
        if (frame.settings.layers || !out.strokes) return;
        // The lines only: thin tone strokes cover few pixels completely, and a pass over the
        // frame to find them costs more than the samples they would save.
        const ink::InkLines& ink = *out.strokes;
        ink::opaque_lines(ink.coverage, ink.style, ink.pens, covered_);
    }
    const std::uint8_t* covered() const override {
        return covered_.size() > 0 ? covered_.data() : nullptr;
    }

    void bucket(const FrameContext&, const Bucket& bucket, const BucketSampler& sampler,
                FrameLayers& out) override {
        sampler.resolve_colours(bucket.pixels, out.image, 0, 0);
    }

    void finish(const FrameContext& frame, FrameLayers& out) override {
        const RenderSettings& settings = frame.settings;
        const ink::InkLines& ink = *out.strokes;
        if (settings.layers) out.cel = out.image;
        // The tone under the lines, as hatching goes before lines.
        const bool tone = ink.tone_coverage.size() > 0;
        if (tone)
            ink::composite_styled_lines(ink.tone_coverage, ink.tone_style, ink.pens, out.image);
        ink::composite_styled_lines(ink.coverage, ink.style, ink.pens, out.image);
        if (!settings.layers) return;
        out.lines = ink.coverage;
        if (tone) out.tone = ink.tone_coverage;
        else out.tone.resize(settings.width, settings.height, 0.0f);
        // Each type's strokes drawn with their own pens, exactly as in the frame's line layer.
        std::vector<ink::Stroke> strokes;
        Image<std::uint16_t> style;
        for (int type = 0; type < ink::kEdgeTypeCount; ++type) {
            if (type == static_cast<int>(ink::EdgeType::Tone)) continue;  // out.tone
            strokes.clear();
            for (const ink::Stroke& s : ink.strokes)
                if (static_cast<int>(s.type) == type) strokes.push_back(s);
            LineLayer& layer = out.line_types.emplace_back();
            layer.name = ink::edge_type_name(static_cast<ink::EdgeType>(type));
            ink::draw_styled_strokes(strokes, ink.pens, settings.width, settings.height,
                                     layer.coverage, style, settings.threads);
        }
    }

    std::uint64_t held_frame_bytes() const override { return bytes_of(covered_); }

    std::uint64_t frame_bytes_per_pixel(const RenderSettings& settings) const override {
        // The line layer (coverage and style); without the layers also the mask of pixels the
        // lines cover; with them the style of one type's layer while it is drawn. A tone look
        // draws a layer of its own (the ink step runs in the ink mode, where tone is drawn).
        const std::uint64_t line_layer = sizeof(float) + sizeof(std::uint16_t);
        const std::uint64_t tone = settings.tone.mode != ink::ToneMode::Cel ? line_layer : 0;
        return line_layer + (settings.layers ? sizeof(std::uint16_t) : 1) + tone;
    }

private:
    Image<std::uint8_t> covered_;
};

}  // namespace

std::unique_ptr<LineStep> make_ink_lines() { return std::make_unique<InkLines>(); }

}  // namespace toonray
