#pragma once
/// Whole-file reads and atomic writes.

#include <cstdint>
#include <filesystem>
#include <span>
#include <string>

namespace toonray {

/// Reads a whole file. Throws Error("path: cannot open ...") when it cannot.
std::string read_file(const std::filesystem::path& path);

/// Writes bytes to `path` atomically: a temporary file in the same directory, flushed, then
/// renamed over the target. A crash or a full disk never leaves a truncated `path` behind; on
/// failure the temporary is removed and Error is thrown.
void write_file_atomic(const std::filesystem::path& path, std::span<const std::uint8_t> bytes);

}  // namespace toonray
