#pragma once
/// A plain 2D array of pixels, row-major, y = 0 at the top. Resizing keeps the allocation when
/// the size does not grow, so per-frame buffers are reused across an animation.

#include <array>
#include <cstdint>
#include <vector>

namespace toonray {

template <typename T>
class Image {
public:
    Image() = default;
    Image(int width, int height, T fill = T{}) { resize(width, height, fill); }

    void resize(int width, int height, T fill = T{}) {
        width_ = width;
        height_ = height;
        pixels_.assign(static_cast<std::size_t>(width) * height, fill);
    }
    [[nodiscard]] int width() const { return width_; }
    [[nodiscard]] int height() const { return height_; }
    [[nodiscard]] std::size_t size() const { return pixels_.size(); }
    T& operator()(int x, int y) { return pixels_[static_cast<std::size_t>(y) * width_ + x]; }
    const T& operator()(int x, int y) const {
        return pixels_[static_cast<std::size_t>(y) * width_ + x];
    }
    T* data() { return pixels_.data(); }
    const T* data() const { return pixels_.data(); }
    T* row(int y) { return pixels_.data() + static_cast<std::size_t>(y) * width_; }
    const T* row(int y) const { return pixels_.data() + static_cast<std::size_t>(y) * width_; }

private:
    int width_ = 0, height_ = 0;
    std::vector<T> pixels_;
};

using Rgb8 = std::array<std::uint8_t, 3>;
using ImageRgb8 = Image<Rgb8>;
using ImageGray8 = Image<std::uint8_t>;
using ImageF = Image<float>;

}  // namespace toonray
