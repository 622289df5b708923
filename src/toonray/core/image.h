#pragma once
/// A plain 2D array of pixels, row-major, y = 0 at the top. Resizing keeps the allocation when
/// the size does not grow, so per-frame buffers are reused across an animation.

#include <array>
#include <cstdint>
#include <memory>
#include <new>
#include <type_traits>
#include <utility>
#include <vector>

namespace toonray {

/// std::allocator, except that constructing an element without a value default-initialises it
/// rather than value-initialising it: for pixel types without a constructor (float, uint32_t,
/// Rgb8) growing a vector then leaves the new memory untouched instead of zeroing it. Image uses
/// it so that reshape() does not write every pixel of a buffer its caller is about to overwrite.
template <typename T>
struct DefaultInitAllocator : std::allocator<T> {
    template <typename U>
    struct rebind {
        using other = DefaultInitAllocator<U>;
    };
    using std::allocator<T>::allocator;

    template <typename U>
    void construct(U* p) noexcept(std::is_nothrow_default_constructible_v<U>) {
        ::new (static_cast<void*>(p)) U;
    }
    template <typename U, typename... Args>
    void construct(U* p, Args&&... args) {
        ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
    }
};

/// v.resize(n), allocating exactly n when it grows (resize alone may take up to twice what is
/// held), so that a buffer's size is what the frame memory estimates expect.
template <typename Vector>
void resize_exact(Vector& v, std::size_t n) {
    if (n > v.capacity()) v.reserve(n);
    v.resize(n);
}

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
    /// Sets the size without filling: every pixel's value is unspecified (new ones are left
    /// uninitialised for types without a constructor). For buffers the caller overwrites
    /// completely, where a fill would only touch the memory twice.
    void reshape(int width, int height) {
        width_ = width;
        height_ = height;
        resize_exact(pixels_, static_cast<std::size_t>(width) * height);
    }
    [[nodiscard]] int width() const { return width_; }
    [[nodiscard]] int height() const { return height_; }
    [[nodiscard]] std::size_t size() const { return pixels_.size(); }
    /// Pixels the allocation holds (at least size(): it is kept when the image shrinks).
    [[nodiscard]] std::size_t capacity() const { return pixels_.capacity(); }
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
    std::vector<T, DefaultInitAllocator<T>> pixels_;
};

using Rgb8 = std::array<std::uint8_t, 3>;
using ImageRgb8 = Image<Rgb8>;
using ImageGray8 = Image<std::uint8_t>;
using ImageF = Image<float>;

}  // namespace toonray
