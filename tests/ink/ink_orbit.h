#pragma once
/// A slow camera orbit with ink lines: the number and total length of the visible strokes in
/// each frame.

#include <vector>

#include "ink/ink_scenes.h"
#include "toonray/ink/ink.h"

namespace toonray::test_support {

struct StrokeSeries {
    std::vector<double> counts, lengths;  ///< per frame: visible strokes, their length in px
};

/// Draws the ink lines of `frames` views, the camera turned by `degrees_per_frame` about the
/// vertical through its gaze point from one to the next.
inline StrokeSeries orbit_strokes(const Scene& scene, const TriangleAccel& accel,
                                  const CameraSpec& start, int w, int h, int frames,
                                  float degrees_per_frame) {
    StrokeSeries series;
    ink::InkLines lines;
    for (int frame = 0; frame < frames; ++frame) {
        const CameraSpec camera =
            orbit_camera(start, degrees_per_frame * static_cast<float>(frame));
        ink::draw_ink_lines(scene, accel, camera, w, h, {}, 0, lines);
        double count = 0, length = 0;
        for (const ink::Stroke& s : lines.strokes)
            if (s.visible) {
                ++count;
                length += ink::polyline_length(s.points);
            }
        series.counts.push_back(count);
        series.lengths.push_back(length);
    }
    return series;
}

}  // namespace toonray::test_support
