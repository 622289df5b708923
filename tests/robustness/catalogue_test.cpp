// The catalogue of bad inputs (docs/robustness.md), run through the command line: each one
// fails with exactly the error given (file, line or byte offset, reason) and exit code 1, and
// leaves no output file behind. Inputs that must work (CRLF, a byte-order mark, degenerate
// triangles, missing materials and textures) render.

#include <gtest/gtest.h>

#include <string>

#include "robustness_util.h"
#include "toonray/io/png.h"

using namespace robustness;

namespace {

struct BadInput {
    std::string name;  ///< test name
    std::string
        args;  ///< toonray arguments; {data} = tests/robustness/data, {out} = a fresh directory
    std::string error;  ///< the expected "toonray: error: " line, without that prefix
};

std::string expand(std::string s, const std::string& out) {
    for (auto [key, value] :
         {std::pair<std::string, std::string>{"{data}", TOONRAY_ROBUSTNESS_DATA}, {"{out}", out}}) {
        for (std::size_t at; (at = s.find(key)) != std::string::npos;)
            s.replace(at, key.size(), value);
    }
    return s;
}

const std::string kRender = "render {data}/";
const std::string kTo = " -o {out}/frame.png --size 64x48 --threads 1";

std::vector<BadInput> catalogue() {
    return {
        // --- files that are not OBJ text ---
        {"EmptyObj", kRender + "empty.obj" + kTo,
         "{data}/empty.obj: empty file: no OBJ statements"},
        {"BlankObj", kRender + "blank.obj" + kTo,
         "{data}/blank.obj: blank file: no OBJ statements"},
        {"BinaryObj", kRender + "binary.obj" + kTo,
         "{data}/binary.obj:3: binary data (NUL byte): not an OBJ text file"},
        // --- numbers ---
        {"NanWeight", kRender + "nan_w.obj" + kTo,
         "{data}/nan_w.obj:4: non-finite number 'nan' in 'v' statement"},
        // --- face indices ---
        {"FaceIndexZero", kRender + "index_zero.obj" + kTo,
         "{data}/index_zero.obj:4: face vertex index 0 in '0' (OBJ indices start at 1)"},
        {"FaceIndexOutOfRange", kRender + "index_out_of_range.obj" + kTo,
         "{data}/index_out_of_range.obj:4: face vertex index 4 out of range (3 vertices defined so far)"},
        {"FaceIndexPast2To31", kRender + "index_2p31.obj" + kTo,
         "{data}/index_2p31.obj:4: face vertex index 2147483648 out of range (3 vertices defined so far)"},
        {"FaceIndexBelowMinus2To31", kRender + "index_negative_2p31.obj" + kTo,
         "{data}/index_negative_2p31.obj:4: face vertex index -2147483649 out of range (3 vertices defined so far)"},
        {"FaceIndexPast2To63", kRender + "index_2p63.obj" + kTo,
         "{data}/index_2p63.obj:4: face vertex index in '9223372036854775808' out of range"},
        {"FaceIndexMostNegative", kRender + "index_llong_min.obj" + kTo,
         "{data}/index_llong_min.obj:4: face vertex index -9223372036854775808 out of range (3 vertices defined so far)"},
        // --- camera blocks ---
        {"CameraBadIndex", kRender + "camera_bad_index.obj" + kTo,
         "{data}/camera_bad_index.obj:6: camera gaze index 7 out of range (3 vertices defined so far)"},
        {"CameraEyeIsGaze", kRender + "camera_eye_is_gaze.obj" + kTo,
         "{data}/camera_eye_is_gaze.obj:8: invalid camera: eye and gaze point are the same point"},
        {"CameraUpParallel", kRender + "camera_up_parallel.obj" + kTo,
         "{data}/camera_up_parallel.obj:8: invalid camera: up vector is zero or parallel to the view direction"},
        {"CameraGazeFarAway", kRender + "camera_far_gaze.obj" + kTo,
         "{data}/camera_far_gaze.obj:8: invalid camera: the gaze point is 3e+07 from the eye (at most 1e6; the "
         "distance sets the field of view, 1 gives 90 degrees)"},
        // --- limits ---
        {"TooManyTriangles", kRender + "degenerate.obj" + kTo + " --max-triangles 3",
         "{data}/degenerate.obj:9: more than 3 triangles (the limit); --max-triangles raises it"},
        {"TooManyVertices", kRender + "degenerate.obj" + kTo + " --max-vertices 4",
         "{data}/degenerate.obj:6: more than 4 vertices ('v') (the limit); --max-vertices raises it"},
        {"InputTooLarge", kRender + "degenerate.obj" + kTo + " --max-input-size 100",
         "{data}/degenerate.obj: 204 bytes, more than the input size limit of 100 bytes (--max-input-size raises it)"},
        {"ImageTooLarge", kRender + "degenerate.obj -o {out}/frame.png --size 20000x20000",
         "image size 20000x20000: 400000000 pixels, more than the limit of 67108864 (--max-image-pixels raises it)"},
        {"FrameBuffersOverMemory",
         kRender +
             "degenerate.obj -o {out}/frame.png --size 4096x4096 --threads 2 --max-memory 64M",
         "a 4096x4096 frame needs about 373 MiB of memory, more than the limit of 64 MiB (--max-memory raises it)"},
        {"BadLimitValue", kRender + "degenerate.obj" + kTo + " --max-triangles lots",
         "--max-triangles: expected a positive number such as 50000000 or 50M, got 'lots'"},
        // --- scores ---
        {"UnknownKey", "piano --score {data}/unknown_key.notes -o {out} --size 64x48 --quiet",
         "{data}/unknown_key.notes:3: unknown key 'w53': white keys are w1..w52"},
        {"UnknownDirective", "score convert {data}/unknown_directive.notes {out}/out.mid",
         "{data}/unknown_directive.notes:2: unknown directive 'swing' (known: ppq, tempo, time, step, wait, "
         "velocity, track, channel, pedal)"},
        {"BinaryScore", "score convert {data}/binary.notes {out}/out.mid",
         "{data}/binary.notes:2: binary data (NUL byte): neither a note script nor a MIDI file (no \"MThd\" header)"},
        {"EmptyScore", "score convert {data}/empty.obj {out}/out.mid",
         "{data}/empty.obj: empty file: not a score (MIDI file or note script)"},
        {"TruncatedMidi", "score convert {data}/truncated.mid {out}/out.notes",
         "{data}/truncated.mid: byte 18: truncated track chunk: length 12 but only 7 bytes left"},
        {"MidiTooManyTracks", "score convert {data}/too_many_tracks.mid {out}/out.notes",
         "{data}/too_many_tracks.mid: byte 10: 65535 tracks exceed the limit of 1024"},
        {"MidiChunkLongerThanFile", "score convert {data}/oversized_chunk.mid {out}/out.notes",
         "{data}/oversized_chunk.mid: byte 18: truncated track chunk: length 2147483647 but only 12 bytes left"},
        {"MidiOverInputLimit", "score convert {data}/good.mid {out}/out.notes --max-input-size 20",
         "{data}/good.mid: 34 bytes, more than the input size limit of 20 bytes (--max-input-size raises it)"},
        {"ScoreLastingCenturies", "piano --score {data}/long.notes -o {out} --size 64x48 --quiet",
         "36028794871 s at 24 fps: over 2147483647 frames is more than the limit of 10000000"},
        {"SoundtrackOverMemory",
         "piano --score {data}/good.mid -o {out} --audio {out}/a.wav --seconds 400000 --fps 0.001 --max-memory 1G "
         "--size 64x48 --quiet",
         "the soundtrack (400000 s) needs about 131 GiB of memory, more than the limit of 1.0 GiB (--max-memory "
         "raises it)"},
        {"DemoScoreLastingCenturies",
         "demo --score {data}/long.notes -o {out} --full --size 64x48 --quiet",
         "36028794871 s at 24 fps: over 2147483647 frames is more than the limit of 10000000"},
        {"DemoSoundtrackOverMemory",
         "demo --score {data}/good.mid -o {out} --seconds 400000 --fps 0.001 --max-memory 1G --size 64x48 --quiet",
         "the soundtrack (400000 s) needs about 131 GiB of memory, more than the limit of 1.0 GiB (--max-memory "
         "raises it)"},
        // --- camera paths ---
        {"CameraPathTimesDecrease",
         "piano --camera-path {data}/times_decrease.campath -o {out} --seconds 1 --size 64x48 --quiet",
         "{data}/times_decrease.campath:2: key times must increase: 1 s comes after 2 s (line 1)"},
        {"BinaryCameraPath",
         "piano --camera-path {data}/binary.campath -o {out} --seconds 1 --size 64x48 --quiet",
         "{data}/binary.campath:2: binary data (NUL byte): not a camera path file"},
        // --- frame ranges ---
        {"FrameRangeBackwards", "batch keys 5 4 --input {data} --output {out}",
         "frame range 5 4: the first frame is after the last"},
        {"FrameRangeTooLong", "batch keys 0 2000000000 --input {data} --output {out}",
         "frame range 0 2000000000: 2000000001 frames is more than the limit of 10000000"},
        {"TooManyJobsForMemory",
         "batch keys 1 4 --input {data} --output {out} --size 1024x1024 --jobs 4 --max-memory 64M",
         "4 frames at once (a 1024x1024 frame each) needs about 124 MiB of memory, more than the limit of 64 MiB "
         "(--max-memory raises it, or render fewer frames at once with --jobs)"},
        // --- glTF ---
        {"GltfCountPastBufferView", kRender + "gltf_huge_count.gltf" + kTo,
         "{data}/gltf_huge_count.gltf: accessors[0].count: 4294967295 exceeds the buffer view "
         "(bufferViews[0], 36 bytes)"},
        {"GltfIndexOutOfRange", kRender + "gltf_index.gltf" + kTo,
         "{data}/gltf_index.gltf: meshes[0].primitives[0].indices: index 9 at element 2 is out of "
         "range (3 vertices)"},
        {"GltfCyclicNodes", kRender + "gltf_cycle.gltf" + kTo,
         "{data}/gltf_cycle.gltf: nodes[2].children: the node hierarchy has a cycle through "
         "nodes[1]"},
        {"GltfNodeWeightsWithoutTargets", kRender + "gltf_node_weights.gltf" + kTo,
         "{data}/gltf_node_weights.gltf: nodes[0].weights: 1 weights for the 0 morph targets of "
         "meshes[0]"},
        {"GltfSkinOfGltf1", kRender + "gltf_skin_1_0.gltf" + kTo,
         "{data}/gltf_skin_1_0.gltf: skins[0]: missing \"joints\" (jointNames and bindShapeMatrix "
         "are glTF 1.0; a glTF 2.0 skin lists its joint nodes by index in \"joints\", and its "
         "bind shape is part of \"inverseBindMatrices\")"},
        {"GltfNoAsset", kRender + "gltf_no_asset.gltf" + kTo,
         "{data}/gltf_no_asset.gltf: asset: missing (a glTF 2.0 file has \"asset\": "
         "{\"version\": \"2.0\"})"},
        {"GltfBase64Garbage", kRender + "gltf_base64.gltf" + kTo,
         "{data}/gltf_base64.gltf: buffers[0].uri: the data URI's payload is not base64"},
        {"GltfTruncatedGlb", kRender + "gltf_truncated.glb" + kTo,
         "{data}/gltf_truncated.glb: byte 8: truncated GLB: the header says 540 bytes, the file "
         "has 520"},
        {"GltfZerosOverMemory", kRender + "gltf_zeros.gltf" + kTo + " --max-memory 512M",
         "{data}/gltf_zeros.gltf: accessors[0] (90000000 values without a buffer view) needs "
         "about 5.4 GiB of memory, more than the limit of 512 MiB (--max-memory raises it)"},
        {"GltfTooManyVertices", kRender + "gltf_triangle.gltf" + kTo + " --max-vertices 2",
         "{data}/gltf_triangle.gltf: accessors[0].count: 3 is more than the limit of 2 "
         "(--max-vertices raises it)"},
    };
}

void PrintTo(const BadInput& b, std::ostream* os) { *os << b.name; }

class Catalogue : public ::testing::TestWithParam<BadInput> {};

}  // namespace

