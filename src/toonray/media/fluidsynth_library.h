#pragma once
/// FluidSynth, loaded when a soundtrack is first synthesised rather than linked. Linked, it and
/// the fifty-odd libraries it needs (SDL2, X11, Wayland, PulseAudio, JACK...) load into every
/// toonray process, which took 4.4 ms of each one's start (200 starts of an empty program
/// linked with toonray's libraries: 6.6 ms with FluidSynth, 2.3 ms without), though only the
/// soundtrack uses them; a single frame takes a few tens of milliseconds.

#include <fluidsynth.h>

namespace toonray {

/// The FluidSynth functions toonray calls, with their own names and types.
struct FluidSynthLibrary {
#define TOONRAY_FLUIDSYNTH_FUNCTIONS(X) \
    X(new_fluid_settings)               \
    X(delete_fluid_settings)            \
    X(fluid_settings_setnum)            \
    X(fluid_settings_setint)            \
    X(new_fluid_synth)                  \
    X(delete_fluid_synth)               \
    X(fluid_synth_sfload)               \
    X(fluid_synth_get_sfont_by_id)      \
    X(fluid_synth_program_select)       \
    X(fluid_synth_noteon)               \
    X(fluid_synth_noteoff)              \
    X(fluid_synth_cc)                   \
    X(fluid_synth_write_float)          \
    X(fluid_sfont_get_preset)           \
    X(fluid_sfont_iteration_start)      \
    X(fluid_sfont_iteration_next)       \
    X(fluid_preset_get_name)            \
    X(fluid_preset_get_banknum)         \
    X(fluid_preset_get_num)             \
    X(fluid_set_log_function)
#define TOONRAY_FLUIDSYNTH_MEMBER(name) decltype(&::name) name = nullptr;
    TOONRAY_FLUIDSYNTH_FUNCTIONS(TOONRAY_FLUIDSYNTH_MEMBER)
#undef TOONRAY_FLUIDSYNTH_MEMBER
};

/// FluidSynth's functions, loaded on the first call (thread-safe). Throws Error naming the
/// library and why it could not be loaded (the Debian package is libfluidsynth3).
const FluidSynthLibrary& fluidsynth();

}  // namespace toonray
