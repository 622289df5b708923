#pragma once
/// Embree 3 as an independent closest-hit reference (when the build found it). Everything
/// Embree stays in this file pair, so the benchmark builds without it.

#include <array>
#include <cstdint>
#include <memory>
#include <span>

#include "toonray/accel/triangle_accel.h"

namespace toonray::bench {

class EmbreeScene {
public:
    /// True when the benchmark was built with Embree.
    static bool available();

    /// Builds an Embree scene over the triangles (default build quality, as an application
    /// would). Throws std::runtime_error when Embree is not available or fails.
    EmbreeScene(std::span<const Vec3f> positions,
                std::span<const std::array<std::uint32_t, 3>> tris);
    ~EmbreeScene();
    EmbreeScene(const EmbreeScene&) = delete;
    EmbreeScene& operator=(const EmbreeScene&) = delete;

    /// Closest hit with t in [0, ray.tmax]; fills t and prim (u, v as Embree reports them).
    bool intersect(const Ray& ray, Hit& hit) const;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace toonray::bench
