// Reading OBJ text in chunks read ahead by other threads and merged (parse_obj_in_chunks)
// gives what reading it line by line on one thread gives: the scene, the warnings, the error
// and its line, the limits and the pace of the memory estimate.

#include <gtest/gtest.h>

#include <cstring>
#include <fmt/format.h>
#include <random>
#include <string>
#include <vector>

#include "toonray/core/error.h"
#include "toonray/scene/obj_fast_path.h"
#include "toonray/scene/obj_loader.h"
#include "support/same_bits.h"

using namespace toonray;

namespace {

struct Read {
    Scene scene;
    Warnings warnings;
    std::string error;
};

Read read(const std::string& text, const ObjOptions& options, std::size_t chunk_bytes,
          int threads) {
    Read out;
    try {
        wavefront::parse_obj_in_chunks(text, "chunks.obj", out.scene, out.warnings, options,
                                       chunk_bytes, threads);
    } catch (const Error& e) {
        out.error = e.what();
    }
    return out;
}

using test_support::same_bits;
// Read on one thread, then in chunks of several sizes with several threads: all the same.
// Returns the one-thread reading.
Read expect_chunks_read_the_same(const std::string& text, const ObjOptions& options = {}) {
    Read serial = read(text, options, text.size(), 1);
    for (const std::size_t chunk_bytes : {std::size_t{1}, std::size_t{100}, std::size_t{4096}})
        for (const int threads : {0, 2, 4}) {
            const Read chunked = read(text, options, chunk_bytes, threads);
            const std::string how =
                fmt::format("chunks of {} bytes, {} threads", chunk_bytes, threads);
            EXPECT_EQ(serial.error, chunked.error) << how;
            EXPECT_EQ(serial.warnings, chunked.warnings) << how;
            if (!serial.error.empty()) continue;
            const Scene &a = serial.scene, &b = chunked.scene;
            EXPECT_TRUE(same_bits(a.positions, b.positions)) << how;
            EXPECT_TRUE(same_bits(a.normals, b.normals)) << how;
            EXPECT_TRUE(same_bits(a.texcoords, b.texcoords)) << how;
            EXPECT_TRUE(same_bits(a.tri_positions, b.tri_positions)) << how;
            EXPECT_TRUE(same_bits(a.tri_normals, b.tri_normals)) << how;
            EXPECT_TRUE(same_bits(a.tri_texcoords, b.tri_texcoords)) << how;
            EXPECT_TRUE(same_bits(a.tri_material, b.tri_material)) << how;
            EXPECT_TRUE(same_bits(a.tri_object, b.tri_object)) << how;
            EXPECT_TRUE(same_bits(a.polyline_points, b.polyline_points)) << how;
            EXPECT_EQ(a.objects, b.objects) << how;
            EXPECT_EQ(a.camera.has_value(), b.camera.has_value()) << how;
        }
    return serial;
}

// Lines of every kind the reader knows, and some it does not, at random.
std::string mixed_text(unsigned seed, int lines) {
    std::mt19937 rng(seed);
    std::string text = "# mixed\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvn 0 0 1\n";
    int v = 3, vt = 1, vn = 1;
    auto index = [&](int count) {
        const int i = 1 + static_cast<int>(rng() % static_cast<unsigned>(count));
        // Relative indices in some texts (reading ahead stops at them).
        return seed > 3 && rng() % 10 == 0 ? fmt::format("{}", i - count - 1)
                                           : fmt::format("{}", i);
    };
    for (int i = 0; i < lines; ++i) {
        switch (rng() % 17) {
            case 0:
            case 1:
            case 2:
                text += fmt::format("v {} {:.4f} {}e-2\n", rng() % 100, (rng() % 1000) / 7.0,
                                    rng() % 50);
                ++v;
                break;
            case 3: text += "vn 0 0.6 -0.8\n", ++vn; break;
            case 4: text += fmt::format("vt 0.{} 1\n", rng() % 1000), ++vt; break;
            case 5:
            case 6:
            case 7: text += fmt::format("f {} {} {}\n", index(v), index(v), index(v)); break;
            case 8:
                text += fmt::format("f {0}/{1}/{2} {3}/{1}/{2} {4}//{2} {0}/{1}\n", index(v),
                                    index(vt), index(vn), index(v), index(v));
                break;
            case 9: text += fmt::format("o part{}\nusemtl m{}\n", rng() % 5, rng() % 3); break;
            case 10: text += rng() % 2 ? "# a comment\n" : "\n"; break;
            case 11: text += "s 1\r\n"; break;
            case 15:  // a comment is never continued; a '#' after a vertical tab is no comment
                text += "\t# comment \\\n\v# joined \\\nv 9 9 9\n";
                break;
            case 12: text += fmt::format("l {} {}\n", index(v), index(v)); break;
            case 13: text += "v 1 2 \\\n 3\n", ++v; break;  // continued
            case 14:  // non-finite values, in some texts: their faces are dropped
                text += seed % 2 ? "v 1e300 0 0\nv nan 1 1\n" : "v 1 1 1\nv 2 2 2\n";
                v += 2;
                break;
            default: text += fmt::format("f {} {} {} {}\n", index(v), index(v), index(v), index(v));
        }
    }
    return text;
}

}  // namespace

