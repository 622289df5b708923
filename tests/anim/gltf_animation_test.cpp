#include "toonray/scene/gltf_animation.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include "scene/gltf_test_files.h"
#include "toonray/frame/frame_renderer.h"
#include "toonray/io/png.h"
#include "support/test_scenes.h"
#include "support/test_support.h"

namespace toonray {
namespace {

const std::string kSamples = std::string(TOONRAY_TEST_DATA_DIR) + "/gltf/";

GltfDocument sample(const std::string& name) {
    Warnings warnings;
    return load_gltf(kSamples + name + ".gltf", warnings);
}

// The bounds of the triangles of object `name`.
BBox object_bounds(const Scene& scene, const std::string& name) {
    BBox box;
    for (std::size_t t = 0; t < scene.triangle_count(); ++t)
        if (scene.objects[scene.tri_object[t]] == name)
            for (std::uint32_t v : scene.tri_positions[t]) box.extend(scene.positions[v]);
    return box;
}

Scene pose(const GltfAnimator& animator, double seconds, std::vector<Light>* lights = nullptr) {
    Scene scene;
    std::vector<Light> unused;
    animator.pose(seconds, 200, 100, scene, lights ? *lights : unused);
    return scene;
}

// A document of one triangle at node 0 (named "tri"), to animate by hand.
GltfDocument one_triangle() {
    GltfDocument doc;
    doc.file = "hand.gltf";
    GltfNode node;
    node.name = "tri";
    node.mesh = 0;
    doc.nodes.push_back(node);
    doc.roots = {0};
    GltfPrimitive prim;
    prim.positions = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    prim.indices = {0, 1, 2};
    doc.meshes.push_back({"m", {prim}, {}});
    return doc;
}

GltfSampler sampler(std::vector<float> times, std::vector<float> values, int width,
                    GltfInterpolation interpolation) {
    GltfSampler s;
    s.times = std::move(times);
    s.values = std::move(values);
    s.width = width;
    s.interpolation = interpolation;
    return s;
}

void expect_near(const Vec3f& a, const Vec3f& b, float tolerance = 1e-5f) {
    EXPECT_NEAR(a.x, b.x, tolerance);
    EXPECT_NEAR(a.y, b.y, tolerance);
    EXPECT_NEAR(a.z, b.z, tolerance);
}

TEST(GltfAnimation, BoxAnimatedMovesByItsKeys) {
    const GltfAnimator animator(sample("BoxAnimated"), {});
    const Scene start = pose(animator, 0.0);
    // Node 0 is translated from y = 0 to 2.52 over 1.25 s (LINEAR); node 2, its grandchild,
    // holds the inner box.
    const Scene middle = pose(animator, 0.625);
    const Scene top = pose(animator, 1.25);
    const float y0 = object_bounds(start, "inner_box").lo.y;
    EXPECT_NEAR(object_bounds(middle, "inner_box").lo.y - y0, 1.26f, 1e-4f);
    EXPECT_NEAR(object_bounds(top, "inner_box").lo.y - y0, 2.52f, 1e-4f);
    // The outer box (node 3) is not animated.
    EXPECT_EQ(object_bounds(start, "outer_box").lo, object_bounds(top, "outer_box").lo);
    // From 1.25 s to 2.5 s node 2 turns 180 degrees about x (slerp): at 1.875 s it is a quarter
    // turn, which swaps the box's y and z extents.
    const BBox turned = object_bounds(pose(animator, 1.875), "inner_box");
    const BBox still = object_bounds(top, "inner_box");
    EXPECT_NEAR(turned.hi.z - turned.lo.z, still.hi.y - still.lo.y, 1e-3f);
}

TEST(GltfAnimation, InterpolationModes) {
    GltfDocument doc = one_triangle();
    GltfAnimation anim;
    // Rotation: identity to half a turn about z, LINEAR (slerp).
    anim.samplers.push_back(
        sampler({0, 1}, {0, 0, 0, 1, 0, 0, 1, 0}, 4, GltfInterpolation::Linear));
    // Translation in x: STEP from 0 to 5 at t = 1.
    anim.samplers.push_back(sampler({0, 1}, {0, 0, 0, 5, 0, 0}, 3, GltfInterpolation::Step));
    // Scale: CUBICSPLINE from 1 to 2 with an out-tangent of 3 at the first key.
    anim.samplers.push_back(sampler({0, 1}, {0, 0, 0, 1, 1, 1, 3, 3, 3, 0, 0, 0, 2, 2, 2, 0, 0, 0},
                                    3, GltfInterpolation::CubicSpline));
    anim.channels = {
        {0, GltfPath::Rotation, 0}, {0, GltfPath::Translation, 1}, {0, GltfPath::Scale, 2}};
    anim.duration = 1;
    doc.animations.push_back(anim);
    const GltfAnimator animator(std::move(doc), {});
    // At 0.5 s: a quarter turn ((1,0,0) -> (0,1,0)), no translation yet, and scale
    // h00 * 1 + h10 * 3 + h01 * 2 = 0.5 + 0.375 + 1 = 1.875.
    const Scene half = pose(animator, 0.5);
    expect_near(half.positions[0], {0, 1.875f, 0});
    expect_near(half.positions[2], {0, 0, 1.875f});
    const Scene end = pose(animator, 1.0);
    expect_near(end.positions[0], {5 - 2, 0, 0});  // half a turn, scale 2, moved by 5
    const Scene after = pose(animator, 7.0);       // clamped to the last key
    expect_near(after.positions[0], end.positions[0]);
    const Scene before = pose(animator, 0.999);
    EXPECT_LT(before.positions[1].x, 0.01f);  // STEP: not moved until t = 1
}

TEST(GltfAnimation, SkinnedMeshBends) {
    const GltfDocument doc = sample("SimpleSkin");
    const GltfPrimitive& prim = doc.meshes[0].primitives[0];
    const GltfAnimator animator(sample("SimpleSkin"), {});
    const Scene rest = pose(animator, 0.0);
    const Scene bent = pose(animator, 1.0);  // joint 1 turned a quarter about z
    ASSERT_EQ(rest.positions.size(), prim.positions.size());
    int fixed = 0, moved = 0;
    for (std::size_t v = 0; v < prim.positions.size(); ++v) {
        const float shift = length(bent.positions[v] - rest.positions[v]);
        if (prim.weights[v][0] == 1.0f && prim.joints[v][0] == 0) {
            EXPECT_LT(shift, 1e-5f) << v;  // bound to the root joint only
            ++fixed;
        } else if (shift > 0.1f) {
            ++moved;
        }
    }
    EXPECT_GT(fixed, 0);
    EXPECT_GT(moved, 2);
    // The top row leans: its x moves, the bottom row's does not.
    EXPECT_GT(std::abs(bent.bounds().lo.x - rest.bounds().lo.x), 0.2f);

    const GltfAnimator rigged(sample("RiggedSimple"), {});
    const BBox a = pose(rigged, 0.0).bounds(), b = pose(rigged, 1.0).bounds();
    EXPECT_GT(length(a.hi - b.hi) + length(a.lo - b.lo), 0.5f);
}

TEST(GltfAnimation, MorphWeightsMoveVertices) {
    const GltfDocument doc = sample("SimpleMorph");
    const GltfPrimitive& prim = doc.meshes[0].primitives[0];
    const GltfSampler& weights = doc.animations[0].samplers[0];
    ASSERT_EQ(weights.width, 2);
    const GltfAnimator animator(sample("SimpleMorph"), {});
    for (std::size_t k = 0; k < weights.times.size(); ++k) {
        const Scene scene = pose(animator, weights.times[k]);
        const float w0 = weights.values[2 * k], w1 = weights.values[2 * k + 1];
        for (std::size_t v = 0; v < prim.positions.size(); ++v)
            expect_near(scene.positions[v], prim.positions[v] + prim.targets[0].positions[v] * w0 +
                                                prim.targets[1].positions[v] * w1);
    }
    // The silhouette changes: the key with the largest weights against the rest.
    EXPECT_NE(pose(animator, weights.times.front()).bounds().hi,
              pose(animator, weights.times[1]).bounds().hi);
}

// Without animated weights, a node's own weights apply, else its mesh's.
TEST(GltfAnimation, NodeWeightsReplaceTheMeshsUnlessAbsent) {
    GltfDocument doc = sample("SimpleMorph");
    doc.animations.clear();
    const GltfPrimitive prim = doc.meshes[0].primitives[0];
    const std::vector<float> mesh_weights = doc.meshes[0].weights;
    ASSERT_EQ(mesh_weights.size(), 2u);
    for (const std::vector<float>& node_weights : {std::vector<float>{}, {1.0f, 0.25f}}) {
        doc.nodes[0].weights = node_weights;
        const std::vector<float>& w = node_weights.empty() ? mesh_weights : node_weights;
        const Scene scene = pose(GltfAnimator(doc, {}), 0.0);
        for (std::size_t v = 0; v < prim.positions.size(); ++v)
            expect_near(scene.positions[v], prim.positions[v] +
                                                prim.targets[0].positions[v] * w[0] +
                                                prim.targets[1].positions[v] * w[1]);
    }
}

TEST(GltfAnimation, CameraKeepsTheVerticalFieldOfView) {
    GltfDocument doc = one_triangle();
    GltfNode camera;
    camera.name = "cam";
    camera.camera = 0;
    camera.translation = {0, 0, 5};
    doc.nodes.push_back(camera);
    doc.roots.push_back(1);
    doc.cameras.push_back({"lens", 0.5f, 1.5f});
    const GltfAnimator animator(std::move(doc), {});
    const Scene scene = pose(animator, 0.0);  // 200x100
    ASSERT_TRUE(scene.camera.has_value());
    expect_near(scene.camera->eye, {0, 0, 5});
    expect_near(scene.camera->up, {0, 1, 0});
    // Horizontal fov = 2 atan(1 / |gaze - eye|) = 2 atan(tan(yfov / 2) * 200 / 100).
    const float distance = 1.0f / (std::tan(0.25f) * 2.0f);
    expect_near(scene.camera->gaze, {0, 0, 5 - distance});
    ASSERT_TRUE(animator.aspect_warning(200, 100).has_value());
    EXPECT_FALSE(animator.aspect_warning(150, 100).has_value());
}

TEST(GltfAnimation, ChoosesAnimationAndCameraByName) {
    GltfDocument doc = one_triangle();
    doc.animations.push_back({"walk", {}, {}, 0.0f});
    GltfPoseOptions options;
    options.animation = "run";
    EXPECT_EQ(test_support::error_of([&] { GltfAnimator(doc, options); }),
              "hand.gltf: no animation 'run' (it has 0 'walk')");
    options.animation = "0";
    EXPECT_NO_THROW(GltfAnimator(doc, options));
    options = {};
    options.camera_node = "side";
    EXPECT_EQ(test_support::error_of([&] { GltfAnimator(doc, options); }),
              "hand.gltf: no camera node 'side' (the scene has no camera)");
}

TEST(GltfAnimation, LightsBecomeToonLights) {
    GltfDocument doc = one_triangle();
    doc.lights = {{"lamp", GltfLight::Kind::Spot, Vec3f(1.0f), 40.0f},
                  {"sun", GltfLight::Kind::Directional, Vec3f(1.0f), 20.0f}};
    GltfNode lamp;
    lamp.light = 0;
    lamp.translation = {1, 2, 3};
    GltfNode sun;
    sun.light = 1;
    sun.rotation = {std::sin(0.25f * 3.14159265f), 0, 0,
                    std::cos(0.25f * 3.14159265f)};  // 90 deg about x
    doc.nodes.push_back(lamp);
    doc.nodes.push_back(sun);
    doc.roots = {0, 1, 2};
    const GltfAnimator animator(std::move(doc), {});
    std::vector<Light> lights;
    pose(animator, 0.0, &lights);
    ASSERT_EQ(lights.size(), 2u);
    EXPECT_EQ(lights[0].kind, Light::Kind::Point);
    expect_near(lights[0].vector, {1, 2, 3});
    EXPECT_FLOAT_EQ(lights[0].intensity, 1.0f);
    EXPECT_EQ(lights[1].kind, Light::Kind::Directional);
    expect_near(lights[1].vector, {0, 1, 0});  // -z turned a quarter about x
    EXPECT_FLOAT_EQ(lights[1].intensity, 0.5f);
    // A scene source lights the frame with them, unless the settings give lights.
    GltfDocument again = animator.document();
    SceneFrame frame;
    Warnings warnings;
    GltfSource(again, {}, 24.0, SceneSetup{}).load(0, frame, warnings);
    EXPECT_EQ(frame.lights, lights);
    SceneSetup given;
    given.lights = {Light{}};
    GltfSource(again, {}, 24.0, given).load(0, frame, warnings);
    EXPECT_EQ(frame.lights, given.lights);
}

TEST(GltfAnimation, MovingNodesRefitTheBvh) {
    const GltfAnimator animator(sample("BoxAnimated"), {});
    test_support::TempDir dir("gltf_refit");
    FrameOptions options;
    options.settings.width = 64;
    options.settings.height = 48;
    FrameRenderer renderer;
    Warnings warnings;
    Scene scene;
    std::vector<Light> lights;
    for (int frame = 0; frame < 3; ++frame) {
        animator.pose(gltf_frame_time(frame, 24.0), 64, 48, scene, lights);
        renderer.render(
            test_support::scene_frame(scene, options.settings.width, options.settings.height),
            dir / ("f" + std::to_string(frame) + ".png"), options, warnings);
        EXPECT_EQ(renderer.accel().refitted(), frame > 0) << frame;
    }
    EXPECT_DOUBLE_EQ(gltf_frame_time(1, 24.0), 1.0 / 24.0);
}

}  // namespace
}  // namespace toonray

