#pragma once
/// Sketchy strokes (LineStyle::sketch): several overdrawn copies of a stroke, each moved across
/// and along it on the image by a noise of its points' places in the world. The noise is
/// anchored on the surfaces, not the screen: a still camera and scene give the same copies
/// frame after frame, and a moving one carries them with the surfaces. It is a value noise on
/// an integer lattice hashed with the seed (no library random numbers, whose sequences differ
/// between standard libraries): the same bits on every machine and thread count.

#include <span>
#include <vector>

#include "toonray/core/math.h"
#include "toonray/ink/draw.h"
#include "toonray/ink/strokes.h"

namespace toonray::ink {

/// A smooth noise in [-1, 1] of a point in lattice units, for a seed.
[[nodiscard]] float value_noise(const Vec3f& p, std::uint32_t seed);

/// The strokes with each one whose pen asks for sketch >= 2 copies (and that has its points'
/// places, Stroke::world) replaced by its copies, in order. `world_per_pixel` turns the pens'
/// periods (pixels) into world units: the size of a pixel at the distance of the scene's
/// centre, the product rounded to a power of two so that small moves of the camera keep the
/// noise. `frame` with the pen's boil picks the noise: it changes every `boil` frames.
[[nodiscard]] std::vector<Stroke> sketch_strokes(std::vector<Stroke> strokes,
                                                 std::span<const StrokePen> pens,
                                                 float world_per_pixel, int frame);

}  // namespace toonray::ink