TEST(ObjChunks, MixedLinesReadAsOnOneThread) {
    for (unsigned seed = 1; seed <= 6; ++seed) {
        const Read r = expect_chunks_read_the_same(mixed_text(seed, 600));
        EXPECT_TRUE(r.error.empty()) << r.error;
    }
}

TEST(ObjChunks, ErrorsAndWarningsInsideAChunkAreTheSame) {
    std::string text = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
    for (int i = 0; i < 300; ++i) text += "v 0 0 0\nvt 0 0\nf 1/1 2/1 3/1\n";  // 29 bytes
    // A texture index past the vt lines (a warning), then a vertex index past the v lines, in
    // the middle of the text: after line 453.
    std::string warned = text;
    warned.insert(24 + 150 * 29, "f 1/999 2/1 3/1\n");
    const Read w = expect_chunks_read_the_same(warned);
    ASSERT_FALSE(w.warnings.empty());
    EXPECT_NE(w.warnings[0].find("face texture index 999 out of range"), std::string::npos);
    std::string failed = text;
    failed.insert(24 + 150 * 29, "f 1 2 5000\n");
    EXPECT_NE(expect_chunks_read_the_same(failed).error.find(
                  "chunks.obj:454: face vertex index 5000 out of range"),
              std::string::npos);
}

TEST(ObjChunks, CountLimitsFailAtTheSameLine) {
    std::string text;
    for (int i = 0; i < 500; ++i) text += "v 0 0 0\nvn 0 0 1\nf 1 1 1\n";
    ObjOptions options;
    options.limits.max_vertices = 321;
    EXPECT_EQ(expect_chunks_read_the_same(text, options).error,
              "chunks.obj:964: more than 321 vertices ('v') (the limit)");
    options = {};
    options.limits.max_triangles = 123;
    EXPECT_EQ(expect_chunks_read_the_same(text, options).error,
              "chunks.obj:372: more than 123 triangles (the limit)");
}

TEST(ObjChunks, TheMemoryEstimateKeepsItsPace) {
    // The estimate is checked each time the element count doubles past 65,536: the chunks
    // must keep that pace, so that the same line fails with the same figures. Triangles and
    // quads (whose two triangles count together).
    for (const char* face : {"f 1 2 3\n", "f 1 2 3 4\n"}) {
        std::string text;
        for (int i = 0; i < 40'000; ++i) text += "v 0 0 0\n";
        for (int i = 0; i < 90'000; ++i) text += face;
        for (const std::uint64_t mib : {4, 8, 16, 64}) {
            ObjOptions options;
            options.limits.max_memory = mib * kMiB;
            const Read r = expect_chunks_read_the_same(text, options);
            // Needed: about 22 MB with triangles, 41 MB with quads.
            EXPECT_EQ(r.error.find("needs about") != std::string::npos, mib < 64)
                << mib << " MiB: " << r.error;
        }
    }
}

TEST(ObjChunks, ABinaryFileIsRefusedWhateverTheThreads) {
    // Larger than the 4 MiB from which lines (and NUL bytes) are counted on several threads.
    std::string text;
    for (int i = 0; i < 300'000; ++i) text += "v 0.5 0.25 0.125\n";
    text[text.size() - 1000] = '\0';
    const Read r = expect_chunks_read_the_same(text);
    EXPECT_EQ(r.error, "chunks.obj:299942: binary data (NUL byte): not an OBJ text file");
}