namespace toonray {
namespace {

// A quad facing +z, seen by a glTF camera, textured red over blue (glTF texture coordinates
// start at the image's top left).
std::string textured_quad(const std::string& image) {
    std::vector<std::uint8_t> bin;
    gltf_test::put<float>(bin, {-1, 1, 0, 1, 1, 0, 1, -1, 0, -1, -1, 0});  // 48 bytes
    gltf_test::put<float>(bin, {0, 0, 1, 0, 1, 1, 0, 1});                  // 32 at 48
    gltf_test::put<std::uint16_t>(bin, {0, 2, 1, 0, 3, 2});                // 12 at 80
    return R"({"asset": {"version": "2.0"}, "scenes": [{"nodes": [0, 1]}],
  "nodes": [{"mesh": 0, "name": "quad"}, {"camera": 0, "translation": [0, 0, 3]}],
  "cameras": [{"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.1}}],
  "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 1}, "indices": 2,
                              "material": 0}]}],
  "materials": [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}],
  "textures": [{"source": 0}], "images": [{"uri": ")" +
           image + R"("}],
  "accessors": [{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3"},
                {"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC2"},
                {"bufferView": 2, "componentType": 5123, "count": 6, "type": "SCALAR"}],
  "bufferViews": [{"buffer": 0, "byteLength": 48}, {"buffer": 0, "byteOffset": 48, "byteLength": 32},
                  {"buffer": 0, "byteOffset": 80, "byteLength": 12}],
  "buffers": [{"byteLength": 92, "uri": ")" +
           gltf_test::data_uri(bin) + R"("}]})";
}

