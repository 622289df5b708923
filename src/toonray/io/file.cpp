#include "toonray/io/file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <algorithm>
#include <cstring>
#include <fmt/format.h>

#include "toonray/core/error.h"

namespace toonray {

std::string read_file(const std::filesystem::path& path, std::uint64_t max_bytes) {
    // O_NONBLOCK: opening a FIFO must not wait for a writer; a FIFO is refused below anyway.
    const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0)
        throw Error(fmt::format("{}: cannot open: {}", path.string(), std::strerror(errno)));
    struct Closer {
        int fd;
        ~Closer() { ::close(fd); }
    } closer{fd};
    struct stat st {};
    if (::fstat(fd, &st) != 0)
        throw Error(fmt::format("{}: cannot read: {}", path.string(), std::strerror(errno)));
    if (S_ISDIR(st.st_mode))
        throw Error(fmt::format("{}: is a directory, not a file", path.string()));
    if (!S_ISREG(st.st_mode))
        throw Error(
            fmt::format("{}: not a regular file (a device, FIFO or socket); toonray reads "
                        "inputs from regular files only",
                        path.string()));
    const auto size = static_cast<std::uint64_t>(st.st_size);
    auto too_large = [&](std::uint64_t bytes) {
        return LimitError(Limit::InputBytes,
                          fmt::format("{}: {}, more than the input size limit of {}", path.string(),
                                      bytes == 0 ? "larger" : fmt::format("{} bytes", bytes),
                                      format_bytes(max_bytes)));
    };
    if (size > max_bytes) throw too_large(size);
    auto read_some = [&](char* buffer, std::size_t count) -> std::size_t {
        while (true) {
            ssize_t n = ::read(fd, buffer, count);
            if (n >= 0) return static_cast<std::size_t>(n);
            if (errno != EINTR)
                throw Error(fmt::format("{}: read error: {}", path.string(), std::strerror(errno)));
        }
    };
    std::string data(static_cast<std::size_t>(size), '\0');
    std::size_t have = 0;
    while (have < data.size()) {
        std::size_t n = read_some(data.data() + have, data.size() - have);
        if (n == 0) {  // shorter than fstat said
            data.resize(have);
            return data;
        }
        have += n;
    }
    // Files in /proc report size 0, and a file may grow while it is read: read on to the end,
    // but never past the limit.
    char buffer[1 << 16];
    while (std::size_t n = read_some(buffer, sizeof buffer)) {
        if (data.size() + n > max_bytes) throw too_large(0);
        data.append(buffer, n);
    }
    return data;
}

void write_file_atomic(const std::filesystem::path& path, std::span<const std::uint8_t> bytes) {
    std::filesystem::path dir = path.parent_path().empty() ? "." : path.parent_path();
    std::string tmpl = (dir / ("." + path.filename().string() + ".tmp.XXXXXX")).string();
    int fd = ::mkstemp(tmpl.data());
    if (fd < 0)
        throw Error(fmt::format("{}: cannot create file: {}", path.string(), std::strerror(errno)));
    auto fail = [&](const char* what) {
        int err = errno;
        ::close(fd);
        ::unlink(tmpl.c_str());
        throw Error(fmt::format("{}: {}: {}", path.string(), what, std::strerror(err)));
    };
    const std::uint8_t* p = bytes.data();
    std::size_t left = bytes.size();
    while (left > 0) {
        ssize_t w = ::write(fd, p, left);
        if (w < 0) {
            if (errno == EINTR) continue;
            fail("write failed");
        }
        p += w;
        left -= static_cast<std::size_t>(w);
    }
    // mkstemp creates 0600; output images should be as readable as any other file.
    mode_t mask = ::umask(0);
    ::umask(mask);
    ::fchmod(fd, 0666 & ~mask);
    if (::close(fd) != 0) {
        int err = errno;
        ::unlink(tmpl.c_str());
        throw Error(fmt::format("{}: write failed: {}", path.string(), std::strerror(err)));
    }
    if (::rename(tmpl.c_str(), path.c_str()) != 0) {
        int err = errno;
        ::unlink(tmpl.c_str());
        throw Error(
            fmt::format("{}: cannot rename into place: {}", path.string(), std::strerror(err)));
    }
}

}  // namespace toonray