TEST_P(Catalogue, FailsWithTheExactErrorAndLeavesNothing) {
    const BadInput& c = GetParam();
    TempDir out("catalogue_" + c.name);
    CommandResult r = run_toonray(expand(c.args, out.path.string()));
    EXPECT_EQ(r.exit_code, 1) << r.output;
    std::vector<std::string> errors = error_lines(r.output);
    ASSERT_EQ(errors.size(), 1u) << r.output;
    EXPECT_EQ(errors[0], expand(c.error, out.path.string()));
    EXPECT_EQ(files_under(out.path), std::vector<std::string>{})
        << "a failed run must leave no output";
}

INSTANTIATE_TEST_SUITE_P(BadInputs, Catalogue, ::testing::ValuesIn(catalogue()),
                         [](const auto& info) { return info.param.name; });

TEST(CatalogueCli, DirectoryGivenAsSceneIsRefusedBeforeAnyWork) {
    TempDir out("catalogue_dir");
    CommandResult r = run_toonray(expand("render {data} -o {out}/frame.png", out.path.string()));
    EXPECT_NE(r.exit_code, 0) << r.output;
    EXPECT_NE(r.output.find("scene: File is actually a directory"), std::string::npos) << r.output;
    EXPECT_EQ(files_under(out.path), std::vector<std::string>{});
}

