#pragma once
/// Frame file names from printf-style patterns such as `keys_%06d.obj`.

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace toonray {

/// A validated pattern with exactly one integer conversion (`%d` or `%0Nd`, N <= 9); `%%` is a
/// literal percent sign. Formatting is ours, never printf's, so a pattern cannot be a format
/// string attack.
class FramePattern {
public:
    /// Throws Error when the pattern has no conversion, more than one, or an unsupported one.
    explicit FramePattern(std::string pattern);

    [[nodiscard]] std::string format(int frame) const;
    [[nodiscard]] const std::string& text() const { return text_; }

private:
    std::string text_;
    std::string prefix_, suffix_;
    int width_ = 0;  ///< zero-padded width, 0 = none
};

/// The patterns tried, in order, for frame N of animation `name` when no --pattern is given:
/// NAME_%06d.obj, NAME_%04d.obj, NAME%d.obj, NAME_%d.obj.
std::vector<FramePattern> default_input_patterns(const std::string& name);

/// The input file of `frame`: the first pattern whose file exists in `dir`, or, with one
/// pattern given, that file whether or not it exists. nullopt when none exists.
std::optional<std::filesystem::path> find_frame_file(const std::filesystem::path& dir,
                                                     const std::vector<FramePattern>& patterns,
                                                     int frame);

}  // namespace toonray
