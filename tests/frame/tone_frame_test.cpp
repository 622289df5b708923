// Tone looks and band and shadow lines through the frame layer: the PNG, the feature images, the
// EXR and the SVG all come from one drawing, and are the same bytes for any thread count.

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include "support/instance_scenes.h"
#include "support/test_scenes.h"
#include "support/test_support.h"
#include "toonray/frame/feature_images.h"
#include "toonray/frame/frame_renderer.h"
#include "toonray/frame/settings.h"
#include "toonray/io/exr.h"
#include "toonray/io/file.h"
#include "toonray/io/png.h"

using namespace toonray;
namespace fs = std::filesystem;

namespace {

// Every file a frame wrote, by name, as bytes.
std::vector<std::pair<std::string, std::string>> files_of(const fs::path& dir) {
    std::vector<std::pair<std::string, std::string>> files;
    for (const auto& entry : fs::recursive_directory_iterator(dir))
        if (entry.is_regular_file())
            files.emplace_back(fs::relative(entry.path(), dir).string(), read_file(entry.path()));
    std::sort(files.begin(), files.end());
    return files;
}

FrameOptions options_for(const std::vector<std::pair<std::string, std::string>>& keys) {
    Settings settings;
    settings.render.width = 320;
    settings.render.height = 240;
    for (const auto& [key, value] : keys) set_setting(settings, key, value);
    check_settings(settings);
    return settings.frame_options();
}

// Renders spot with `o` into `dir` (PNG, feature images, SVG, and the EXR when the build has
// it) with `threads` threads.
void render_spot(FrameOptions o, int threads, const fs::path& dir) {
    o.settings.threads = threads;
    o.aov_dir = dir / "aov";
    o.svg = dir / "frame.svg";
    o.svg_hidden = true;
    if (exr_available()) o.aov_exr = dir / "frame.exr";
    FrameRenderer renderer;
    Warnings warnings;
    SceneFrame frame = test_support::scene_frame(test_support::load_test_scene("spot.obj"),
                                                 o.settings.width, o.settings.height);
    renderer.render(frame, dir / "frame.png", o, warnings);
}

}  // namespace

TEST(ToneFrames, AreTheSameBytesForOneAndTwoThreads) {
    const std::vector<std::vector<std::pair<std::string, std::string>>> looks = {
        {{"tone.mode", "hatch"}},
        {{"tone.mode", "hatch"}, {"tone.anchor", "screen"}},
        {{"tone.mode", "screentone"}},
        {{"tone.mode", "screentone"}, {"tone.anchor", "object"}},
        {{"lines.types", "all,band,shadow"}, {"shading.shadows", "true"}},
    };
    for (const auto& keys : looks) {
        test_support::TempDir one("tone_one"), two("tone_two");
        const FrameOptions o = options_for(keys);
        render_spot(o, 1, one.path);
        render_spot(o, 2, two.path);
        const auto a = files_of(one.path), b = files_of(two.path);
        ASSERT_EQ(a.size(), b.size());
        for (std::size_t i = 0; i < a.size(); ++i) {
            EXPECT_EQ(a[i].first, b[i].first);
            EXPECT_TRUE(a[i].second == b[i].second)
                << keys[0].second << ": " << a[i].first << " differs";
        }
        // The tone and the two new line types have feature images of their own.
        for (const char* name :
             {"frame_tone.png", "frame_lines_band.png", "frame_lines_shadow.png"})
            EXPECT_TRUE(fs::exists(one.path / "aov" / name)) << name;
    }
}

TEST(ToneFrames, TheSvgHoldsTheToneUnderTheLinesAndTheFeatureImageIsItsCoverage) {
    for (const char* mode : {"hatch", "screentone"}) {
        test_support::TempDir dir("tone_svg");
        render_spot(options_for({{"tone.mode", mode}}), 2, dir.path);
        const std::string svg = read_file(dir.path / "frame.svg");
        const std::size_t tone = svg.find("<g id=\"tone\""),
                          visible = svg.find("<g id=\"visible\"");
        ASSERT_NE(tone, std::string::npos) << mode;
        EXPECT_LT(tone, visible) << "the tone goes under the lines";
        const std::string group = svg.substr(tone, visible - tone);
        const std::string element = std::string(mode) == "hatch" ? "<path" : "<circle";
        std::size_t count = 0;
        for (std::size_t at = group.find(element); at != std::string::npos;
             at = group.find(element, at + 1))
            ++count;
        EXPECT_GT(count, 100u) << mode;
        // The _tone image is the tone's coverage: dark where the tone is, white elsewhere.
        const DecodedPng png = read_png(dir.path / "aov" / "frame_tone.png");
        long dark = 0;
        for (std::size_t i = 0; i < png.rgb.size(); ++i) dark += png.rgb.data()[i][0] < 128;
        EXPECT_GT(dark, 500) << mode;
    }
}

