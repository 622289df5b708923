#include "toonray/ink/sketch.h"

#include <algorithm>
#include <cmath>

#include "toonray/ink/hash.h"

namespace toonray::ink {

namespace {

// A lattice point's value in [-1, 1].
float lattice(std::int64_t x, std::int64_t y, std::int64_t z, std::uint32_t seed) {
    const std::size_t h = hash_words(static_cast<std::uint32_t>(x) ^ seed,
                                     static_cast<std::uint32_t>(y) ^ (seed * 0x9e3779b9u),
                                     static_cast<std::uint32_t>(z) ^ (seed * 0x85ebca6bu));
    const std::uint64_t mixed = static_cast<std::uint64_t>(h) * 0xff51afd7ed558ccdull;
    return static_cast<float>(mixed >> 40) * (2.0f / 16777216.0f) - 1.0f;
}

float smooth(float t) { return t * t * (3.0f - 2.0f * t); }

}  // namespace

float value_noise(const Vec3f& p, std::uint32_t seed) {
    const float fx = std::floor(p.x), fy = std::floor(p.y), fz = std::floor(p.z);
    if (!std::isfinite(fx) || !std::isfinite(fy) || !std::isfinite(fz)) return 0.0f;
    const auto x = static_cast<std::int64_t>(fx), y = static_cast<std::int64_t>(fy),
               z = static_cast<std::int64_t>(fz);
    const float tx = smooth(p.x - fx), ty = smooth(p.y - fy), tz = smooth(p.z - fz);
    auto along_x = [&](std::int64_t j, std::int64_t k) {
        return lattice(x, j, k, seed) * (1.0f - tx) + lattice(x + 1, j, k, seed) * tx;
    };
    auto along_y = [&](std::int64_t k) {
        return along_x(y, k) * (1.0f - ty) + along_x(y + 1, k) * ty;
    };
    return along_y(z) * (1.0f - tz) + along_y(z + 1) * tz;
}

std::vector<Stroke> sketch_strokes(std::vector<Stroke> strokes, std::span<const StrokePen> pens,
                                   float world_per_pixel, int frame) {
    std::vector<Stroke> out;
    out.reserve(strokes.size());
    for (Stroke& s : strokes) {
        const StrokePen* pen = s.style < pens.size() ? &pens[s.style] : nullptr;
        const int copies = pen ? static_cast<int>(pen->sketch) : 0;
        if (copies < 2 || s.world.size() != s.points.size() || s.points.size() < 2 ||
            !(pen->sketch_offset > 0.0f)) {
            out.push_back(std::move(s));
            continue;
        }
        // The noise's wavelength in the world, a power of two.
        const float wanted = std::max(pen->sketch_period, 1e-3f) * world_per_pixel;
        int exponent = 0;
        static_cast<void>(
            std::frexp(wanted > 0.0f && std::isfinite(wanted) ? wanted : 1.0f, &exponent));
        const float inverse = std::ldexp(1.0f, -exponent);
        const auto epoch = static_cast<std::uint32_t>(
            pen->boil >= 1.0f ? std::max(frame, 0) / static_cast<int>(pen->boil) : 0);
        const std::size_t n = s.points.size();
        for (int copy = 0; copy < copies; ++copy) {
            const auto seed =
                static_cast<std::uint32_t>(hash_words(static_cast<std::uint32_t>(pen->sketch_seed),
                                                      static_cast<std::uint32_t>(copy), epoch));
            Stroke c = s;
            for (std::size_t i = 0; i < n; ++i) {
                // The stroke's direction on the image at the point (around a closed stroke's
                // seam, from its neighbours across it).
                std::size_t before = i > 0 ? i - 1 : (s.closed ? n - 2 : 0);
                std::size_t after = i + 1 < n ? i + 1 : (s.closed ? 1 : n - 1);
                float tx = s.points[after].x - s.points[before].x,
                      ty = s.points[after].y - s.points[before].y;
                const float len = std::sqrt(tx * tx + ty * ty);
                if (!(len > 0.0f)) continue;
                tx /= len;
                ty /= len;
                const Vec3f at = s.world[i] * inverse;
                const float across = pen->sketch_offset * value_noise(at, seed);
                const float along = 0.5f * pen->sketch_offset * value_noise(at, seed ^ 0x5bd1e995u);
                c.points[i].x += -ty * across + tx * along;
                c.points[i].y += tx * across + ty * along;
            }
            if (s.closed) c.points.back() = c.points.front();
            out.push_back(std::move(c));
        }
    }
    return out;
}

}  // namespace toonray::ink
