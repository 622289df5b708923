// The look stage (render/look.h): colours from the surface record, and what refinement compares.
#include "toonray/render/look.h"

#include <gtest/gtest.h>

using namespace toonray;

namespace {

Scene two_materials() {
    Scene s;
    Material shiny("shiny");
    shiny.kd = Vec3f(0.5f, 0.25f, 1.0f);
    shiny.ks = Vec3f(0.25f);
    s.materials.push_back(shiny);
    return s;
}

// One hit sample of `s` with these fields, kept with keys and where.
SurfaceSamples one_sample(std::uint32_t object, std::uint32_t material, std::uint8_t band,
                          std::uint8_t accents, const Vec3f& albedo) {
    SurfaceSamples samples;
    samples.resize(1, kSurfaceKeys | kSurfaceWhere, 1);
    samples.found[0] = 1;
    samples.object[0] = object;
    samples.material[0] = material;
    samples.band[0] = band;
    samples.accents[0] = accents;
    samples.albedo[0] = albedo;
    return samples;
}

}  // namespace

TEST(CelLook, EachBandIsItsLevelWithTheAccentsAdded) {
    const Scene scene = two_materials();
    ShadingSettings shading;
    shading.rim_strength = 0.5f;
    const LookFrame frame{scene, shading, Vec3f(1.0f), false};
    const Vec3f albedo(0.5f, 0.25f, 1.0f);
    for (std::uint8_t band = 0; band < 3; ++band) {
        const LookResult plain = look_hit(frame, 1, albedo, band, 0);
        EXPECT_EQ(plain.colour, albedo * shading.ramp.levels[band]);
        EXPECT_EQ(plain.edge, 0u);
        // The highlight adds the material's Ks, the rim albedo times the rim strength.
        EXPECT_EQ(look_hit(frame, 1, albedo, band, kAccentHighlight).colour,
                  albedo * shading.ramp.levels[band] + Vec3f(0.25f));
        EXPECT_EQ(look_hit(frame, 1, albedo, band, kAccentRim).colour,
                  albedo * shading.ramp.levels[band] + albedo * 0.5f);
    }
    EXPECT_EQ(look_miss(frame).colour, Vec3f(1.0f));
    // apply_look gives what shading's look gives.
    SurfaceSamples samples = one_sample(0, 1, 2, kAccentHighlight, albedo);
    apply_look(frame, samples, 0, 1);
    EXPECT_EQ(samples.colour[0], look_hit(frame, 1, albedo, 2, kAccentHighlight).colour);
}

TEST(CelLook, TheEdgeSignalIsTheAlbedoWhereItVaries) {
    const Scene scene = two_materials();
    const ShadingSettings shading;
    const LookFrame flat{scene, shading, Vec3f(1.0f), false};
    const LookFrame textured{scene, shading, Vec3f(1.0f), true};
    const Vec3f a(0.5f, 0.25f, 1.0f), b(0.5f, 0.26f, 1.0f);
    EXPECT_EQ(look_hit(flat, 1, a, 2, 0).edge, look_hit(flat, 1, b, 2, 0).edge);
    EXPECT_NE(look_hit(textured, 1, a, 2, 0).edge, look_hit(textured, 1, b, 2, 0).edge);
    EXPECT_EQ(look_hit(textured, 1, a, 2, 0).edge, look_hit(textured, 1, a, 0, 0).edge);
}

TEST(RefineKey, DiffersInEveryDiscreteFieldAndNothingElse) {
    const Vec3f albedo(0.5f);
    auto key_of = [](const SurfaceSamples& s) { return refine_key(s, 0); };
    auto differ = [](const RefineKey& a, const RefineKey& b) {
        return a.ids != b.ids || a.shade != b.shade;
    };
    const RefineKey base = key_of(one_sample(3, 1, 2, 0, albedo));
    EXPECT_FALSE(differ(base, key_of(one_sample(3, 1, 2, 0, Vec3f(0.9f)))))
        << "the albedo counts only through the look's edge signal";
    EXPECT_TRUE(differ(base, key_of(one_sample(4, 1, 2, 0, albedo))));
    EXPECT_TRUE(differ(base, key_of(one_sample(3, 0, 2, 0, albedo))));
    EXPECT_TRUE(differ(base, key_of(one_sample(3, 1, 1, 0, albedo))));
    EXPECT_TRUE(differ(base, key_of(one_sample(3, 1, 2, kAccentRim, albedo))));
    SurfaceSamples edged = one_sample(3, 1, 2, 0, albedo);
    edged.edge[0] = 7;
    EXPECT_TRUE(differ(base, key_of(edged)));
    SurfaceSamples missed = one_sample(3, 1, 2, 0, albedo);
    missed.found[0] = 0;
    EXPECT_TRUE(differ(base, key_of(missed)));
}