TEST(GltfAnimation, TexturesAreRightWayUp) {
    test_support::TempDir dir("gltf_texture");
    // An external PNG, an external JPEG, and the PNG embedded as a data URI.
    std::ifstream png_file(kSamples + "red_over_blue.png", std::ios::binary);
    const std::string png_bytes((std::istreambuf_iterator<char>(png_file)), {});
    const std::string embedded =
        "data:image/png;base64," +
        gltf_test::base64(std::vector<std::uint8_t>(png_bytes.begin(), png_bytes.end()));
    for (const std::string& image :
         {std::string("red_over_blue.png"), std::string("red_over_blue.jpg"), embedded}) {
        const std::string label = image.substr(0, 40);
        if (image.rfind("data:", 0) != 0) std::filesystem::copy_file(kSamples + image, dir / image);
        Warnings warnings;
        const GltfAnimator animator(
            load_gltf(dir.write("quad.gltf", textured_quad(image)), warnings), {});
        EXPECT_TRUE(warnings.empty()) << warnings.front();
        Scene scene;
        std::vector<Light> lights;
        animator.pose(0.0, 64, 64, scene, lights);
        ASSERT_TRUE(scene.materials[1].kd_image) << label;
        FrameOptions options;
        options.settings.width = options.settings.height = 64;
        FrameRenderer renderer;
        renderer.render(
            test_support::scene_frame(scene, options.settings.width, options.settings.height),
            dir / "quad.png", options, warnings);
        const DecodedPng png = read_png(dir / "quad.png");
        const Rgb8 top = png.rgb(32, 24), bottom = png.rgb(32, 40);
        EXPECT_GT(top[0], top[2] + 60) << label;
        EXPECT_GT(bottom[2], bottom[0] + 60) << label;
    }
}

