#include "toonray/media/process.h"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <fmt/format.h>

#include "toonray/core/error.h"

extern char** environ;

namespace toonray {

namespace {

bool is_executable_file(const std::filesystem::path& path) {
    struct stat st {};
    return ::stat(path.c_str(), &st) == 0 && S_ISREG(st.st_mode) &&
           ::access(path.c_str(), X_OK) == 0;
}

/// Closes a file descriptor once.
class Fd {
public:
    Fd() = default;
    explicit Fd(int fd) : fd_(fd) {}
    ~Fd() { reset(); }
    Fd(const Fd&) = delete;
    Fd& operator=(const Fd&) = delete;
    int get() const { return fd_; }
    void reset() {
        if (fd_ >= 0) ::close(fd_);
        fd_ = -1;
    }

private:
    int fd_ = -1;
};

/// Keeps stderr bounded: a tool stuck in a warning loop must not fill memory.
constexpr std::size_t kMaxCapture = 1 << 20;

}  // namespace

std::filesystem::path find_program(std::string_view name) {
    if (name.empty()) return {};
    if (name.find('/') != std::string_view::npos) {
        std::filesystem::path p(name);
        return is_executable_file(p) ? p : std::filesystem::path();
    }
    const char* env = std::getenv("PATH");
    // POSIX leaves an unset PATH implementation-defined; glibc's execvp uses this default.
    std::string_view path = env ? env : "/bin:/usr/bin";
    while (true) {
        std::size_t colon = path.find(':');
        std::string_view dir = path.substr(0, colon);
        // An empty PATH entry means the current directory.
        std::filesystem::path candidate = std::filesystem::path(dir.empty() ? "." : dir) / name;
        if (is_executable_file(candidate)) return candidate;
        if (colon == std::string_view::npos) break;
        path.remove_prefix(colon + 1);
    }
    return {};
}

ProcessResult run_process(const std::vector<std::string>& argv) {
    if (argv.empty()) throw Error("run_process: empty argument list");
    const std::filesystem::path program = find_program(argv[0]);
    if (program.empty()) throw Error(fmt::format("{}: program not found on PATH", argv[0]));

    int out_pipe[2], err_pipe[2];
    // O_CLOEXEC: another thread spawning at the same moment must not inherit our pipe ends,
    // or we would never see end-of-file on them.
    if (::pipe2(out_pipe, O_CLOEXEC) != 0)
        throw Error(fmt::format("{}: cannot create a pipe: {}", argv[0], std::strerror(errno)));
    Fd out_r(out_pipe[0]), out_w(out_pipe[1]);
    if (::pipe2(err_pipe, O_CLOEXEC) != 0)
        throw Error(fmt::format("{}: cannot create a pipe: {}", argv[0], std::strerror(errno)));
    Fd err_r(err_pipe[0]), err_w(err_pipe[1]);

    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, 0, "/dev/null", O_RDONLY, 0);
    posix_spawn_file_actions_adddup2(&actions, out_w.get(), 1);
    posix_spawn_file_actions_adddup2(&actions, err_w.get(), 2);

    // The child starts with no blocked signals and SIGPIPE at its default, whatever this
    // process (or the thread calling us) has set.
    posix_spawnattr_t attr;
    posix_spawnattr_init(&attr);
    sigset_t empty, defaults;
    sigemptyset(&empty);
    sigemptyset(&defaults);
    sigaddset(&defaults, SIGPIPE);
    posix_spawnattr_setsigmask(&attr, &empty);
    posix_spawnattr_setsigdefault(&attr, &defaults);
    posix_spawnattr_setflags(&attr, POSIX_SPAWN_SETSIGMASK | POSIX_SPAWN_SETSIGDEF);

    std::vector<char*> args;
    args.reserve(argv.size() + 1);
    for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
    args.push_back(nullptr);

    pid_t pid = 0;
    const int rc = ::posix_spawn(&pid, program.c_str(), &actions, &attr, args.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    posix_spawnattr_destroy(&attr);
    if (rc != 0)
        throw Error(fmt::format("{}: cannot start: {}", program.string(), std::strerror(rc)));
    out_w.reset();
    err_w.reset();

    ProcessResult result;
    pollfd fds[2] = {{out_r.get(), POLLIN, 0}, {err_r.get(), POLLIN, 0}};
    std::string* sinks[2] = {&result.out, &result.err};
    int open_fds = 2;
    char buffer[1 << 15];
    while (open_fds > 0) {
        if (::poll(fds, 2, -1) < 0) {
            if (errno == EINTR) continue;
            break;  // cannot happen with valid fds; reap the child below regardless
        }
        for (int i = 0; i < 2; ++i) {
            if (fds[i].fd < 0 || fds[i].revents == 0) continue;
            ssize_t n = ::read(fds[i].fd, buffer, sizeof buffer);
            if (n < 0 && errno == EINTR) continue;
            if (n <= 0) {
                fds[i].fd = -1;  // poll ignores negative fds
                --open_fds;
                continue;
            }
            std::string& sink = *sinks[i];
            sink.append(buffer, static_cast<std::size_t>(n));
            if (i == 1 && sink.size() > 2 * kMaxCapture) sink.erase(0, sink.size() - kMaxCapture);
        }
    }

    int status = 0;
    while (::waitpid(pid, &status, 0) < 0) {
        if (errno != EINTR)
            throw Error(fmt::format("{}: waitpid failed: {}", argv[0], std::strerror(errno)));
    }
    if (WIFEXITED(status)) {
        result.exit_code = WEXITSTATUS(status);
    } else if (WIFSIGNALED(status)) {
        result.signal = WTERMSIG(status);
    }
    return result;
}

std::string tail_lines(std::string_view text, int max_lines) {
    std::vector<std::string_view> lines;
    while (!text.empty()) {
        std::size_t nl = text.find('\n');
        std::string_view line = text.substr(0, nl);
        while (!line.empty() && (line.back() == '\r' || line.back() == ' ')) line.remove_suffix(1);
        if (!line.empty()) lines.push_back(line);
        if (nl == std::string_view::npos) break;
        text.remove_prefix(nl + 1);
    }
    std::string out;
    std::size_t from =
        lines.size() > static_cast<std::size_t>(max_lines) ? lines.size() - max_lines : 0;
    for (std::size_t i = from; i < lines.size(); ++i) {
        if (!out.empty()) out += '\n';
        out += lines[i];
    }
    return out;
}

}  // namespace toonray
