#pragma once
/// Triangle sets for the accelerator tests: random soups and the test meshes.

#include <array>
#include <cstdint>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "toonray/core/math.h"
#include "toonray/scene/obj_loader.h"

namespace toonray::test_support {

/// Triangles as the accelerator takes them: positions and corner indices.
struct Soup {
    std::vector<Vec3f> positions;
    std::vector<std::array<std::uint32_t, 3>> tris;
};

/// `count` triangles of size up to `size` scattered in [-1, 1]^3, from a fixed seed (the same
/// soup on every machine: std::mt19937 and uniform_real_distribution<float> are specified).
inline Soup random_soup(int count, unsigned seed, float size = 0.2f) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> pos(-1.0f, 1.0f), off(-size, size);
    Soup s;
    for (int i = 0; i < count; ++i) {
        Vec3f c(pos(rng), pos(rng), pos(rng));
        auto base = static_cast<std::uint32_t>(s.positions.size());
        for (int k = 0; k < 3; ++k) s.positions.push_back(c + Vec3f(off(rng), off(rng), off(rng)));
        s.tris.push_back({base, base + 1, base + 2});
    }
    return s;
}

/// The unit square in the plane z = 0, corners (0,0), (1,0), (1,1), (0,1), as the two
/// triangles `tris` (rays straight down meet its edges, diagonal and corners exactly).
inline Soup unit_square(std::vector<std::array<std::uint32_t, 3>> tris) {
    return {{{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}}, std::move(tris)};
}

/// The triangles of tests/data/<name>.
inline Soup from_obj(const std::string& name) {
    Scene scene;
    Warnings w;
    load_obj(std::string(TOONRAY_TEST_DATA_DIR) + "/" + name, scene, w);
    return {scene.positions, scene.tri_positions};
}

}  // namespace toonray::test_support
