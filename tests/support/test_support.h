#pragma once
/// Helpers shared by the test suites: a scratch directory per test and the message of an
/// expected error.

#include <stdlib.h>  // mkdtemp

#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <string_view>

#include "toonray/core/error.h"

namespace toonray::test_support {

/// A fresh, empty directory under the system temp directory, removed with its contents when
/// the test ends. mkdtemp makes the name unique, so tests may run in parallel processes and
/// one test may hold several.
struct TempDir {
    std::filesystem::path path;

    explicit TempDir(std::string_view name = "test") {
        std::string tmpl =
            (std::filesystem::temp_directory_path() / ("toonray_" + std::string(name) + "_XXXXXX"))
                .string();
        if (!::mkdtemp(tmpl.data())) throw std::runtime_error("mkdtemp failed for " + tmpl);
        path = tmpl;
    }
    ~TempDir() {
        std::error_code ec;
        std::filesystem::remove_all(path, ec);
    }
    TempDir(const TempDir&) = delete;
    TempDir& operator=(const TempDir&) = delete;

    std::filesystem::path operator/(const std::string& name) const { return path / name; }

    /// Writes `text` to `<path>/<name>` as bytes, and returns that file's path.
    std::filesystem::path write(const std::string& name, std::string_view text) const {
        std::ofstream(path / name, std::ios::binary)
            .write(text.data(), static_cast<std::streamsize>(text.size()));
        return path / name;
    }
};

/// The message of the toonray::Error that `f` throws, or "(no error)".
template <typename F>
std::string error_of(F&& f) {
    try {
        f();
    } catch (const Error& e) {
        return e.what();
    }
    return "(no error)";
}

}  // namespace toonray::test_support
