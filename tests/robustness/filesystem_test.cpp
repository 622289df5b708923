// Where the output goes wrong: an output directory that cannot be written, a full disk, and
// SIGTERM in the middle of a run. Each fails with a clear error (or exit code 130 when
// stopped), and leaves no partial or temporary file behind.

#include <gtest/gtest.h>

#include <signal.h>
#include <spawn.h>
#include <sys/stat.h>
#include <sys/wait.h>

#include <chrono>
#include <fmt/format.h>
#include <optional>
#include <thread>

#include "robustness_util.h"
#include "toonray/io/png.h"

extern char** environ;

using namespace robustness;

namespace {

const std::string kTeapot = std::string(TOONRAY_TEST_DATA_DIR) + "/teapot.obj";

int count_with(const fs::path& dir, const std::string& part) {
    int n = 0;
    for (const std::string& f : files_under(dir)) n += f.find(part) != std::string::npos;
    return n;
}

/// A read-only directory: a read-only tmpfs when root (root ignores permission bits), else a
/// directory with mode 0555.
struct ReadOnlyDir {
    std::optional<ScratchMount> mount;
    std::optional<TempDir> dir;
    fs::path path;

    explicit ReadOnlyDir(const std::string& name) {
        if (::geteuid() == 0) {
            mount.emplace(name, "size=64k", true);
            path = mount->path;
            if (!mount->ok) path.clear();
        } else {
            dir.emplace(name);
            path = dir->path;
            fs::permissions(path, fs::perms::owner_read | fs::perms::owner_exec);
        }
    }
    ~ReadOnlyDir() {
        if (dir) fs::permissions(dir->path, fs::perms::owner_all);
    }
};

}  // namespace

TEST(Filesystem, OutputPathThroughAFileIsAClearError) {
    TempDir dir("fs_notdir");
    dir.write("file", "not a directory");
    const fs::path out = dir / "file" / "frame.png";
    CommandResult r = run_toonray("render " + kTeapot + " -o " + out.string() + " --size 64x48");
    EXPECT_EQ(r.exit_code, 1) << r.output;
    EXPECT_EQ(error_lines(r.output),
              std::vector<std::string>{out.string() + ": cannot create file: Not a directory"});
    EXPECT_EQ(files_under(dir.path), std::vector<std::string>{"file"});
}

TEST(Filesystem, ReadOnlyOutputDirectory) {
    ReadOnlyDir ro("fs_readonly");
    if (ro.path.empty()) GTEST_SKIP() << ro.mount->why;
    const std::string err = ::geteuid() == 0 ? "Read-only file system" : "Permission denied";
    CommandResult r = run_toonray("render " + kTeapot + " -o " + (ro.path / "frame.png").string() +
                                  " --size 64x48");
    EXPECT_EQ(r.exit_code, 1) << r.output;
    EXPECT_EQ(error_lines(r.output), std::vector<std::string>{(ro.path / "frame.png").string() +
                                                              ": cannot create file: " + err});

    TempDir in("fs_readonly_in");
    fs::copy_file(kTeapot, in / "keys_000001.obj");
    r = run_toonray("batch keys 1 1 --quiet --input " + in.path.string() + " --output " +
                    ro.path.string());
    EXPECT_EQ(r.exit_code, 1) << r.output;
    EXPECT_EQ(error_lines(r.output),
              std::vector<std::string>{ro.path.string() +
                                       ": output directory cannot be created or is not writable"});
    EXPECT_EQ(files_under(ro.path), std::vector<std::string>{});
}

