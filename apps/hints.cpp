#include "hints.h"

#include <cctype>
#include <fmt/format.h>
#include <map>
#include <optional>

#include "toonray/media/audio.h"

namespace toonray::cli {
namespace {

/// One way past a limit: `option` of the command, and what to say about it.
struct LimitHint {
    Limit limit;
    std::string_view option;
    std::string_view text;
};

constexpr LimitHint kLimitHints[] = {
    {Limit::InputBytes, "--max-input-size", "--max-input-size raises it"},
    {Limit::Vertices, "--max-vertices", "--max-vertices raises it"},
    {Limit::Triangles, "--max-triangles", "--max-triangles raises it"},
    {Limit::ImagePixels, "--max-image-pixels", "--max-image-pixels raises it"},
    {Limit::Memory, "--max-memory", "--max-memory raises it"},
    {Limit::Memory, "--jobs", "render fewer frames at once with --jobs"},
};

/// What `limit` limits, as in "the triangle limit".
std::string_view limit_name(Limit limit) {
    switch (limit) {
        case Limit::InputBytes: return "input size";
        case Limit::LineBytes: return "line length";
        case Limit::Vertices: return "vertex";
        case Limit::Triangles: return "triangle";
        case Limit::ImagePixels: return "image size";
        case Limit::Memory: return "memory";
        case Limit::Frames: return "frame count";
        case Limit::CameraKeys: return "camera key";
        case Limit::Notes: return "note";
    }
    return "";
}

/// The hints of `limit` that apply to `command` and that `message` does not give already,
/// joined: "--max-memory raises it, or render fewer frames at once with --jobs".
std::string limit_hints(const std::string& message, Limit limit, const CLI::App& command) {
    std::string hints;
    for (const LimitHint& hint : kLimitHints) {
        if (hint.limit != limit || !command.get_option_no_throw(std::string(hint.option))) continue;
        if (message.find(hint.option) != std::string::npos) continue;
        if (!hints.empty()) hints += ", or ";
        hints += hint.text;
    }
    return hints;
}

}  // namespace

std::string_view raise_hint(Limit limit) {
    for (const LimitHint& hint : kLimitHints)
        if (hint.limit == limit) return hint.text;
    return {};
}

std::string with_limit_hint(const std::string& message, Limit limit, const CLI::App& command) {
    const std::string hints = limit_hints(message, limit, command);
    if (hints.empty()) return message;
    // "(the limit)" becomes "(the limit); --max-triangles raises it", not two parentheses in a row.
    return message.ends_with(')') ? fmt::format("{}; {}", message, hints)
                                  : fmt::format("{} ({})", message, hints);
}

void print_frame_limit_hints(const BatchReport& report, const CLI::App& command) {
    std::map<Limit, std::pair<int, std::string>> hinted;  // frames and hint, per limit
    for (const FrameFailure& failure : report.failures) {
        if (!failure.limit) continue;
        const std::string hints = limit_hints(failure.message, *failure.limit, command);
        if (hints.empty()) continue;
        auto& [frames, text] = hinted[*failure.limit];
        ++frames;
        text = hints;
    }
    for (const auto& [limit, frames_and_hint] : hinted) {
        const auto& [frames, hint] = frames_and_hint;
        fmt::print(stderr, "toonray: {} frame{} exceeded the {} limit: {}\n", frames,
                   frames == 1 ? "" : "s", limit_name(limit), hint);
    }
}

bool starts_with_flag(std::string_view message, std::string_view flag) {
    if (!message.starts_with(flag)) return false;
    if (message.size() == flag.size()) return true;
    const unsigned char next = static_cast<unsigned char>(message[flag.size()]);
    return !std::isalnum(next) && next != '-' && next != '_';
}

std::string soundfont_hint(const std::string& message, const std::filesystem::path& soundfont) {
    const std::filesystem::path path = soundfont.empty() ? default_soundfont() : soundfont;
    std::error_code ec;
    if (std::filesystem::exists(path, ec) || message.find(path.string()) == std::string::npos ||
        message.find("--soundfont") != std::string::npos)
        return message;
    return message + "; --soundfont chooses another";
}

}  // namespace toonray::cli
