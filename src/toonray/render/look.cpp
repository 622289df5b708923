#include "toonray/render/look.h"

namespace toonray {

unsigned look_fields(const ShadingSettings&) {
    return 0;  // the cel look reads its terms as shading finds them (look_hit)
}

void apply_look(const LookFrame& frame, SurfaceSamples& s, std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
        const LookResult look =
            s.found[i] ? look_hit(frame, s.material[i], s.albedo[i], s.band[i], s.accents[i])
                       : look_miss(frame);
        s.colour[i] = look.colour;
        s.edge[i] = look.edge;
    }
}

}  // namespace toonray
