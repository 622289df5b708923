#include "toonray/frame/settings.h"

#include <gtest/gtest.h>

#include <set>
#include <string>

#include "support/test_support.h"
#include "toonray/io/file.h"

using namespace toonray;

namespace {

// Settings with every key away from its default, and two line rules.
Settings changed() {
    Settings s;
    set_setting(s, "image.size", std::string("321x123"));
    set_setting(s, "image.background", std::string("0.1,0.2,0.3"));
    set_setting(s, "scene.camera", std::string("1,2,3,0,0,0,0,1,0"));
    set_setting(s, "scene.lights",
                std::vector<std::string>{"dir:0,-1,0.25@0.5", "point:1e-07,2,3"});
    set_setting(s, "scene.auto_smooth", 30.5);
    set_setting(s, "shading.ramp", std::string("0.2,0.6,1@0.1,0.7"));
    set_setting(s, "shading.shadows", true);
    set_setting(s, "shading.specular", true);
    set_setting(s, "shading.rim", 0.3);
    set_setting(s, "shading.rim_strength", 0.5);
    set_setting(s, "shading.textures", false);
    set_setting(s, "lines.mode", std::string("robust"));
    set_setting(s, "lines.types", std::string("silhouette,depth"));
    set_setting(s, "lines.crease_angle", 33.3);
    set_setting(s, "lines.width", std::int64_t{3});
    set_setting(s, "lines.colour", std::string("#402010"));
    set_setting(s, "lines.classic.depth_threshold", 7.5);
    set_setting(s, "lines.classic.normal_threshold", 3.25);
    set_setting(s, "lines.robust.depth_step", 0.03);
    set_setting(s, "lines.robust.silhouette_ratio", 0.2);
    set_setting(s, "lines.ink.taper", 4.0);
    set_setting(s, "lines.ink.width_by_depth", true);
    set_setting(s, "tone.mode", std::string("hatch"));
    set_setting(s, "tone.anchor", std::string("screen"));
    set_setting(s, "tone.hatch_direction", std::string("light"));
    set_setting(s, "tone.spacing", 5.5);
    set_setting(s, "tone.angle", std::int64_t{30});
    set_setting(s, "sampling.samples", std::int64_t{9});
    set_setting(s, "sampling.adaptive", false);
    set_setting(s, "sampling.tile_size", std::int64_t{64});
    set_setting(s, "render.threads", std::int64_t{2});
    set_setting(s, "render.bvh_leaf_size", std::int64_t{4});
    set_setting(s, "output.png_level", std::int64_t{6});
    set_setting(s, "output.svg_hidden", true);
    set_setting(s, "output.svg_fill", true);
    set_setting(s, "output.svg_plotter", true);
    set_setting(s, "limits.triangles", std::string("5M"));
    set_setting(s, "limits.vertices", std::string("6M"));
    set_setting(s, "limits.image_pixels", std::string("10M"));
    set_setting(s, "limits.memory", std::string("4G"));
    set_setting(s, "limits.input_size", std::string("512M"));
    add_line_rule(s, {{{"object", "w*,b?"}, {"type", "crease"}, {"color", "#808080"}}}, "test");
    add_line_rule(s, {{{"lines", "hidden"}, {"draw", "yes"}, {"dash", "4,2"}, {"width", "0.5"}}},
                  "test");
    return s;
}

}  // namespace

TEST(Settings, EveryKeyIsChangedByTheDocumentAndReadBackExactly) {
    const Settings s = changed();
    const std::string text = settings_toml(s);
    // Every key of the table is written with a value (none left as a comment).
    for (const Setting& setting : settings_table())
        EXPECT_NE(text.find(std::string(setting.key.substr(setting.key.rfind('.') + 1)) + " = "),
                  std::string::npos)
            << setting.key << "\n"
            << text;
    Settings back;
    read_settings(text, "round.toml", back);
    EXPECT_EQ(settings_toml(back), text);
    EXPECT_EQ(back.render.width, 321);
    EXPECT_EQ(back.render.lines.mode, LineMode::Robust);
    EXPECT_EQ(back.render.lines.crease_angle, 33.3f);
    EXPECT_EQ(back.scene.lights, s.scene.lights);
    EXPECT_EQ(back.render.shading.ramp, s.render.shading.ramp);
    EXPECT_EQ(back.render.lines.ink.styles.rules, s.render.lines.ink.styles.rules);
    EXPECT_EQ(back.limits, s.limits);
    EXPECT_EQ(back.applied_limits(Limits{}).max_memory, 4ull << 30);
}

TEST(Settings, ADocumentChangesOnlyTheKeysItHas) {
    Settings s;
    read_settings("[lines]\nwidth = 5\n[shading]\nshadows = true\n", "part.toml", s);
    EXPECT_EQ(s.render.lines.width, 5.0f);
    EXPECT_TRUE(s.render.shading.shadows);
    const Settings defaults;
    EXPECT_EQ(s.render.lines.mode, defaults.render.lines.mode);
    EXPECT_EQ(s.render.sampling.samples, defaults.render.sampling.samples);
}

