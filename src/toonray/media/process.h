#pragma once
/// Running external tools (ffmpeg, ffprobe) as child processes: an argv array handed to
/// posix_spawn, never a shell command line, so file names with spaces, quotes or `$` are safe.

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace toonray {

struct ProcessResult {
    int exit_code = -1;  ///< the exit status, or -1 when the process was killed by a signal
    int signal = 0;      ///< the signal that killed it, 0 when it exited
    std::string out;     ///< everything it wrote to stdout
    std::string err;     ///< what it wrote to stderr (the last 1 MB when it wrote more)

    [[nodiscard]] bool ok() const { return exit_code == 0; }
};

/// Finds a program as execvp would: a name with a '/' is taken as a path, any other name is
/// searched in the directories of $PATH. Returns an empty path when there is no executable
/// regular file of that name.
std::filesystem::path find_program(std::string_view name);

/// Runs `argv` (argv[0] looked up with find_program) to completion with stdin from /dev/null
/// and stdout/stderr captured. Throws Error when argv is empty or the program is missing or
/// cannot be started; a non-zero exit is not an error here, it is reported in the result.
ProcessResult run_process(const std::vector<std::string>& argv);

/// The last `max_lines` non-empty lines of `text`, for quoting a tool's stderr in an Error.
std::string tail_lines(std::string_view text, int max_lines = 12);

}  // namespace toonray