TEST(ToneFrames, ToneLooksAndBandLinesNeedTheInkLines) {
    for (const char* mode : {"robust", "classic"}) {
        Settings s;
        set_setting(s, "lines.mode", mode);
        set_setting(s, "tone.mode", "hatch");
        EXPECT_THROW(check_settings(s), Error) << mode;
        Settings band;
        set_setting(band, "lines.mode", mode);
        set_setting(band, "lines.types", "all,band");
        EXPECT_THROW(check_settings(band), Error) << mode;
    }
    Settings shadow;
    set_setting(shadow, "lines.types", "silhouette,shadow");
    EXPECT_THROW(check_settings(shadow), Error) << "shadow lines without toon shadows";
    set_setting(shadow, "shading.shadows", "true");
    EXPECT_NO_THROW(check_settings(shadow));
}

TEST(ToneFrames, SettingsRoundTripThroughToml) {
    Settings s;
    set_setting(s, "tone.mode", "screentone");
    set_setting(s, "tone.anchor", "object");
    set_setting(s, "tone.hatch_direction", "0.5,1,0");
    set_setting(s, "tone.spacing", "4.5");
    set_setting(s, "tone.angle", "15");
    set_setting(s, "lines.types", "silhouette,band");
    Settings back;
    read_settings(settings_toml(s), "tone.toml", back);
    EXPECT_EQ(back.render.tone, s.render.tone);
    EXPECT_EQ(back.render.lines.types, s.render.lines.types);
    EXPECT_EQ(settings_toml(back), settings_toml(s));
    // Unset, the anchor is the mode's own and written as a comment.
    EXPECT_NE(settings_toml(Settings{}).find("# anchor is not set"), std::string::npos);
}

TEST(ToneFrames, InstancesAreTonedAndLinedAsInTheFlattenedScene) {
    // Tone, band and shadow lines are found on a scene's own triangles: a scene with instances
    // is drawn flattened for them, so each instance is toned (or lined) as its copy in the
    // flattened scene.
    const Scene instanced = test_support::instanced_test_scene();
    const Scene flat = flatten_instances(instanced);
    for (const char* mode : {"hatch", "screentone", "band lines"}) {
        const bool lines = std::string(mode) == "band lines";
        FrameOptions o =
            lines ? options_for({{"lines.types", "all,band,shadow"}, {"shading.shadows", "true"}})
                  : options_for({{"tone.mode", mode}});
        o.keep_layers = true;
        const SceneFrame frame = test_support::scene_frame(
            instanced, test_support::instanced_test_camera(), o.settings.width, o.settings.height);
        Warnings warnings;
        FrameRenderer with_instances, flattened;
        const FrameLayers& a =
            with_instances.render_layers(instanced, frame.camera, frame.lights, o, warnings);
        const FrameLayers& b =
            flattened.render_layers(flat, frame.camera, frame.lights, o, warnings);
        auto same = [](const auto& p, const auto& q) {
            return p.width() == q.width() && p.height() == q.height() &&
                   std::equal(p.data(), p.data() + p.width() * p.height(), q.data());
        };
        EXPECT_TRUE(same(a.image, b.image)) << mode;
        EXPECT_TRUE(same(a.tone, b.tone)) << mode;
        EXPECT_TRUE(same(a.lines, b.lines)) << mode;
        EXPECT_EQ(with_instances.drawn_scene()->triangle_count(), flat.triangle_count()) << mode;
        // And the instances are toned (or have band lines): some of their pixels are covered.
        const ImageF& covered = lines ? a.line_type("band")->coverage : a.tone;
        std::vector<std::uint8_t> instance_object(instanced.objects.size(), 0);
        for (const Instance& instance : instanced.instances) instance_object[instance.object] = 1;
        double on_instances = 0.0;
        for (int y = 0; y < a.tone.height(); ++y)
            for (int x = 0; x < a.tone.width(); ++x)
                if (a.object(x, y) != kNoIndex && instance_object[a.object(x, y)])
                    on_instances += covered(x, y);
        EXPECT_GT(on_instances, 50.0) << mode;
    }
}
