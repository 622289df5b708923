#pragma once
// Runs the built toonray binary for end-to-end tests.

#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "support/test_support.h"
#include "toonray/io/png.h"

struct CommandResult {
    int exit_code = -1;
    std::string output;  ///< stdout and stderr together
};

/// Runs `toonray ARGS` through the shell (arguments are test-controlled) and captures output.
inline CommandResult run_toonray(const std::string& args) {
    std::string cmd = std::string(TOONRAY_CLI) + " " + args + " 2>&1";
    CommandResult r;
    FILE* pipe = ::popen(cmd.c_str(), "r");
    if (!pipe) return r;
    std::array<char, 4096> buf;
    std::size_t n;
    while ((n = std::fread(buf.data(), 1, buf.size(), pipe)) > 0) r.output.append(buf.data(), n);
    int status = ::pclose(pipe);
    r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    return r;
}

using toonray::test_support::TempDir;

/// The pixels of a PNG file, decoded, as bytes: frames compare by picture, since every PNG
/// also records the settings that made it.
inline std::string png_pixels(const std::filesystem::path& path) {
    const toonray::DecodedPng png = toonray::read_png(path);
    return std::string(reinterpret_cast<const char*>(png.rgb.data()), png.rgb.size() * 3);
}