TEST(CatalogueCli, HelpListsTheLimitsAndTheirDefaults) {
    for (const char* command : {"render", "batch", "piano", "demo", "score convert"}) {
        CommandResult r = run_toonray(std::string(command) + " --help");
        ASSERT_EQ(r.exit_code, 0) << r.output;
        for (const char* opt : {"--max-triangles", "--max-vertices", "--max-image-pixels",
                                "--max-memory", "--max-input-size"})
            EXPECT_NE(r.output.find(opt), std::string::npos) << command << " " << opt;
        EXPECT_NE(r.output.find("default 50000000"), std::string::npos) << command;
        EXPECT_NE(r.output.find("default 67108864 = 8192x8192"), std::string::npos) << command;
        EXPECT_NE(r.output.find("default 2.0 GiB"), std::string::npos) << command;
    }
}

// --- Inputs that must work -----------------------------------------------------------------

namespace {

/// Renders `obj` from the catalogue at 64x48 and returns the output and the image's presence.
CommandResult render_ok(const std::string& obj, const TempDir& out, const std::string& extra = "") {
    return run_toonray(expand(kRender + obj + kTo + extra, out.path.string()));
}

}  // namespace

TEST(CatalogueWorks, CrlfAndByteOrderMark) {
    TempDir out("works_crlf");
    CommandResult r = render_ok("crlf_bom.obj", out);
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_EQ(r.output.find("warning"), std::string::npos) << r.output;
    toonray::DecodedPng png = toonray::read_png(out / "frame.png");
    // The square is red: the material from the CRLF MTL applied.
    int red = 0;
    for (int y = 0; y < png.height; ++y)
        for (int x = 0; x < png.width; ++x) {
            auto p = png.rgb(x, y);
            if (p[0] > 100 && p[1] < 50 && p[2] < 50) ++red;
        }
    EXPECT_GT(red, 100);
}

