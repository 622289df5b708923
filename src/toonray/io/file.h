#pragma once
/// Whole-file reads and atomic writes.

#include <cstdint>
#include <filesystem>
#include <span>
#include <string>

#include "toonray/core/limits.h"

namespace toonray {

/// Reads a whole regular file of at most `max_bytes` bytes. Throws Error naming the path when
/// it cannot be opened, is not a regular file (a directory, a FIFO, a device such as /dev/zero
/// or a terminal: inputs name other files, and those must not hang or flood the reader), or is
/// larger than `max_bytes` (--max-input-size).
std::string read_file(const std::filesystem::path& path,
                      std::uint64_t max_bytes = limits().max_input_bytes);

/// Writes bytes to `path` atomically: a temporary file in the same directory, flushed, then
/// renamed over the target. A crash or a full disk never leaves a truncated `path` behind; on
/// failure the temporary is removed and Error is thrown.
void write_file_atomic(const std::filesystem::path& path, std::span<const std::uint8_t> bytes);

}  // namespace toonray
