#pragma once
/// Everything a frame is rendered with: image, shading, lines, sampling, and what is kept
/// besides the picture.

#include "toonray/core/math.h"
#include "toonray/ink/draw.h"
#include "toonray/ink/tone.h"
#include "toonray/render/line_settings.h"
#include "toonray/render/shading.h"

namespace toonray {

/// Adaptive supersampling (render/sampler.h), for the robust and ink lines.
struct SamplingSettings {
    int samples = 4;  ///< per pixel on a regular grid: 1, 4, 9 or 16
    /// One sample per pixel, and the whole grid only where neighbours differ. false: every
    /// pixel takes every sample (full supersampling, the reference adaptive frames are measured
    /// against).
    bool adaptive = true;
    /// Pixels per side of the buckets the frame is rendered in. Memory follows the bucket, not
    /// the image; the frame is the same for any size. 126: with the one pixel of halo each side
    /// that a bucket traces, 128 = 8 of the accelerator's 16-ray tiles (piano frame: 3% fewer
    /// instructions in the bucket pass than 64).
    int tile_size = 126;
};

struct RenderSettings {
    int width = 1280;
    int height = 720;
    Vec3f background{1.0f};   ///< colour of pixels that see nothing
    ShadingSettings shading;  ///< ramp, shadows, specular, rim, textures
    LineSettings lines;
    /// The tone look (ink/tone.h): cel, or hatching or screentone drawn as ink over every
    /// band's full colour (the ink mode only).
    ink::ToneSettings tone;
    SamplingSettings sampling;
    int threads = 0;  ///< 0 = all hardware threads
    /// Fill the per-pixel layers of FrameLayers (render/frame_layers.h). The picture is the
    /// same either way.
    bool layers = false;
    /// Keep the strokes (FrameLayers::strokes) in every mode, for SVG: the ink lines of the
    /// geometry with the mode's line types. The picture is the same either way.
    bool strokes = false;
    /// With strokes: also chain the hidden lines, with the number of surfaces hiding them.
    /// They are drawn only where a line style says so.
    bool hidden_lines = false;
    /// The frame's number in its sequence (sketchy strokes boil with it; 0 for a single frame).
    int frame = 0;
    /// The brushes line styles name, read by the frame layer (frame/frame_renderer.h); null
    /// when no style names one.
    const ink::BrushSet* brushes = nullptr;
};

/// Sub-samples per pixel side for a sample count: 1, 4, 9, 16 -> 1, 2, 3, 4. Throws Error
/// ("N samples per pixel: ...") otherwise.
[[nodiscard]] int samples_per_side(int samples);

}  // namespace toonray
