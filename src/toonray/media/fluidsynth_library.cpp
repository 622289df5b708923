#include "toonray/media/fluidsynth_library.h"

#include <dlfcn.h>

#include <fmt/format.h>
#include <mutex>
#include <string>

#include "toonray/core/error.h"

namespace toonray {

const FluidSynthLibrary& fluidsynth() {
    static FluidSynthLibrary library;
    static std::string failure;
    static std::once_flag once;
    std::call_once(once, [] {
        // The soname the build linked against (TOONRAY_FLUIDSYNTH_SONAME, from CMake), so that
        // the functions have the types of the header compiled here. Kept loaded for the process.
        void* handle = ::dlopen(TOONRAY_FLUIDSYNTH_SONAME, RTLD_NOW | RTLD_LOCAL);
        if (!handle) {
            failure = fmt::format("sound needs FluidSynth ({}), which could not be loaded: {}",
                                  TOONRAY_FLUIDSYNTH_SONAME, ::dlerror());
            return;
        }
#define TOONRAY_FLUIDSYNTH_LOAD(name)                                                  \
    library.name = reinterpret_cast<decltype(&::name)>(::dlsym(handle, #name));        \
    if (!library.name && failure.empty())                                              \
        failure = fmt::format("sound needs FluidSynth ({}), which has no function {}", \
                              TOONRAY_FLUIDSYNTH_SONAME, #name);
        TOONRAY_FLUIDSYNTH_FUNCTIONS(TOONRAY_FLUIDSYNTH_LOAD)
#undef TOONRAY_FLUIDSYNTH_LOAD
    });
    if (!failure.empty()) throw Error(failure);
    return library;
}

}  // namespace toonray