TEST(Filesystem, FullDiskFailsTheFrameAndLeavesNoPartialFile) {
    // The teapot at 1280x720 (classic lines) is a ~60 KB PNG: it cannot fit a 32 KiB tmpfs.
    ScratchMount disk("fs_full", "size=32k");
    if (!disk.ok) GTEST_SKIP() << disk.why;
    const fs::path out = disk.path / "frame.png";
    CommandResult r = run_toonray("render " + kTeapot + " -o " + out.string() +
                                  " --size 1280x720 --edges classic");
    EXPECT_EQ(r.exit_code, 1) << r.output;
    EXPECT_EQ(error_lines(r.output),
              std::vector<std::string>{out.string() + ": write failed: No space left on device"});
    EXPECT_EQ(files_under(disk.path), std::vector<std::string>{}) << "no partial or temporary file";

    // A batch goes on past a failed frame and reports it; small frames still fit.
    TempDir in("fs_full_in");
    fs::copy_file(kTeapot, in / "keys_000001.obj");
    fs::copy_file(kTeapot, in / "keys_000002.obj");
    r = run_toonray("batch keys 1 2 --quiet --jobs 1 --input " + in.path.string() + " --output " +
                    disk.path.string() + " --size 1280x720 --edges classic");
    EXPECT_EQ(r.exit_code, 1) << r.output;
    EXPECT_NE(r.output.find("write failed: No space left on device"), std::string::npos)
        << r.output;
    EXPECT_EQ(count_with(disk.path, ".tmp"), 0);
    EXPECT_EQ(count_with(disk.path, ".png"), 0);

    // A score written to a full disk: the 32 KiB tmpfs is filled by a large file first.
    {
        std::ofstream fill(disk.path / "fill", std::ios::binary);
        std::string block(4096, 'x');
        for (int i = 0; i < 64 && fill; ++i) fill << block;
    }
    r = run_toonray("score convert " + std::string(TOONRAY_DATA_DIR) + "/entertainer.midi " +
                    (disk.path / "out.notes").string());
    EXPECT_EQ(r.exit_code, 1) << r.output;
    EXPECT_NE(r.output.find((disk.path / "out.notes").string() + ": "), std::string::npos)
        << r.output;
    EXPECT_EQ(files_under(disk.path), std::vector<std::string>{"fill"});
}

namespace {

/// Starts `toonray ARGS...`, waits until `dir` holds `frames` PNG files, sends `sig`, and
/// returns the exit status.
int interrupt_when(const std::vector<std::string>& args, const fs::path& dir, int frames, int sig) {
    std::vector<std::string> all = {TOONRAY_CLI};
    all.insert(all.end(), args.begin(), args.end());
    std::vector<char*> argv;
    for (auto& a : all) argv.push_back(a.data());
    argv.push_back(nullptr);
    pid_t pid;
    if (posix_spawn(&pid, TOONRAY_CLI, nullptr, nullptr, argv.data(), environ) != 0) return -1;
    for (int i = 0; i < 3000 && count_with(dir, ".png") - count_with(dir, ".tmp") < frames; ++i)
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
    ::kill(pid, sig);
    int status = 0;
    ::waitpid(pid, &status, 0);
    return status;
}

}  // namespace

TEST(Interruption, SigtermStopsABatchCleanly) {
    TempDir dir("fs_sigterm_batch");
    fs::create_directories(dir / "in");
    const int frames = 200;
    for (int f = 1; f <= frames; ++f)
        fs::create_symlink(kTeapot, dir / "in" / fmt::format("keys_{:06d}.obj", f));
    const fs::path out = dir / "png";
    int status = interrupt_when(
        {"batch", "keys", "1", std::to_string(frames), "--input", (dir / "in").string(), "--output",
         out.string(), "--size", "320x240", "--quiet", "--jobs", "2"},
        out, 3, SIGTERM);
    ASSERT_TRUE(WIFEXITED(status))
        << "killed by signal " << (WIFSIGNALED(status) ? WTERMSIG(status) : 0);
    EXPECT_EQ(WEXITSTATUS(status), 130);
    const int done = count_with(out, ".png");
    EXPECT_GE(done, 3);
    EXPECT_LT(done, frames) << "the run should have been stopped early";
    EXPECT_EQ(count_with(out, ".tmp"), 0) << "no temporary file may remain";
    for (const std::string& f : files_under(out)) EXPECT_TRUE(toonray::is_valid_png(out / f)) << f;
}

TEST(Interruption, SigtermStopsAPianoMovieCleanly) {
    TempDir dir("fs_sigterm_piano");
    const fs::path out = dir / "png";
    int status = interrupt_when({"piano", "-o", out.string(), "--seconds", "20", "--size",
                                 "160x120", "--quiet", "--jobs", "1"},
                                out, 2, SIGTERM);
    ASSERT_TRUE(WIFEXITED(status))
        << "killed by signal " << (WIFSIGNALED(status) ? WTERMSIG(status) : 0);
    EXPECT_EQ(WEXITSTATUS(status), 130);
    EXPECT_LT(count_with(out, ".png"), 480);
    EXPECT_EQ(count_with(out, ".tmp"), 0) << "no temporary file may remain";
}
