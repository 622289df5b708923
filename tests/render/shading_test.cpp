#include "toonray/render/shading.h"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>

#include "toonray/core/error.h"
#include "toonray/render/classic.h"
#include "toonray/render/render_settings.h"
#include "toonray/render/trace.h"

using namespace toonray;

namespace {

// A square in z = 0 facing +z, from (-a,-a) to (a,a), with texture coordinates 0..1.
Scene square(float a, Vec3f kd = Vec3f(1.0f)) {
    Scene s;
    s.positions = {{-a, -a, 0}, {a, -a, 0}, {a, a, 0}, {-a, a, 0}};
    s.texcoords = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
    Material m("paint");
    m.kd = kd;
    s.materials.push_back(m);
    s.add_triangle({0, 1, 2}, 1, 0, {kNoIndex, kNoIndex, kNoIndex}, {0, 1, 2});
    s.add_triangle({0, 2, 3}, 1, 0, {kNoIndex, kNoIndex, kNoIndex}, {0, 2, 3});
    return s;
}

// The toon colour (shade_hit) of the surface at each pixel's centre; `seen` is 1 where a
// surface is seen.
struct Shaded {
    Image<Vec3f> colour;
    Image<std::uint8_t> seen;
};

Shaded shade(const Scene& s, const RenderSettings& settings, const std::vector<Light>& lights,
             const CameraSpec& cam, const TextureSet* textures = nullptr) {
    TriangleAccel accel;
    accel.build(s.positions, s.tri_positions);
    const ViewPlane view = make_view_plane(cam, settings.width, settings.height);
    const ShadingContext ctx{s, accel, settings.shading, lights, textures};
    Shaded out{Image<Vec3f>(settings.width, settings.height, settings.background),
               Image<std::uint8_t>(settings.width, settings.height, 0)};
    trace_primary(accel, view, settings.width, settings.height, 1, 1, [&](const SampleTile& t) {
        for (int y = t.y0; y < t.y1; ++y)
            for (int x = t.x0; x < t.x1; ++x) {
                const std::size_t i = static_cast<std::size_t>(y - t.y0) * t.width() + (x - t.x0);
                if (!t.found[i]) continue;
                const Vec3f n = shading_normal(s, t.hits[i], t.dirs[i]);
                out.colour(x, y) = shade_hit(ctx, t.hits[i], view.eye, t.dirs[i], n);
                out.seen(x, y) = 1;
            }
    });
    return out;
}

Image<Vec3f> colours(const Scene& s, const RenderSettings& settings,
                     const std::vector<Light>& lights, const CameraSpec& cam,
                     const TextureSet* textures = nullptr) {
    return shade(s, settings, lights, cam, textures).colour;
}

const CameraSpec kTopDown{{0, 0, 8}, {0, 0, 7}, {0, 1, 0}};  // sees x, y in [-8, 8]

}  // namespace

TEST(ToonRamp, DefaultIsTheSeedsSixteenLevelTable) {
    ToonRamp ramp;
    for (int i = -100; i <= 1100; ++i) {
        float x = i / 1000.0f;
        ASSERT_EQ(ramp.level(std::min(std::max(0.0f, x), 1.0f)), classic_cel_level(x)) << x;
    }
    for (float x : {0.25f, std::nextafter(0.25f, 0.0f), 0.5f, std::nextafter(0.5f, 0.0f)})
        EXPECT_EQ(ramp.level(x), classic_cel_level(x)) << x;
}

TEST(ToonRamp, ParsesLevelsAndThresholds) {
    ToonRamp r = parse_ramp("0.2,0.6,0.8,1@0.1,0.4,0.7");
    EXPECT_EQ(r.level(0.05f), 0.2f);
    EXPECT_EQ(r.level(0.1f), 0.6f);
    EXPECT_EQ(r.level(0.69f), 0.8f);
    EXPECT_EQ(r.level(0.9f), 1.0f);
    EXPECT_EQ(parse_ramp("0.7").level(0.0f), 0.7f);  // one flat band
    for (const char* bad :
         {"", "0.5,1@0.3,0.6", "0.5,1", "0.5,0.7,1@0.5,0.2", "a,1@0.5", "0.5,1@x"})
        EXPECT_THROW(parse_ramp(bad), Error) << bad;
}

TEST(Lights, ParseFromOptions) {
    Light p = parse_light("4,6,10");
    EXPECT_EQ(p.kind, Light::Kind::Point);
    EXPECT_EQ(p.vector, Vec3f(4, 6, 10));
    Light d = parse_light("dir:0,-1,0@0.5");
    EXPECT_EQ(d.kind, Light::Kind::Directional);
    EXPECT_EQ(d.intensity, 0.5f);
    EXPECT_THROW((void)parse_light("dir:0,0,0"), Error);
    EXPECT_THROW((void)parse_light("1,2"), Error);
    EXPECT_THROW((void)parse_light("1,2,3@-1"), Error);
}

