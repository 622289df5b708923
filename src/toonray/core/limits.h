#pragma once
/// Limits on the work and memory an input may ask for (docs/robustness.md).
///
/// toonray reads files downloaded from anywhere. Every reader checks these limits and, instead
/// of running out of memory or time, throws LimitError (core/error.h) saying which limit and by
/// how much; the front end says how to raise it. The limits are process-wide: the command line
/// sets them once, before any work starts (set_limits); library callers may pass their own where
/// a function takes them.

#include <cstdint>
#include <string>
#include <string_view>

namespace toonray {

inline constexpr std::uint64_t kKiB = 1024, kMiB = kKiB * 1024, kGiB = kMiB * 1024;

/// Indices are 32-bit (kNoIndex = 2^32 - 1 marks "none"): no limit can be raised past this.
inline constexpr std::uint64_t kMaxIndexable = 0xFFFFFFFEu;

struct Limits {
    /// Bytes of any one input file: OBJ, MTL, note script, MIDI, camera path, PNG (--max-input-size).
    std::uint64_t max_input_bytes = 2 * kGiB;
    /// Bytes of one line of a text input (OBJ and MTL lines with `\` continuations joined).
    std::uint64_t max_line_bytes = 16 * kMiB;
    /// OBJ `v`, `vn` and `vt` statements, each (--max-vertices).
    std::uint64_t max_vertices = 100'000'000;
    /// Triangles of one scene, after polygons are split into triangles (--max-triangles).
    std::uint64_t max_triangles = 50'000'000;
    /// Pixels of one image, width times height (--max-image-pixels): 8192 x 8192.
    std::uint64_t max_image_pixels = 8192ull * 8192;
    /// Bytes the memory estimate (frame buffers of all frames in flight plus their scenes) may
    /// reach (--max-memory). Default: three quarters of the physical memory.
    std::uint64_t max_memory = default_max_memory();
    /// Frames of one batch or movie.
    std::uint64_t max_frames = 10'000'000;
    /// Keys of one camera path.
    std::uint64_t max_camera_keys = 100'000;
    /// Notes of one note script (a MIDI file is bounded by MidiLimits::max_events).
    std::uint64_t max_notes = 10'000'000;

    /// Set by a caller that keeps several frames in flight (batch, piano): bytes already
    /// committed to frame buffers, and how many scenes are loaded at once. The OBJ loader counts
    /// them in its estimate.
    std::uint64_t reserved_memory = 0;
    std::uint32_t scenes_in_flight = 1;

    /// 3/4 of the physical memory (sysconf), or 8 GiB when that is unknown.
    static std::uint64_t default_max_memory();
};

/// The process-wide limits (defaults until set_limits is called).
[[nodiscard]] const Limits& limits();
/// Replaces the process-wide limits. Call before starting threads that read inputs.
void set_limits(const Limits& limits);

// --- Memory -----------------------------------------------------------------------------------
// Each module estimates the memory of its own buffers (render: frame_buffer_bytes; scene:
// scene_bytes), deliberately generously: the buffers a frame keeps plus the temporaries of
// building it, so that a frame within the estimate does not run out of memory.

/// Throws LimitError(Limit::Memory, "WHAT needs about X of memory, more than the limit of Y")
/// when `bytes` exceeds limits().max_memory. How to need less memory (fewer frames at once) or
/// raise the limit is the front end's to say.
void check_memory(std::uint64_t bytes, std::string_view what);

/// "1.5 GiB", "512 MiB", "1234 bytes".
[[nodiscard]] std::string format_bytes(std::uint64_t bytes);

/// Parses a count for a limit: "50000000", "50M", "2G" (k, M, G = 10^3, 10^6, 10^9). Throws
/// Error quoting `text` when malformed or zero.
[[nodiscard]] std::uint64_t parse_count(std::string_view text);
/// Parses a size in bytes: "4096", "64K", "512M", "8G", "1T" (powers of 1024; a trailing "B"
/// or "iB" is accepted). Throws Error quoting `text` when malformed or zero.
[[nodiscard]] std::uint64_t parse_bytes(std::string_view text);

}  // namespace toonray
