// Scenes for Python: loaded from OBJ and glTF files, or built from numpy arrays (meshes placed by
// instances, materials, a camera and lights).

#include <cstring>
#include <fmt/format.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include "binding.h"
#include "toonray/core/error.h"
#include "toonray/core/limits.h"
#include "toonray/core/saturating.h"
#include "toonray/scene/gltf_loader.h"
#include "toonray/scene/obj_loader.h"
#include "toonray/scene/scene_arrays.h"
#include "toonray/scene/scene_source.h"

namespace toonray::python {

CameraSpec PyCamera::spec(int width, int height) const {
    if (const auto* block = std::get_if<CameraSpec>(&camera)) {
        validate_camera(*block);
        return *block;
    }
    if (const auto* lens = std::get_if<LensCamera>(&camera))
        return lens_camera(*lens, width, height);
    const Gltf& gltf = std::get<Gltf>(camera);
    if (!posed || posed_width != width || posed_height != height) {
        // The file's camera keeps its vertical field of view; the horizontal one follows the
        // image, so it is posed for each size (as `toonray render --size` poses it).
        Scene scene;
        std::vector<Light> lights;
        gltf.animator->pose(gltf.seconds, width, height, scene, lights);
        if (!scene.camera) throw Error("the glTF camera could not be posed (degenerate matrix)");
        posed = *scene.camera;
        posed_width = width;
        posed_height = height;
    }
    return *posed;
}

void PyScene::check_not_rendering() const {
    if (rendering.load() > 0)
        throw py::value_error("the scene is being rendered: change it when the render is done");
}

CameraSpec PyScene::frame_camera(const SceneSetup& setup) const {
    if (setup.camera) return *setup.camera;
    if (camera) return camera->spec(setup.width, setup.height);
    return choose_camera(scene, setup);
}

namespace {

Vec3f vec3(const std::array<float, 3>& v) { return {v[0], v[1], v[2]}; }
std::array<float, 3> array3(const Vec3f& v) { return {v.x, v.y, v.z}; }

template <class T>
using Array = py::array_t<T, py::array::c_style | py::array::forcecast>;

// An (n, columns) array's rows (n = 0 for None).
template <class T>
Array<T> rows(const py::object& value, py::ssize_t columns, const char* what) {
    if (value.is_none()) return Array<T>(std::vector<py::ssize_t>{0, columns});
    Array<T> a = Array<T>::ensure(value);
    if (!a) throw py::type_error(fmt::format("{}: expected an array of numbers", what));
    if (a.ndim() != 2 || a.shape(1) != columns)
        throw py::value_error(
            fmt::format("{}: expected shape (n, {}), got {}", what, columns,
                        py::str(py::tuple(value.attr("shape"))).cast<std::string>()));
    return a;
}

template <class Out, class T>
std::vector<Out> copied(const Array<T>& a) {
    static_assert(sizeof(Out) == sizeof(T) * (sizeof(Out) / sizeof(T)));
    std::vector<Out> out(static_cast<std::size_t>(a.shape(0)));
    if (!out.empty())
        std::memcpy(static_cast<void*>(out.data()), a.data(), out.size() * sizeof(Out));
    return out;
}

Affine3 affine_of(const py::object& matrix) {
    if (matrix.is_none()) return {};
    const Array<double> m = Array<double>::ensure(matrix);
    if (!m || m.ndim() != 2 || m.shape(0) != 4 || m.shape(1) != 4)
        throw py::value_error("matrix: expected a 4x4 array (rows: m[row][column])");
    if (m.at(3, 0) != 0.0 || m.at(3, 1) != 0.0 || m.at(3, 2) != 0.0 || m.at(3, 3) != 1.0)
        throw Error("matrix: the last row must be 0 0 0 1 (an affine transform)");
    Affine3 a;
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 4; ++c) a.m[r][c] = m.at(r, c);
    return a;
}

std::shared_ptr<MeshData> make_mesh(PyScene& self, const py::object& positions,
                                    const py::object& triangles, const py::object& normals,
                                    const py::object& uvs, const py::object& materials,
                                    std::string name) {
    auto mesh = std::make_shared<MeshData>();
    mesh->name = std::move(name);
    mesh->scene = &self;
    mesh->positions = copied<Vec3f>(rows<float>(positions, 3, "positions"));
    mesh->triangles =
        copied<std::array<std::uint32_t, 3>>(rows<std::uint32_t>(triangles, 3, "triangles"));
    mesh->normals = copied<Vec3f>(rows<float>(normals, 3, "normals"));
    mesh->uvs = copied<Vec2f>(rows<float>(uvs, 2, "uvs"));
    if (!materials.is_none()) {
        const Array<std::uint32_t> ids = Array<std::uint32_t>::ensure(materials);
        if (!ids || ids.ndim() != 1)
            throw py::value_error("materials: expected one material index per triangle");
        mesh->materials = copied<std::uint32_t>(ids);
    }
    check_mesh(
        MeshArrays{mesh->positions, mesh->triangles, mesh->normals, mesh->uvs, mesh->materials},
        self.scene.materials.size(), mesh->name);
    return mesh;
}

MeshArrays arrays_of(const MeshData& mesh) {
    return MeshArrays{mesh.positions, mesh.triangles, mesh.normals, mesh.uvs, mesh.materials};
}

// An instance of `mesh`: the mesh is stored in the scene once, at its first instance.
std::uint32_t add_instance(PyScene& self, MeshData& mesh, const py::object& matrix,
                           const std::optional<std::string>& name) {
    self.check_not_rendering();
    if (mesh.scene != &self)
        throw py::value_error("add_instance: the mesh belongs to another scene");
    const Affine3 to_world = affine_of(matrix);
    if (mesh.scene_mesh == kNoIndex)
        mesh.scene_mesh = self.scene.add_mesh(
            instance_mesh(arrays_of(mesh), self.scene.materials.size(), mesh.name));
    const std::uint32_t instance =
        self.scene.add_instance(mesh.scene_mesh, to_world, name ? *name : mesh.name);
    return self.scene.instances[instance].object;
}

SensorFit sensor_fit(const std::string& text) {
    if (text == "AUTO") return SensorFit::Auto;
    if (text == "HORIZONTAL") return SensorFit::Horizontal;
    if (text == "VERTICAL") return SensorFit::Vertical;
    throw Error(fmt::format("sensor_fit '{}': expected AUTO, HORIZONTAL or VERTICAL", text));
}

py::dict spec_dict(const CameraSpec& c) {
    py::dict d;
    d["eye"] = array3(c.eye);
    d["gaze"] = array3(c.gaze);
    d["up"] = array3(c.up);
    d["shift"] = std::array<float, 2>{c.shift.x, c.shift.y};
    return d;
}

template <class T>
py::array_t<T> array_of(const void* data, std::vector<py::ssize_t> shape) {
    py::array_t<T> out(shape);
    std::size_t n = 1;
    for (py::ssize_t s : shape) n *= static_cast<std::size_t>(s);
    if (n) std::memcpy(out.mutable_data(), data, n * sizeof(T));
    return out;
}

std::shared_ptr<PyScene> load_scene(const std::filesystem::path& path,
                                    const std::optional<double>& time,
                                    const std::optional<int>& frame, double fps,
                                    const std::optional<std::string>& animation,
                                    const std::optional<std::string>& camera_node) {
    auto out = std::make_shared<PyScene>();
    Warnings warnings;
    if (is_gltf_path(path)) {
        if (time && frame) throw Error("time and frame: give one of them");
        GltfDocument document = load_gltf(path, warnings);
        check_memory(add_saturated(limits().reserved_memory,
                                   scene_bytes(document.vertices, document.triangles)),
                     path.string());
        GltfPoseOptions pose;
        pose.animation = animation;
        pose.camera_node = camera_node;
        auto animator = std::make_shared<const GltfAnimator>(std::move(document), pose);
        const double seconds = time ? *time : (frame ? gltf_frame_time(*frame, fps) : 0.0);
        const SceneSetup defaults;
        animator->pose(seconds, defaults.width, defaults.height, out->scene, out->lights);
        out->scene.camera.reset();
        if (animator->has_camera()) out->camera = PyCamera{PyCamera::Gltf{animator, seconds}};
    } else {
        if (time || frame || animation || camera_node)
            throw Error("animation, camera_node, time and frame need a glTF scene");
        load_obj(path, out->scene, warnings);
        out->lights = scene_file_lights(path);
    }
    out->warnings = std::move(warnings);
    return out;
}

}  // namespace