TEST(CatalogueWorks, ZeroAreaAndDegenerateTrianglesRender) {
    TempDir out("works_degenerate");
    for (const char* edges : {"robust", "classic"}) {
        CommandResult r = render_ok("degenerate.obj", out, std::string(" --edges ") + edges);
        ASSERT_EQ(r.exit_code, 0) << r.output;
        EXPECT_TRUE(toonray::is_valid_png(out / "frame.png"));
    }
}

TEST(CatalogueWorks, NonFiniteCoordinatesAreWarnings) {
    // As other readers take them: the vertex's faces are dropped, the rest renders.
    for (const char* name : {"nan.obj", "inf.obj", "huge.obj"}) {
        TempDir out("works_nonfinite");
        CommandResult r = render_ok(name, out);
        ASSERT_EQ(r.exit_code, 0) << r.output;
        EXPECT_NE(r.output.find(std::string("toonray: warning: ") + TOONRAY_ROBUSTNESS_DATA + "/" +
                                name + ":4: non-finite coordinate in 'v'"),
                  std::string::npos)
            << r.output;
        EXPECT_TRUE(toonray::is_valid_png(out / "frame.png"));
    }
}

TEST(CatalogueWorks, MissingMaterialLibraryIsAWarning) {
    TempDir out("works_missing_mtl");
    CommandResult r = render_ok("missing_mtllib.obj", out);
    ASSERT_EQ(r.exit_code, 0) << r.output;
    const std::string data = TOONRAY_ROBUSTNESS_DATA;
    EXPECT_NE(
        r.output.find(
            "toonray: warning: " + data + "/missing_mtllib.obj:1: cannot read material library '" +
            data + "/does_not_exist.mtl' (" + data +
            "/does_not_exist.mtl: cannot open: No such file or directory); faces using its "
            "materials get the default material"),
        std::string::npos)
        << r.output;
    EXPECT_TRUE(toonray::is_valid_png(out / "frame.png"));
}