TEST(Settings, ErrorsNameTheFileThePlaceAndTheKey) {
    auto error = [](const std::string& text) {
        return test_support::error_of([&] {
            Settings s;
            read_settings(text, "bad.toml", s);
        });
    };
    EXPECT_EQ(error("[lines]\nwidht = 2\n"), "bad.toml:2:1: unknown key 'lines.widht'");
    EXPECT_EQ(error("[lines]\nwidth = \"wide\"\n"),
              "bad.toml:2:9: lines.width: expected a number, got 'wide'");
    EXPECT_EQ(error("[sampling]\nsamples = 5\n"),
              "bad.toml:2:11: sampling.samples: 5 samples per pixel: must be 1, 4, 9 or 16 (a "
              "square grid per pixel)");
    EXPECT_EQ(error("[shading]\nrim = 2.0\n"), "bad.toml:2:7: shading.rim: 2 is outside [0, 0.99]");
    EXPECT_EQ(error("[lines]\nmode = \"fancy\"\n"),
              "bad.toml:2:8: lines.mode: mode: unknown line mode 'fancy' (ink, robust or classic)");
    EXPECT_EQ(error("[shading]\nshadows = 1\n"),
              "bad.toml:2:11: shading.shadows: expected true or false, got 1");
    EXPECT_EQ(error("[[lines.rule]]\ntype = \"crease\"\n[[lines.rule]]\nwidth = \"x\"\n"),
              "bad.toml:3:1: lines.rule[2].width: expected a number, got 'x'");
    EXPECT_EQ(error("lines = 3\n"), "bad.toml:1:1: unknown key 'lines'");
    const std::string syntax = error("[lines\nwidth = 2\n");
    EXPECT_EQ(syntax.rfind("bad.toml:1:", 0), 0u) << syntax;
    // Characters the TOML reader mishandles are refused before it sees them (found by fuzzing).
    EXPECT_EQ(error("[lines]\nwidth = 2 # \xc3\xa9\n"),
              "bad.toml:2:13: a character that is not ASCII (settings documents are ASCII; a "
              ".style file can name other objects)");
    EXPECT_EQ(error(std::string("[\0\x13]\n", 5)),
              "bad.toml:1:2: control character 0x00 (TOML allows none but the tab)");
    // A document that breaks one of the TOML reader's own checks is refused (found by fuzzing:
    // with the checks off, clang may compile the reader as if they always held).
    const std::string unfinished = error("[\nshadows = true\n");
    EXPECT_EQ(unfinished.rfind("bad.toml: not a TOML document the reader can read (its check '", 0),
              0u)
        << unfinished;
    EXPECT_EQ(error("[lines]\r\n\twidth = 2\x7f\n"),
              "bad.toml:2:11: control character 0x7f (TOML allows none but the tab)");
}

TEST(Settings, OutputsRecordOnlyWhatCanChangeThePicture) {
    const Settings s = changed();
    const std::string recorded = settings_toml(s, true);
    for (const char* left_out : {"threads", "tile_size", "bvh_leaf_size", "png_level", "[limits]"})
        EXPECT_EQ(recorded.find(left_out), std::string::npos) << left_out;
    for (const char* kept : {"size = \"321x123\"", "samples = 9", "[[lines.rule]]"})
        EXPECT_NE(recorded.find(kept), std::string::npos) << kept;
    const OutputRecord record = output_record(s);
    EXPECT_EQ(record.software, "toonray " + std::string(toonray_version()));
    EXPECT_EQ(record.settings, recorded);
    // Threads and buckets never change a frame: settings that differ only in them record the same.
    Settings other = s;
    other.render.threads = 7;
    other.render.sampling.tile_size = 5;
    EXPECT_EQ(output_record(other).settings, recorded);
    // Keys that came later are recorded when set, and left out at their defaults, so that the
    // frames made without them record what they did before.
    for (const char* kept : {"[tone]", "mode = \"hatch\"", "spacing = 5.5", "svg_plotter = true"})
        EXPECT_NE(recorded.find(kept), std::string::npos) << kept;
    const std::string plain = settings_toml(Settings{}, true);
    for (const char* left_out : {"[tone]", "svg_plotter", "anchor"})
        EXPECT_EQ(plain.find(left_out), std::string::npos) << left_out;
    EXPECT_NE(settings_toml(Settings{}).find("[tone]"), std::string::npos)
        << "the whole document has every key";
}

TEST(Settings, TheTableHasOneKeyAndFlagEach) {
    std::set<std::string_view> keys, flags;
    const Settings defaults;
    for (const Setting& s : settings_table()) {
        EXPECT_TRUE(keys.insert(s.key).second) << s.key;
        if (!s.flag.empty()) {
            EXPECT_TRUE(flags.insert(s.flag).second) << s.flag;
        }
        EXPECT_FALSE(s.help.empty()) << s.key;
        // A default value reads back as itself.
        if (const auto value = s.get(defaults)) {
            Settings again;
            s.set(again, *value);
            EXPECT_EQ(settings_toml(again), settings_toml(defaults)) << s.key;
        }
    }
}

TEST(Settings, TheInkModeRefusesDepthLinesAskedByName) {
    // Before: --edges ink --lines depth drew nothing without a word.
    Settings s;
    set_setting(s, "lines.types", std::string("depth"));
    s.render.lines.mode = LineMode::Robust;
    EXPECT_NO_THROW(check_settings(s)) << "robust lines have depth lines";
    s.render.lines.mode = LineMode::Ink;
    const std::string message = test_support::error_of([&] { check_settings(s); });
    EXPECT_NE(message.find("lines.types: the ink mode finds no depth lines"), std::string::npos)
        << message;
    s.render.lines.types = kLineAll;  // all: every type the mode has
    EXPECT_NO_THROW(check_settings(s));
}

TEST(Settings, TheDocsListEveryKeyWithItsOption) {
    const std::string doc = read_file(std::string(TOONRAY_DOCS_DIR) + "/settings.md");
    for (const Setting& s : settings_table()) {
        EXPECT_NE(doc.find("| `" + std::string(s.key) + "` |"), std::string::npos) << s.key;
        if (!s.flag.empty()) {
            const std::string flag(s.flag.substr(0, s.flag.find(',')));
            EXPECT_NE(doc.find("`" + flag + "`"), std::string::npos) << flag;
        }
    }
}
