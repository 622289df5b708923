#include "toonray/core/error.h"

#include <fmt/format.h>

namespace toonray {

std::string located(std::string_view file, std::size_t line, std::string_view message) {
    if (line == 0) return fmt::format("{}: {}", file, message);
    return fmt::format("{}:{}: {}", file, line, message);
}

void throw_at(std::string_view file, std::size_t line, std::string_view message) {
    throw Error(located(file, line, message));
}

}  // namespace toonray