TEST(CatalogueWorks, RecursiveMaterialLibrariesAreReadOnce) {
    TempDir out("works_recursive_mtl");
    CommandResult r = render_ok("recursive_mtllib.obj", out);
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_EQ(r.output.find("unknown material 'blue'"), std::string::npos) << r.output;
    EXPECT_TRUE(toonray::is_valid_png(out / "frame.png"));
}

TEST(CatalogueWorks, MaterialLibraryThatIsADeviceOrDirectoryIsAWarningNotAHang) {
    TempDir out("works_special_mtl");
    CommandResult r = render_ok("mtllib_special.obj", out);
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_NE(r.output.find("/dev/zero: not a regular file"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find(": is a directory, not a file"), std::string::npos) << r.output;
    EXPECT_TRUE(toonray::is_valid_png(out / "frame.png"));
}

TEST(CatalogueWorks, TexturesThatAreMissingOrNotImagesDoNotBreakLoading) {
    for (const char* obj : {"texture_missing.obj", "texture_not_image.obj"}) {
        TempDir out(std::string("works_") + obj);
        CommandResult r = render_ok(obj, out);
        ASSERT_EQ(r.exit_code, 0) << obj << "\n" << r.output;
        EXPECT_TRUE(toonray::is_valid_png(out / "frame.png")) << obj;
    }
}

TEST(CatalogueWorks, OverlappingNotesAreCutShortWithAWarning) {
    TempDir out("works_overlap");
    CommandResult r = run_toonray(
        expand("score convert {data}/overlapping.notes {out}/out.mid", out.path.string()));
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_NE(r.output.find("overlapping.notes: 1 note(s) overlapped a later note of the same key"),
              std::string::npos)
        << r.output;
    EXPECT_TRUE(std::filesystem::exists(out / "out.mid"));
}
