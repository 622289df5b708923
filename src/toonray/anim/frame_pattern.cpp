#include "toonray/anim/frame_pattern.h"

#include <fmt/format.h>

#include "toonray/core/error.h"

namespace toonray {

FramePattern::FramePattern(std::string pattern) : text_(std::move(pattern)) {
    bool found = false;
    std::string* out = &prefix_;
    for (std::size_t i = 0; i < text_.size(); ++i) {
        char c = text_[i];
        if (c != '%') {
            out->push_back(c);
            continue;
        }
        if (i + 1 < text_.size() && text_[i + 1] == '%') {
            out->push_back('%');
            ++i;
            continue;
        }
        std::size_t j = i + 1;
        int width = 0;
        bool zero = j < text_.size() && text_[j] == '0';
        if (zero) ++j;
        while (j < text_.size() && text_[j] >= '0' && text_[j] <= '9' && width < 100)
            width = width * 10 + (text_[j++] - '0');
        if (j >= text_.size() || text_[j] != 'd' || width > 9 || (width > 0 && !zero))
            throw Error(
                fmt::format("frame pattern '{}': only %d and %0Nd (N <= 9) are supported", text_));
        if (found) throw Error(fmt::format("frame pattern '{}': more than one %d", text_));
        found = true;
        width_ = width;
        out = &suffix_;
        i = j;
    }
    if (!found)
        throw Error(
            fmt::format("frame pattern '{}': needs a %d or %0Nd for the frame number", text_));
    if (text_.find('/') != std::string::npos)
        throw Error(fmt::format("frame pattern '{}': must be a file name, not a path", text_));
}

std::string FramePattern::format(int frame) const {
    return prefix_ + fmt::format("{:0{}d}", frame, width_) + suffix_;
}

std::vector<FramePattern> default_input_patterns(const std::string& name) {
    std::string escaped;
    for (char c : name) {
        if (c == '%') escaped.push_back('%');
        escaped.push_back(c);
    }
    return {FramePattern(escaped + "_%06d.obj"), FramePattern(escaped + "_%04d.obj"),
            FramePattern(escaped + "%d.obj"), FramePattern(escaped + "_%d.obj")};
}

std::optional<std::filesystem::path> find_frame_file(const std::filesystem::path& dir,
                                                     const std::vector<FramePattern>& patterns,
                                                     int frame) {
    for (const FramePattern& p : patterns) {
        std::filesystem::path candidate = dir / p.format(frame);
        std::error_code ec;
        if (std::filesystem::is_regular_file(candidate, ec)) return candidate;
    }
    if (patterns.size() == 1) return dir / patterns[0].format(frame);
    return std::nullopt;
}

}  // namespace toonray