TEST(GltfAnimation, VertexColoursMultiplyTheMaterial) {
    // A quad facing +z: red corners at the top, blue at the bottom, on a material of Kd 0.5.
    GltfDocument doc;
    doc.file = "colours.gltf";
    GltfNode quad;
    quad.mesh = 0;
    GltfNode camera;
    camera.camera = 0;
    camera.translation = {0, 0, 3};
    doc.nodes = {quad, camera};
    doc.roots = {0, 1};
    doc.cameras.push_back({"cam", 0.8f, 0.0f});
    GltfPrimitive prim;
    prim.positions = {{-1, 1, 0}, {1, 1, 0}, {1, -1, 0}, {-1, -1, 0}};
    prim.colours = {{1, 0, 0}, {1, 0, 0}, {0, 0, 1}, {0, 0, 1}};
    prim.indices = {0, 2, 1, 0, 3, 2};
    prim.material = 1;
    doc.meshes.push_back({"quad", {prim}, {}});
    Material half("half");
    half.kd = Vec3f(0.5f);
    doc.materials.push_back(half);
    const GltfAnimator animator(std::move(doc), {});
    Scene scene;
    std::vector<Light> lights;
    animator.pose(0.0, 64, 64, scene, lights);
    ASSERT_EQ(scene.colours.size(), scene.positions.size());
    FrameOptions options;
    options.settings.width = options.settings.height = 64;
    test_support::TempDir dir("gltf_colours");
    FrameRenderer renderer;
    Warnings warnings;
    renderer.render(
        test_support::scene_frame(scene, options.settings.width, options.settings.height),
        dir / "quad.png", options, warnings);
    const DecodedPng png = read_png(dir / "quad.png");
    const Rgb8 top = png.rgb(32, 12), bottom = png.rgb(32, 52);
    EXPECT_GT(top[0], 60);  // 0.5 x red x the lit band
    EXPECT_LT(top[0], 160);
    EXPECT_EQ(top[1], 0);
    EXPECT_LT(top[2], 30);
    EXPECT_GT(bottom[2], 60);
    EXPECT_LT(bottom[0], 30);
}

}  // namespace
}  // namespace toonray
