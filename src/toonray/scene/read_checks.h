#pragma once
/// What the OBJ and MTL readers hold an input to as they read it (internal to the scene
/// module): counts against their limits, the pace of the memory estimate, and the number of
/// warnings one file may produce.

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <fmt/format.h>
#include <string>
#include <string_view>

#include "toonray/core/error.h"
#include "toonray/core/limits.h"
#include "toonray/scene/obj_lexer.h"

namespace toonray::wavefront {

/// Bytes a material or an object name costs, for the memory estimate.
inline constexpr std::uint64_t kNamedBytes = 160;

/// Throws LimitError(limit_kind) when `count` exceeds `limit` (never above what 32-bit indices
/// can address).
inline void check_count(const LineParser& parse, std::uint64_t count, std::uint64_t limit,
                        std::string_view what, Limit limit_kind) {
    limit = std::min(limit, kMaxIndexable);
    if (count > limit)
        parse.fail_limit(limit_kind, fmt::format("more than {} {} (the limit)", limit, what));
}

/// Throws Error when `count` exceeds what 32-bit indices can address, a bound no option raises.
inline void check_indexable(const LineParser& parse, std::uint64_t count, std::string_view what) {
    if (count > kMaxIndexable)
        parse.fail(fmt::format("more than {} {} (the limit)", kMaxIndexable, what));
}

/// Says when to check the memory estimate: every time `count` doubles (so the cost is O(1)
/// per element).
class MemoryCheck {
public:
    bool due(std::uint64_t count) {
        if (count < next_) return false;
        next_ = count * 2;
        return true;
    }
    /// As due() for each count from `first` to `first + n - 1` in turn, without checking: the
    /// pace of the checks is the same as if each had been asked.
    void skip(std::uint64_t first, std::uint64_t n) {
        for (std::uint64_t count = std::max(first, next_); count < first + n; count = next_)
            next_ = count * 2;
    }
    /// How many more elements `count` may grow by before the check is due.
    [[nodiscard]] std::uint64_t until_due(std::uint64_t count) const {
        return count < next_ ? next_ - count : 0;
    }

private:
    std::uint64_t next_ = 1 << 16;
};

/// Collects a file's warnings, at most kMaxWarnings of them: a hostile file could otherwise
/// produce one per line.
class WarningSink {
public:
    static constexpr std::size_t kMaxWarnings = 100;

    WarningSink(Warnings& warnings, std::string_view file) : warnings_(warnings), file_(file) {}
    WarningSink(const WarningSink&) = delete;
    WarningSink& operator=(const WarningSink&) = delete;
    ~WarningSink() {
        if (dropped_ > 0)
            warnings_.push_back(located(
                file_, 0,
                fmt::format("{} more warning{} not shown", dropped_, dropped_ == 1 ? "" : "s")));
    }
    void add(std::string message) {
        if (count_++ < kMaxWarnings) warnings_.push_back(std::move(message));
        else ++dropped_;
    }

private:
    Warnings& warnings_;
    std::string_view file_;
    std::size_t count_ = 0, dropped_ = 0;
};

}  // namespace toonray::wavefront
