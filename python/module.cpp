// The Python module `toonray` (docs/python.md): the library's scenes, settings document and
// renderer for Python and numpy, and so for Blender (blender/toonray_blender).

#include <fmt/format.h>

#include "binding.h"
#include "toonray/core/error.h"
#include "toonray/render/renderer.h"

namespace toonray::python {

std::string_view limit_setting(Limit limit) {
    switch (limit) {
        case Limit::Triangles: return "limits.triangles";
        case Limit::Vertices: return "limits.vertices";
        case Limit::ImagePixels: return "limits.image_pixels";
        case Limit::Memory: return "limits.memory";
        case Limit::InputBytes: return "limits.input_size";
        default: return {};
    }
}

}  // namespace toonray::python

PYBIND11_MODULE(toonray, m) {
    namespace py = pybind11;
    using namespace toonray::python;
    m.doc() =
        "toonray: a toon ray tracer. Scenes from files or numpy arrays in, cel-shaded and "
        "outlined frames with their layers, strokes and SVG out (docs/python.md).";
    m.attr("__version__") = std::string(toonray::toonray_version());

    // Errors: the library's message, as the command line prints it after "toonray: error: ".
    static py::exception<toonray::Error> error(m, "Error");
    static py::exception<toonray::LimitError> limit_error(m, "LimitError", error.ptr());
    static py::exception<toonray::RenderCancelled> cancelled(m, "Cancelled");
    py::register_exception_translator([](std::exception_ptr p) {
        try {
            if (p) std::rethrow_exception(p);
        } catch (const toonray::RenderCancelled& e) {
            cancelled(e.what());
        } catch (const toonray::LimitError& e) {
            // Where the command line names the option that raises the limit, the module names
            // the settings key.
            const std::string_view key = limit_setting(e.limit());
            const std::string message =
                key.empty() ? e.what() : fmt::format("{} ({} raises it)", e.what(), key);
            PyObject* type = limit_error.ptr();
            py::object value = py::reinterpret_borrow<py::object>(type)(message);
            value.attr("setting") = key.empty() ? py::object(py::none()) : py::str(key);
            PyErr_SetObject(type, value.ptr());
        } catch (const toonray::Error& e) {
            error(e.what());
        }
    });

    bind_settings(m);
    bind_scene(m);
    bind_render(m);
}
