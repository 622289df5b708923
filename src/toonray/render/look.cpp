#include "toonray/render/look.h"

#include "toonray/render/classic.h"

namespace toonray {

SurfaceFields look_fields(const ShadingSettings&) { return SurfaceFields::Look; }

void apply_look(const LookFrame& frame, SurfaceSamples& s, std::size_t begin, std::size_t end) {
    const ShadingSettings& shading = frame.shading;
    const std::vector<Material>& materials = frame.scene.materials;
    for (std::size_t i = begin; i < end; ++i) {
        if (!s.found[i]) {
            s.colour[i] = frame.background;
            s.edge[i] = 0;
            continue;
        }
        s.colour[i] =
            cel_colour(shading, s.albedo[i], s.band[i], s.accents[i], materials[s.material[i]].ks);
        // The albedo as bytes: where a texture or vertex colours vary it within a band.
        const Vec3f& a = s.albedo[i];
        s.edge[i] = frame.varying_albedo ? static_cast<std::uint32_t>(to_byte(a.x)) |
                                               static_cast<std::uint32_t>(to_byte(a.y)) << 8 |
                                               static_cast<std::uint32_t>(to_byte(a.z)) << 16
                                         : 0;
    }
}

}  // namespace toonray