TEST(Lights, ErrorsNameTheValueNotAnOption) {
    try {
        (void)parse_light("1,2,3@-1");
        FAIL();
    } catch (const Error& e) {
        EXPECT_EQ(std::string(e.what()), "light '1,2,3@-1': intensity must be one number >= 0");
    }
    try {
        parse_ramp("0.5,1@x");
        FAIL();
    } catch (const Error& e) {
        EXPECT_EQ(std::string(e.what()), "ramp '0.5,1@x': malformed number 'x'");
    }
}

TEST(Shading, DirectionalLightsAddUp) {
    Scene s = square(10.0f);
    RenderSettings settings;
    settings.width = 32;
    settings.height = 32;
    // One directional light at 70 degrees from the normal: l.n = cos 70 = 0.34 -> 0.75 band.
    float a = 70.0f * 3.14159265f / 180.0f;
    std::vector<Light> lights = {
        Light{Light::Kind::Directional, {std::sin(a), 0, -std::cos(a)}, 1.0f}};
    EXPECT_EQ(colours(s, settings, lights, kTopDown)(16, 16).x, 0.75f);
    // Two of them: 0.68 -> the 1.0 band.
    lights.push_back(Light{Light::Kind::Directional, {-std::sin(a), 0, -std::cos(a)}, 1.0f});
    EXPECT_EQ(colours(s, settings, lights, kTopDown)(16, 16).x, 1.0f);
    // Dimmed to a quarter each: 0.17 -> 0.5 band.
    for (Light& l : lights) l.intensity = 0.25f;
    EXPECT_EQ(colours(s, settings, lights, kTopDown)(16, 16).x, 0.5f);
}

TEST(Shading, ToonShadowsDarkenWhatIsBlocked) {
    // A floor and a small square hovering above its middle, lit from straight above.
    Scene s = square(10.0f);
    auto base = static_cast<std::uint32_t>(s.positions.size());
    for (Vec3f p : {Vec3f(-2, -2, 3), Vec3f(2, -2, 3), Vec3f(2, 2, 3), Vec3f(-2, 2, 3)})
        s.positions.push_back(p);
    s.add_triangle({base, base + 1, base + 2}, 1, 0);
    s.add_triangle({base, base + 2, base + 3}, 1, 0);
    RenderSettings settings;
    settings.width = 64;
    settings.height = 64;
    std::vector<Light> lights = {Light{Light::Kind::Directional, {0, 0, -1}, 1.0f}};
    // Look from the side so the floor under the hovering square shows.
    CameraSpec cam{{0, -12, 9}, {0, -11.2f, 8.4f}, {0, 0.6f, 0.8f}};
    const Image<Vec3f> lit = colours(s, settings, lights, cam);
    Image<Vec3f> without = lit;
    settings.shading.shadows = true;
    const Image<Vec3f> shadowed = colours(s, settings, lights, cam);
    int darker = 0, same = 0;
    for (int y = 0; y < 64; ++y)
        for (int x = 0; x < 64; ++x) {
            if (shadowed(x, y).x < without(x, y).x) ++darker;
            else if (shadowed(x, y).x == without(x, y).x) ++same;
            EXPECT_LE(shadowed(x, y).x, without(x, y).x);
        }
    EXPECT_GT(darker, 20);  // the shadow on the floor
    EXPECT_GT(same, 1000);  // everything else unchanged
}

TEST(Shading, SpecularBandFromKsAndNs) {
    Scene s = square(10.0f, Vec3f(0.5f));
    s.materials[1].ks = Vec3f(0.3f);
    s.materials[1].ns = 50.0f;
    RenderSettings settings;
    settings.width = 64;
    settings.height = 64;
    std::vector<Light> lights = {
        Light{Light::Kind::Point, {0, 0, 8}, 1.0f}};  // at the eye: highlight in the middle
    EXPECT_EQ(colours(s, settings, lights, kTopDown)(32, 32).x, 0.5f);  // off by default
    settings.shading.specular = true;
    const Image<Vec3f> c = colours(s, settings, lights, kTopDown);
    EXPECT_FLOAT_EQ(c(32, 32).x, 0.8f);  // Kd + Ks in the band
    EXPECT_FLOAT_EQ(c(2, 2).x, 0.5f);    // far from it: no highlight (l.n = 0.58, the full band)
}

