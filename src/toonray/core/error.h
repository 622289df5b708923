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

/// Builds "file:line: message" (or "file: message" when line is 0).
std::string located(std::string_view file, std::size_t line, std::string_view message);

/// Throws Error("file:line: message").
[[noreturn]] void throw_at(std::string_view file, std::size_t line, std::string_view message);

/// Non-fatal problems (a missing MTL file, an unknown material) collected by a loader so the
/// caller decides where they go.
using Warnings = std::vector<std::string>;

}  // namespace toonray
