// Rendering for Python: a scene and the settings document to a frame in memory (the picture, its
// layers, strokes and SVG), with the GIL released, progress reported and cancellation.

#include <chrono>
#include <condition_variable>
#include <cstring>
#include <fmt/format.h>
#include <mutex>
#include <pybind11/stl.h>
#include <thread>

#include "binding.h"
#include "toonray/anim/frame_scheduler.h"
#include "toonray/core/error.h"
#include "toonray/core/limits.h"
#include "toonray/core/saturating.h"
#include "toonray/frame/feature_exr.h"
#include "toonray/frame/frame_renderer.h"
#include "toonray/io/png.h"
#include "toonray/scene/auto_smooth.h"
#include "toonray/scene/scene_arrays.h"
#include "toonray/scene/scene_source.h"

namespace toonray::python {
namespace {

struct StrokeData {
    std::string type;
    bool visible = true, closed = false;
    std::uint32_t object = kNoIndex;
    std::vector<ink::Point2> points;
};

/// A rendered frame, owned by Python: copies of what the renderer keeps until its next frame.
struct FrameData {
    int width = 0, height = 0;
    ImageRgb8 image;
    FeatureLayers layers;  ///< the EXR's channels; empty without layers
    Image<std::uint32_t> object, material;
    bool has_strokes = false;
    std::vector<StrokeData> strokes;
    std::optional<std::string> svg;
    FrameOptions options;  ///< what the frame was made with: for its PNG
    Warnings warnings;
};

void keep_frame(const FrameLayers& layers, const Scene& scene, const FrameOptions& options,
                FrameData& out) {
    out.width = layers.image.width();
    out.height = layers.image.height();
    out.image = layers.image;
    if (options.keep_layers) {
        gather_feature_layers(layers, out.layers);
        out.object = layers.object;
        out.material = layers.material;
    }
    if (layers.strokes) {
        out.has_strokes = true;
        const ink::InkLines& lines = *layers.strokes;
        out.strokes.reserve(lines.strokes.size());
        for (const ink::Stroke& s : lines.strokes) {
            StrokeData& d = out.strokes.emplace_back();
            d.type = ink::edge_type_name(s.type);
            d.visible = s.visible;
            d.closed = s.closed;
            if (s.segment < lines.segments.size()) {
                // An instance's strokes carry the instance's object (style_source).
                const ink::FeatureSegment& segment = lines.segments[s.segment];
                if (segment.faces[0] != kNoIndex || segment.faces[1] != kNoIndex)
                    d.object = ink::style_source(scene, segment).first;
            }
            d.points = s.points;
        }
    }
    if (options.keep_strokes) out.svg = frame_svg(layers, options);
}

template <class T>
py::array_t<T> image_array(const T* data, int width, int height, int channels = 1) {
    std::vector<py::ssize_t> shape{height, width};
    if (channels > 1) shape.push_back(channels);
    py::array_t<T> out(shape);
    const std::size_t n = static_cast<std::size_t>(width) * static_cast<std::size_t>(height) *
                          static_cast<std::size_t>(channels);
    if (n) std::memcpy(out.mutable_data(), data, n * sizeof(T));
    return out;
}

/// A renderer that keeps its BVH and buffers between frames (a refit when the triangles stay).
class PyRenderer {
public:
    std::shared_ptr<FrameData> render(PyScene& scene, int width, int height,
                                      const py::object& settings_document, bool layers, bool svg,
                                      const py::object& progress,
                                      const std::optional<PyCamera>& camera);
    void cancel() {
        std::lock_guard<std::mutex> lock(current_mutex_);
        if (current_) current_->cancel = true;
    }

private:
    FrameRenderer renderer_;
    std::mutex busy_;  ///< one frame at a time
    std::mutex current_mutex_;
    RenderProgress* current_ = nullptr;  ///< of the frame in flight
};

std::shared_ptr<FrameData> PyRenderer::render(PyScene& py_scene, int width, int height,
                                              const py::object& settings_document, bool layers,
                                              bool svg, const py::object& progress_callback,
                                              const std::optional<PyCamera>& view) {
    // Everything the command line checks before it renders, in its words: the settings, the
    // limits they give (process-wide, as the command line's), the image size and memory, the
    // scene's size.
    Settings settings = settings_from(settings_document);
    set_setting(settings, "image.size", fmt::format("{}x{}", width, height));
    set_limits(settings.applied_limits(Limits{}));
    FrameOptions options = settings.frame_options();
    options.keep_layers = layers;
    options.keep_strokes = svg;
    (void)plan_frame_jobs(options, 1, 1);
    check_scene_limits(py_scene.scene, limits());
    // Instances count into the memory estimate, as a glTF file's do when it is loaded.
    check_memory(add_saturated(limits().reserved_memory, scene_bytes(py_scene.scene)), "the scene");
    const SceneSetup setup = settings.scene_setup();
    const CameraSpec camera = view ? view->spec(width, height) : py_scene.frame_camera(setup);
    validate_camera(camera);
    const std::vector<Light> lights = choose_lights(py_scene.scene, camera, py_scene.lights, setup);
    // Auto-smoothing changes normals: it works on a copy, leaving the scene as it was given.
    std::optional<Scene> smoothed;
    if (setup.auto_smooth) {
        smoothed = py_scene.scene;
        auto_smooth(*smoothed, *setup.auto_smooth);
    }
    const Scene& scene = smoothed ? *smoothed : py_scene.scene;

    struct InFlight {
        PyScene& scene;
        explicit InFlight(PyScene& s) : scene(s) { ++scene.rendering; }
        ~InFlight() { --scene.rendering; }
    } in_flight(py_scene);
    RenderProgress progress;
    auto frame = std::make_shared<FrameData>();
    frame->options = options;
    std::exception_ptr failure;
    std::optional<py::error_already_set> python_error;
    {
        py::gil_scoped_release release;
        std::unique_lock<std::mutex> busy(busy_);
        {
            std::lock_guard<std::mutex> lock(current_mutex_);
            current_ = &progress;
        }
        std::mutex done_mutex;
        std::condition_variable done_signal;
        bool done = false;
        // The frame renders on a thread of its own, so that this one can report progress and
        // notice a cancel (the callback's False, Ctrl-C, Renderer.cancel) while it runs.
        std::thread worker([&] {
            try {
                const FrameLayers& result = renderer_.render_layers(scene, camera, lights, options,
                                                                    frame->warnings, &progress);
                keep_frame(result, *renderer_.drawn_scene(), options, *frame);
            } catch (...) {
                failure = std::current_exception();
            }
            {
                std::lock_guard<std::mutex> lock(done_mutex);
                done = true;
            }
            done_signal.notify_all();
        });
        for (;;) {
            {
                std::unique_lock<std::mutex> lock(done_mutex);
                if (done_signal.wait_for(lock, std::chrono::milliseconds(100),
                                         [&] { return done; }))
                    break;
            }
            py::gil_scoped_acquire acquire;
            if (PyErr_CheckSignals() != 0) {
                python_error.emplace();
                progress.cancel = true;
                continue;
            }
            if (progress_callback.is_none() || progress.cancel) continue;
            const std::uint32_t total = progress.buckets, finished = progress.buckets_done;
            try {
                const py::object answer =
                    progress_callback(total ? static_cast<double>(finished) / total : 0.0);
                if (answer.is(py::bool_(false))) progress.cancel = true;
            } catch (py::error_already_set& e) {
                python_error.emplace(std::move(e));
                progress.cancel = true;
            }
        }
        worker.join();
        std::lock_guard<std::mutex> lock(current_mutex_);
        current_ = nullptr;
    }
    if (python_error) throw *python_error;
    if (failure) std::rethrow_exception(failure);
    if (!progress_callback.is_none()) progress_callback(1.0);
    return frame;
}

}  // namespace

void bind_render(py::module_& m) {
    std::vector<std::string> edge_types;
    for (int i = 0; i < ink::kEdgeTypeCount; ++i)
        edge_types.emplace_back(ink::edge_type_name(static_cast<ink::EdgeType>(i)));
    m.attr("EDGE_TYPES") = edge_types;
    py::class_<StrokeData>(m, "Stroke", "A stroke of the frame's ink lines, in pixels.")
        .def_readonly("type", &StrokeData::type,
                      "silhouette, border, crease, material, intersection or polyline")
        .def_readonly("visible", &StrokeData::visible)
        .def_readonly("closed", &StrokeData::closed, "whether the last point is the first")
        .def_readonly("object", &StrokeData::object,
                      "the index of the object it was found on (NO_ID for polylines)")
        .def_property_readonly(
            "points",
            [](const StrokeData& s) {
                return image_array(reinterpret_cast<const float*>(s.points.data()), 2,
                                   static_cast<int>(s.points.size()));
            },
            "(n, 2) float32: x, y in pixels from the top left corner");

    py::class_<FrameData, std::shared_ptr<FrameData>>(m, "Frame", "A rendered frame.")
        .def_readonly("width", &FrameData::width)
        .def_readonly("height", &FrameData::height)
        .def_property_readonly(
            "image",
            [](const FrameData& f) {
                // RGB as rendered, with an opaque alpha: the background is part of the picture.
                py::array_t<std::uint8_t> out({f.height, f.width, 4});
                std::uint8_t* p = out.mutable_data();
                const Rgb8* rgb = f.image.data();
                for (std::size_t i = 0; i < f.image.size(); ++i) {
                    p[4 * i] = rgb[i][0];
                    p[4 * i + 1] = rgb[i][1];
                    p[4 * i + 2] = rgb[i][2];
                    p[4 * i + 3] = 255;
                }
                return out;
            },
            "The picture, (height, width, 4) uint8, rows from the top, alpha 255.")
        .def_property_readonly(
            "layer_names",
            [](const FrameData& f) {
                std::vector<std::string> names;
                for (const FeatureLayers::Layer& layer : f.layers.channels)
                    names.push_back(layer.name);
                return names;
            },
            "The names of the frame's layers (render(layers=True)), in the EXR's order.")
        .def(
            "layer",
            [](const FrameData& f, const std::string& name) {
                const FeatureLayers::Layer* layer = f.layers.find(name);
                if (!layer)
                    throw py::key_error(
                        fmt::format("the frame has no layer '{}' (frame.layer_names lists them; "
                                    "render(layers=True) keeps them)",
                                    name));
                return image_array(layer->values.data(), f.width, f.height);
            },
            py::arg("name"), "One layer as a (height, width) float32 array (frame.layers[name]).")
        .def_property_readonly(
            "layers",
            [](const FrameData& f) {
                py::dict out;
                for (const FeatureLayers::Layer& layer : f.layers.channels)
                    out[py::str(layer.name)] = image_array(layer.values.data(), f.width, f.height);
                return out;
            },
            "The feature layers (render(layers=True)): a dict of (height, width) float32 arrays "
            "named as the EXR's channels (docs/exr.md): R, G, B (cel colour, linear), A, Z, "
            "view_depth.Z, N.X, N.Y, N.Z, object_id.id, material_id.id, band.index, light.L, "
            "P.X, P.Y, P.Z, uv.U, uv.V, lines.all and lines.<type>.")
        .def_property_readonly(
            "object_ids",
            [](const FrameData& f) -> py::object {
                if (f.object.size() == 0) return py::none();
                return image_array(f.object.data(), f.width, f.height);
            },
            "(height, width) uint32 object index of each pixel's first sample, NO_ID where "
            "nothing is seen (render(layers=True)).")
        .def_property_readonly(
            "material_ids",
            [](const FrameData& f) -> py::object {
                if (f.material.size() == 0) return py::none();
                return image_array(f.material.data(), f.width, f.height);
            },
            "(height, width) uint32 material index, NO_ID where nothing is seen.")
        .def_property_readonly(
            "strokes",
            [](const FrameData& f) -> py::object {
                if (!f.has_strokes) return py::none();
                return py::cast(f.strokes);
            },
            "The strokes (ink mode, or render(svg=True)): a list of Stroke; else None.")
        .def_readonly("svg", &FrameData::svg,
                      "The SVG document (render(svg=True)), as `toonray render --svg` writes it.")
        .def_readonly("warnings", &FrameData::warnings)
        .def_property_readonly(
            "settings_toml", [](const FrameData& f) { return f.options.record.settings; },
            "What the frame's outputs record: the settings that can change the picture.")
        .def(
            "png",
            [](const FrameData& f) {
                const std::vector<std::uint8_t> bytes =
                    encode_png(f.image.width(), f.image.height(), 3,
                               reinterpret_cast<const std::uint8_t*>(f.image.data()),
                               frame_png_options(f.options));
                return py::bytes(reinterpret_cast<const char*>(bytes.data()), bytes.size());
            },
            "The picture as the PNG file `toonray render` writes, byte for byte.");

    py::class_<PyRenderer>(m, "Renderer",
                           "Renders frames, keeping its BVH and buffers between them: a scene "
                           "whose triangles stay the same is refitted, not rebuilt.")
        .def(py::init<>())
        .def(
            "render", &PyRenderer::render, py::arg("scene"), py::arg("width"), py::arg("height"),
            py::arg("settings") = py::none(), py::kw_only(), py::arg("layers") = true,
            py::arg("svg") = false, py::arg("progress") = py::none(),
            py::arg("camera") = py::none(),
            "Renders `scene` at width x height with the settings document (None, a dict or a "
            "TOML file's path). layers: keep the feature layers; svg: keep the strokes and "
            "the SVG in any mode; camera: a Camera for this frame (default: the settings' "
            "scene.camera, else the scene's, else one that frames the scene). progress(fraction) is called from this thread about ten "
            "times a second; returning False cancels. Raises toonray.Cancelled when cancelled "
            "(progress, Renderer.cancel, Ctrl-C: KeyboardInterrupt), toonray.Error with the "
            "command line's message for bad settings or scenes. The GIL is released while the "
            "frame renders.")
        .def("cancel", &PyRenderer::cancel,
             "Stops the frame this renderer is rendering (from another thread): its render "
             "raises toonray.Cancelled.");

    m.def(
        "render",
        [](PyScene& scene, int width, int height, const py::object& settings, bool layers, bool svg,
           const py::object& progress, const std::optional<PyCamera>& camera) {
            PyRenderer renderer;
            return renderer.render(scene, width, height, settings, layers, svg, progress, camera);
        },
        py::arg("scene"), py::arg("width"), py::arg("height"), py::arg("settings") = py::none(),
        py::kw_only(), py::arg("layers") = true, py::arg("svg") = false,
        py::arg("progress") = py::none(), py::arg("camera") = py::none(),
        "Renderer().render(...): one frame.");
}

}  // namespace toonray::python