TEST(Shading, RimBandBrightensGrazingSurfaces) {
    Scene s = square(10.0f, Vec3f(0.5f));
    RenderSettings settings;
    settings.width = 64;
    settings.height = 64;
    std::vector<Light> lights = {Light{Light::Kind::Directional, {0, 0, -1}, 1.0f}};
    settings.shading.rim = 0.5f;  // where |n.v| < 0.5
    // A steep view: the far part of the plane is seen at a grazing angle.
    CameraSpec cam{{0, -3, 1.5f}, {0, -2.3f, 1.0f}, {0, 0.58f, 0.81f}};
    const Image<Vec3f> c = colours(s, settings, lights, cam);
    int rim = 0;
    for (int y = 0; y < 64; ++y)
        for (int x = 0; x < 64; ++x)
            if (std::abs(c(x, y).x - 0.5f * (1.0f + settings.shading.rim_strength)) < 1e-6f) ++rim;
    EXPECT_GT(rim, 50);
    settings.shading.rim = 0.0f;
    const Shaded plain_shaded = shade(s, settings, lights, cam);
    const Image<Vec3f>& plain = plain_shaded.colour;
    for (int y = 0; y < 64; ++y)
        for (int x = 0; x < 64; ++x)
            if (plain_shaded.seen(x, y)) {
                EXPECT_LE(plain(x, y).x, 0.5f);
            }
}

TEST(Shading, TexturesMultiplyKd) {
    // 16 x 16 texture of solid quadrants: red, green (top), blue, white (bottom). Bilinear
    // filtering gives the exact colours away from the quadrant boundaries.
    ImageRgb8 tex(16, 16);
    for (int y = 0; y < 16; ++y)
        for (int x = 0; x < 16; ++x)
            tex(x, y) = y < 8 ? (x < 8 ? Rgb8{255, 0, 0} : Rgb8{0, 255, 0})
                              : (x < 8 ? Rgb8{0, 0, 255} : Rgb8{255, 255, 255});
    Scene s = square(8.0f);
    TextureSet textures(s.materials.size());
    textures[1] = std::make_shared<const ImageRgb8>(tex);
    RenderSettings settings;
    settings.width = 64;
    settings.height = 64;
    std::vector<Light> lights = {Light{Light::Kind::Directional, {0, 0, -1}, 1.0f}};
    const Image<Vec3f> c = colours(s, settings, lights, kTopDown, &textures);
    // Texture v = 0 is the bottom of the image (OBJ convention): the top-left quadrant is red.
    EXPECT_EQ(c(16, 16), Vec3f(1, 0, 0));
    EXPECT_EQ(c(48, 16), Vec3f(0, 1, 0));  // top right: green
    EXPECT_EQ(c(16, 48), Vec3f(0, 0, 1));  // bottom left: blue
    EXPECT_EQ(c(48, 48), Vec3f(1, 1, 1));  // bottom right: white

    // Without a texture for the material (an empty set, or textures off), Kd alone.
    const TextureSet none;
    EXPECT_EQ(colours(s, settings, lights, kTopDown, &none)(16, 16), Vec3f(1, 1, 1));
    settings.shading.textures = false;
    EXPECT_EQ(colours(s, settings, lights, kTopDown, &textures)(16, 16), Vec3f(1, 1, 1));
}

TEST(Shading, PlainPathEqualsTheGeneralOne) {
    // shade_hit takes a short path for one point light without shadows, specular, rim or
    // texture. Shadows on an open square (nothing can block the light) and a second, zero
    // intensity light both force the general path, which must give bit-identical colours.
    Scene s = square(10.0f, Vec3f(0.8f, 0.6f, 0.3f));
    RenderSettings settings;
    settings.width = 48;
    settings.height = 48;
    std::vector<Light> lights = {
        Light{Light::Kind::Point, {6, 0, 1.5f}, 1.0f}};  // low: all three bands
    const Image<Vec3f> plain = colours(s, settings, lights, kTopDown);
    int bands[3] = {0, 0, 0};
    for (std::size_t i = 0; i < plain.size(); ++i)
        for (int b = 0; b < 3; ++b)
            bands[b] += plain.data()[i].x == 0.8f * (b == 0 ? 0.5f : b == 1 ? 0.75f : 1.0f);
    EXPECT_GT(bands[0], 0);
    EXPECT_GT(bands[1], 0);
    EXPECT_GT(bands[2], 0);
    struct Lit {
        RenderSettings settings;
        std::vector<Light> lights;
    };
    Lit shadowed{settings, lights};
    shadowed.settings.shading.shadows = true;
    Lit two_lights{settings, lights};
    two_lights.lights.push_back(Light{Light::Kind::Point, {0, 0, 5}, 0.0f});
    for (const Lit& general : {shadowed, two_lights}) {
        const Image<Vec3f> other = colours(s, general.settings, general.lights, kTopDown);
        ASSERT_EQ(other.size(), plain.size());
        for (std::size_t i = 0; i < plain.size(); ++i)
            EXPECT_EQ(other.data()[i], plain.data()[i]) << i;
    }
}
