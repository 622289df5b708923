#include "toonray/scene/scene_source.h"

#include "toonray/scene/auto_smooth.h"

namespace toonray {

CameraSpec choose_camera(const Scene& scene, const SceneSetup& setup) {
    if (setup.camera) return *setup.camera;
    if (scene.camera) return *scene.camera;
    // Frame the vertices that triangles and polylines use.
    std::vector<Vec3f> used;
    used.reserve(scene.triangle_count() * 3 + scene.polyline_points.size());
    for (const auto& tri : scene.tri_positions)
        for (std::uint32_t v : tri) used.push_back(scene.positions[v]);
    for (std::uint32_t v : scene.polyline_points) used.push_back(scene.positions[v]);
    // Instances by the corners of their world boxes: ten thousand instances of a large mesh
    // would be billions of points, and a box frames them nearly as tightly.
    if (!scene.instances.empty()) {
        std::vector<BBox> mesh_box(scene.meshes.size());
        for (std::size_t m = 0; m < scene.meshes.size(); ++m)
            mesh_box[m] = scene.meshes[m]->triangle_bounds();
        for (const Instance& instance : scene.instances) {
            const BBox b = instance.to_world.box(mesh_box[instance.mesh]);
            if (b.empty()) continue;
            for (int c = 0; c < 8; ++c)
                used.push_back({(c & 1) ? b.hi.x : b.lo.x, (c & 2) ? b.hi.y : b.lo.y,
                                (c & 4) ? b.hi.z : b.lo.z});
        }
    }
    return auto_camera(used, setup.width, setup.height);
}

std::vector<Light> choose_lights(const Scene& scene, const CameraSpec& camera,
                                 std::vector<Light> own_lights, const SceneSetup& setup) {
    if (!setup.lights.empty()) return setup.lights;
    if (!own_lights.empty()) return own_lights;
    return {default_light(scene, camera)};
}

void finish_scene(SceneFrame& frame, std::vector<Light> own_lights, const SceneSetup& setup) {
    if (setup.auto_smooth) auto_smooth_scene(frame.scene, *setup.auto_smooth);
    frame.camera = choose_camera(frame.scene, setup);
    frame.lights = choose_lights(frame.scene, frame.camera, std::move(own_lights), setup);
}

ObjFileSource::ObjFileSource(std::filesystem::path path, SceneSetup setup, ObjOptions obj)
    : path_(std::move(path)), setup_(std::move(setup)), obj_(std::move(obj)) {}

void ObjFileSource::load(int, SceneFrame& out, Warnings& warnings) const {
    load_file(path_, setup_, obj_, out, warnings);
}

void ObjFileSource::load_file(const std::filesystem::path& path, const SceneSetup& setup,
                              const ObjOptions& obj, SceneFrame& out, Warnings& warnings) {
    load_obj(path, out.scene, warnings, obj);
    // The scene's own lights file is read only when the settings give no lights.
    finish_scene(out, setup.lights.empty() ? scene_file_lights(path) : std::vector<Light>{}, setup);
}

}  // namespace toonray
