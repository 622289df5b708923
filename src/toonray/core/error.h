#pragma once
/// Errors carry where they come from. Loaders throw; the CLI catches once and prints.

#include <cstddef>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace toonray {

/// An error the user can act on. The message already names the file and line when there is one,
/// in the form "file:line: what was wrong".
class Error : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

/// The limits of core/limits.h that an input can exceed. Each front end has its own way to raise
/// one (the CLI's --max-* options), so the library names the limit and the front end adds how.
enum class Limit {
    InputBytes,
    LineBytes,
    Vertices,
    Triangles,
    ImagePixels,
    Memory,
    Frames,
    CameraKeys,
    Notes
};

/// An input asked for more than a limit allows. The message says what and by how much, never
/// how to raise the limit: that is the front end's to say (see Limit).
class LimitError : public Error {
public:
    LimitError(Limit limit, const std::string& message) : Error(message), limit_(limit) {}
    [[nodiscard]] Limit limit() const { return limit_; }

private:
    Limit limit_;
};

/// Builds "file:line: message" (or "file: message" when line is 0).
std::string located(std::string_view file, std::size_t line, std::string_view message);

/// Throws Error("file:line: message").
[[noreturn]] void throw_at(std::string_view file, std::size_t line, std::string_view message);

/// Non-fatal problems (a missing MTL file, an unknown material) collected by a loader so the
/// caller decides where they go.
using Warnings = std::vector<std::string>;

}  // namespace toonray
