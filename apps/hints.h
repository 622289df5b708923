#pragma once
/// What the command line adds to the library's errors: the option that raises a limit, the flag
/// whose value was bad, the option that chooses another SoundFont. The library says what went
/// wrong in its own terms; only the command line knows its flags.

#include <CLI/CLI.hpp>
#include <filesystem>
#include <string>
#include <string_view>

#include "toonray/anim/batch.h"
#include "toonray/core/error.h"

namespace toonray::cli {

/// `message` followed by how `command` lets the user get past `limit`: "... (--max-triangles
/// raises it)", "... (--max-memory raises it, or render fewer frames at once with --jobs)".
/// Only options `command` has are named, and none the message names already.
std::string with_limit_hint(const std::string& message, Limit limit, const CLI::App& command);

/// How the command line raises `limit` ("--max-memory raises it"); empty for limits it has no
/// option for.
std::string_view raise_hint(Limit limit);

/// After a run: for each limit that failed frames of `report` exceeded, a line saying how
/// `command` raises it.
void print_frame_limit_hints(const BatchReport& report, const CLI::App& command);

/// Whether `message` starts with `flag` as a whole word ("--light 'x'" names --light, not --lights).
bool starts_with_flag(std::string_view message, std::string_view flag);

/// Runs `parse`, a library parser of the value given to `flag`, and puts the flag in front of an
/// Error it throws ("--ramp: ramp '0.2@x': malformed number 'x'"), unless the message starts
/// with the flag already.
template <class Parse>
auto with_flag(std::string_view flag, Parse&& parse) -> decltype(parse()) {
    try {
        return parse();
    } catch (const LimitError& e) {
        if (starts_with_flag(e.what(), flag)) throw;
        throw LimitError(e.limit(), std::string(flag) + ": " + e.what());
    } catch (const Error& e) {
        if (starts_with_flag(e.what(), flag)) throw;
        throw Error(std::string(flag) + ": " + e.what());
    }
}

/// `message` with "; --soundfont chooses another" when it names `soundfont` (empty: the
/// default), which does not exist, and does not name --soundfont already.
std::string soundfont_hint(const std::string& message, const std::filesystem::path& soundfont);

/// Runs `synthesise`, which plays a score on `soundfont` (empty: the default); when it fails
/// because that file does not exist, the error says that --soundfont chooses another.
template <class Synthesise>
auto with_soundfont_hint(const std::filesystem::path& soundfont, Synthesise&& synthesise)
    -> decltype(synthesise()) {
    try {
        return synthesise();
    } catch (const Error& e) {
        std::string message = soundfont_hint(e.what(), soundfont);
        if (message == e.what()) throw;
        throw Error(message);
    }
}

}  // namespace toonray::cli