void bind_scene(py::module_& m) {
    m.attr("NO_ID") = kNoIndex;

    py::class_<Material>(m, "Material", "A material: the MTL fields toonray uses.")
        .def(
            py::init([](std::string name, std::array<float, 3> kd, std::array<float, 3> ka,
                        std::array<float, 3> ks, float ns, float d, int illum, std::string map_kd) {
                Material mat(std::move(name));
                mat.kd = vec3(kd);
                mat.ka = vec3(ka);
                mat.ks = vec3(ks);
                mat.ns = ns;
                mat.d = d;
                mat.illum = illum;
                mat.map_kd = std::move(map_kd);
                return mat;
            }),
            py::arg("name") = "", py::arg("kd") = std::array<float, 3>{0.8f, 0.8f, 0.8f},
            py::arg("ka") = std::array<float, 3>{0, 0, 0},
            py::arg("ks") = std::array<float, 3>{0, 0, 0}, py::arg("ns") = 0.0f,
            py::arg("d") = 1.0f, py::arg("illum") = 2, py::arg("map_kd") = "")
        .def_readwrite("name", &Material::name)
        .def_property(
            "kd", [](const Material& mat) { return array3(mat.kd); },
            [](Material& mat, std::array<float, 3> v) { mat.kd = vec3(v); },
            "Diffuse colour (the cel colour before the band's level)")
        .def_property(
            "ka", [](const Material& mat) { return array3(mat.ka); },
            [](Material& mat, std::array<float, 3> v) { mat.ka = vec3(v); })
        .def_property(
            "ks", [](const Material& mat) { return array3(mat.ks); },
            [](Material& mat, std::array<float, 3> v) { mat.ks = vec3(v); },
            "Specular colour (the highlight band, shading.specular)")
        .def_readwrite("ns", &Material::ns, "Specular exponent")
        .def_readwrite("d", &Material::d)
        .def_readwrite("illum", &Material::illum)
        .def_readwrite("map_kd", &Material::map_kd,
                       "A PNG texture multiplying kd (shading.textures), as a path")
        .def("__repr__", [](const Material& mat) {
            return fmt::format("toonray.Material('{}', kd=({}, {}, {}))", mat.name, mat.kd.x,
                               mat.kd.y, mat.kd.z);
        });

    py::class_<Light>(m, "Light",
                      "A toon light: a point light at a position or a directional light "
                      "shining along a vector, with an intensity (1 gives n.l itself).")
        .def(py::init([](const std::string& text) { return parse_light(text); }), py::arg("text"),
             "Parses the command line's --light text: 'x,y,z', 'point:x,y,z' or 'dir:x,y,z', "
             "each with an optional '@intensity'.")
        .def_static(
            "point",
            [](std::array<float, 3> position, float intensity) {
                return Light{Light::Kind::Point, vec3(position), intensity};
            },
            py::arg("position"), py::arg("intensity") = 1.0f)
        .def_static(
            "directional",
            [](std::array<float, 3> direction, float intensity) {
                return Light{Light::Kind::Directional, vec3(direction), intensity};
            },
            py::arg("direction"), py::arg("intensity") = 1.0f)
        .def_property_readonly(
            "kind",
            [](const Light& l) { return l.kind == Light::Kind::Point ? "point" : "directional"; })
        .def_property_readonly("vector", [](const Light& l) { return array3(l.vector); })
        .def_readonly("intensity", &Light::intensity)
        .def("__eq__", [](const Light& a, const Light& b) { return a == b; })
        .def("__str__", &format_light)
        .def("__repr__", [](const Light& l) { return "toonray.Light('" + format_light(l) + "')"; });

    py::class_<PyCamera>(m, "Camera",
                         "A camera: eye, target and up with a vertical field of view or a lens "
                         "and sensor (Blender's rule), or the seed's camera block (Camera.block).")
        .def(py::init([](std::array<float, 3> eye, std::array<float, 3> target,
                         std::array<float, 3> up, std::optional<float> fov, float lens,
                         float sensor_width, float sensor_height, const std::string& fit,
                         std::array<float, 2> shift, float pixel_aspect) {
                 LensCamera c;
                 c.eye = vec3(eye);
                 c.target = vec3(target);
                 c.up = vec3(up);
                 c.vertical_fov = fov;
                 c.focal_length = lens;
                 c.sensor_width = sensor_width;
                 c.sensor_height = sensor_height;
                 c.fit = sensor_fit(fit);
                 c.shift = {shift[0], shift[1]};
                 c.pixel_aspect = pixel_aspect;
                 return PyCamera{c};
             }),
             py::arg("eye"), py::arg("target"), py::arg("up") = std::array<float, 3>{0, 1, 0},
             py::arg("fov") = py::none(), py::arg("lens") = 50.0f, py::arg("sensor_width") = 36.0f,
             py::arg("sensor_height") = 24.0f, py::arg("sensor_fit") = "AUTO",
             py::arg("shift") = std::array<float, 2>{0, 0}, py::arg("pixel_aspect") = 1.0f)
        .def_static(
            "block",
            [](std::array<float, 3> eye, std::array<float, 3> gaze, std::array<float, 3> up,
               std::array<float, 2> shift) {
                CameraSpec c{vec3(eye), vec3(gaze), vec3(up), {shift[0], shift[1]}};
                validate_camera(c);
                return PyCamera{c};
            },
            py::arg("eye"), py::arg("gaze"), py::arg("up"),
            py::arg("shift") = std::array<float, 2>{0, 0},
            "The seed's camera (the OBJ camera block, --camera): the horizontal field of view "
            "is 2 atan(1 / |gaze - eye|).")
        .def(
            "spec",
            [](const PyCamera& c, int width, int height) {
                return spec_dict(c.spec(width, height));
            },
            py::arg("width"), py::arg("height"),
            "The camera block for an image of this size: a dict of eye, gaze, up and shift.")
        .def("__repr__", [](const PyCamera& c) {
            if (std::holds_alternative<CameraSpec>(c.camera))
                return std::string("toonray.Camera.block(...)");
            if (std::holds_alternative<LensCamera>(c.camera))
                return std::string("toonray.Camera(...)");
            return std::string("toonray.Camera(<glTF camera>)");
        });

    py::class_<MeshData, std::shared_ptr<MeshData>>(
        m, "Mesh", "A mesh of a scene, placed in it by instances (Scene.add_instance).")
        .def_readonly("name", &MeshData::name)
        .def_property_readonly("triangle_count",
                               [](const MeshData& mesh) { return mesh.triangles.size(); })
        .def_property_readonly("vertex_count",
                               [](const MeshData& mesh) { return mesh.positions.size(); });

    py::class_<PyScene, std::shared_ptr<PyScene>>(m, "Scene",
                                                  "Triangles, materials, a camera and lights.")
        .def(py::init([] { return std::make_shared<PyScene>(); }))
        .def(
            "add_material",
            [](PyScene& self, const Material& material) {
                self.check_not_rendering();
                self.scene.materials.push_back(material);
                return self.scene.materials.size() - 1;
            },
            py::arg("material"),
            "Adds a material; returns its index (0 is the default material, Kd 0.8).")
        .def_property_readonly("materials",
                               [](const PyScene& self) { return self.scene.materials; })
        .def(
            "add_mesh",
            [](PyScene& self, const py::object& positions, const py::object& triangles,
               const py::object& normals, const py::object& uvs, const py::object& materials,
               std::string name) {
                return make_mesh(self, positions, triangles, normals, uvs, materials,
                                 std::move(name));
            },
            py::arg("positions"), py::arg("triangles"), py::arg("normals") = py::none(),
            py::arg("uvs") = py::none(), py::arg("materials") = py::none(),
            py::arg("name") = "mesh",
            "A mesh to place with add_instance: positions (n, 3), triangles (t, 3) of position "
            "indices, optional normals (n, 3) or (3t, 3) per corner, uvs (n, 2) or (3t, 2), "
            "and materials (t,) of material indices.")
        .def(
            "add_instance",
            [](PyScene& self, MeshData& mesh, const py::object& matrix,
               const std::optional<std::string>& name) {
                return add_instance(self, mesh, matrix, name);
            },
            py::arg("mesh"), py::arg("matrix") = py::none(), py::arg("name") = py::none(),
            "Places `mesh` with a 4x4 matrix (mesh to world; None: identity) as an object named "
            "`name` (default: the mesh's); returns the object's index. The mesh is stored once "
            "however often it is placed: an instance is a transform and a name.")
        .def(
            "add_object",
            [](PyScene& self, const py::object& positions, const py::object& triangles,
               const py::object& normals, const py::object& uvs, const py::object& materials,
               std::string name, const py::object& matrix) {
                self.check_not_rendering();
                const auto mesh =
                    make_mesh(self, positions, triangles, normals, uvs, materials, name);
                return append_mesh(self.scene, arrays_of(*mesh), affine_of(matrix), mesh->name);
            },
            py::arg("positions"), py::arg("triangles"), py::arg("normals") = py::none(),
            py::arg("uvs") = py::none(), py::arg("materials") = py::none(),
            py::arg("name") = "object", py::arg("matrix") = py::none(),
            "A mesh placed once, as the scene's own triangles (moved by `matrix`; the "
            "`positions` and `triangles` arrays hold them); returns the object's index.")
        .def_property(
            "camera",
            [](const PyScene& self) -> std::optional<PyCamera> {
                if (self.camera) return self.camera;
                if (self.scene.camera) return PyCamera{*self.scene.camera};
                return std::nullopt;
            },
            [](PyScene& self, const std::optional<PyCamera>& camera) {
                self.check_not_rendering();
                self.camera = camera;
                self.scene.camera.reset();
            },
            "The scene's camera (None: the settings' scene.camera, else one that frames the "
            "scene).")
        .def_property(
            "lights", [](const PyScene& self) { return self.lights; },
            [](PyScene& self, std::vector<Light> lights) {
                self.check_not_rendering();
                self.lights = std::move(lights);
            },
            "The scene's own lights (the settings' scene.lights replace them; none: the "
            "default light).")
        .def_property_readonly("objects", [](const PyScene& self) { return self.scene.objects; })
        .def_readonly("warnings", &PyScene::warnings,
                      "What loading reported without failing (a missing MTL file, ...)")
        .def_property_readonly(
            "triangle_count", [](const PyScene& self) { return self.scene.triangle_count(); },
            "The scene's own triangles (loaded files' and add_object's), which the arrays "
            "below hold; instances' are in instanced_triangle_count.")
        .def_property_readonly("vertex_count",
                               [](const PyScene& self) { return self.scene.positions.size(); })
        .def_property_readonly(
            "instance_count", [](const PyScene& self) { return self.scene.instances.size(); },
            "How many instances add_instance (or a glTF file) placed.")
        .def_property_readonly(
            "instanced_triangle_count",
            [](const PyScene& self) { return self.scene.instanced_triangle_count(); },
            "The instances' triangles, each counted once per instance (triangle_count and the "
            "arrays are the scene's own).")
        .def_property_readonly(
            "positions",
            [](const PyScene& self) {
                return array_of<float>(self.scene.positions.data(),
                                       {static_cast<py::ssize_t>(self.scene.positions.size()), 3});
            },
            "A copy of the vertex positions (n, 3), in the world.")
        .def_property_readonly(
            "triangles",
            [](const PyScene& self) {
                return array_of<std::uint32_t>(
                    self.scene.tri_positions.data(),
                    {static_cast<py::ssize_t>(self.scene.triangle_count()), 3});
            },
            "A copy of the triangles' position indices (t, 3).")
        .def_property_readonly("triangle_objects",
                               [](const PyScene& self) {
                                   return array_of<std::uint32_t>(
                                       self.scene.tri_object.data(),
                                       {static_cast<py::ssize_t>(self.scene.triangle_count())});
                               })
        .def_property_readonly("triangle_materials", [](const PyScene& self) {
            return array_of<std::uint32_t>(self.scene.tri_material.data(),
                                           {static_cast<py::ssize_t>(self.scene.triangle_count())});
        });

    m.def(
        "load",
        [](const std::filesystem::path& path, std::optional<double> time, std::optional<int> frame,
           double fps, std::optional<std::string> animation,
           std::optional<std::string> camera_node) {
            py::gil_scoped_release release;
            return load_scene(path, time, frame, fps, animation, camera_node);
        },
        py::arg("path"), py::kw_only(), py::arg("time") = py::none(), py::arg("frame") = py::none(),
        py::arg("fps") = 24.0, py::arg("animation") = py::none(),
        py::arg("camera_node") = py::none(),
        "Loads an OBJ file (its MTL files, camera block and lights file) or a glTF/GLB file "
        "posed at `time` seconds (or `frame` at `fps`), with its camera and lights.");
}

}  // namespace toonray::python
