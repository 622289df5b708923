#pragma once
// Helpers for the bad-input catalogue: running the CLI, checking that a failed run left nothing
// behind, and scratch filesystems (a tiny tmpfs for "disk full", a read-only one).

#include <sys/mount.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "cli/cli_test_util.h"

namespace robustness {

namespace fs = std::filesystem;

/// A catalogue input: tests/robustness/data/NAME.
inline fs::path data(const std::string& name) { return fs::path(TOONRAY_ROBUSTNESS_DATA) / name; }

inline std::string slurp(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

/// Every file under `dir` (recursively), as paths relative to it.
inline std::vector<std::string> files_under(const fs::path& dir) {
    std::vector<std::string> out;
    std::error_code ec;
    if (!fs::exists(dir, ec)) return out;
    // Files may come and go while a run is in progress (temporary files being renamed): no
    // call here may touch the filesystem beyond the listing itself.
    for (auto it = fs::recursive_directory_iterator(dir, ec);
         !ec && it != fs::recursive_directory_iterator(); it.increment(ec))
        if (it->is_regular_file(ec)) out.push_back(it->path().lexically_relative(dir).string());
    return out;
}

/// The lines of the CLI's output that start with "toonray: error: ".
inline std::vector<std::string> error_lines(const std::string& output) {
    std::vector<std::string> out;
    std::size_t at = 0;
    while (at < output.size()) {
        std::size_t nl = output.find('\n', at);
        std::string line = output.substr(at, nl == std::string::npos ? std::string::npos : nl - at);
        if (line.rfind("toonray: error: ", 0) == 0) out.push_back(line.substr(16));
        at = nl == std::string::npos ? output.size() : nl + 1;
    }
    return out;
}

/// A tmpfs mounted on a fresh directory (root only; `ok` is false, with `why`, where it cannot
/// be mounted). Unmounted and removed when the object goes away.
struct ScratchMount {
    fs::path path;
    bool ok = false;
    std::string why;

    ScratchMount(const std::string& name, const std::string& options, bool read_only = false) {
        path = fs::temp_directory_path() /
               ("toonray_mount_" + name + "_" + std::to_string(::getpid()));
        fs::create_directories(path);
        if (::geteuid() != 0) {
            why = "not root: cannot mount a tmpfs";
            return;
        }
        if (::mount("tmpfs", path.c_str(), "tmpfs", read_only ? MS_RDONLY : 0, options.c_str()) !=
            0) {
            why = std::string("mount -t tmpfs -o ") + options + (read_only ? ",ro" : "") +
                  " failed: " + std::strerror(errno) + " (a container without CAP_SYS_ADMIN?)";
            return;
        }
        ok = true;
    }
    ~ScratchMount() {
        if (ok) ::umount2(path.c_str(), MNT_DETACH);
        std::error_code ec;
        fs::remove_all(path, ec);
    }
};

}  // namespace robustness
