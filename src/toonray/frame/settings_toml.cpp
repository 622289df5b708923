// The settings document as TOML: read with toml++ (Debian's libtomlplusplus-dev, header only),
// written by hand so that every number has its shortest exact form.

#include <charconv>
#include <cmath>
#include <fmt/format.h>
#include <map>

#include <stdexcept>

// toml++ states its parser's invariants with TOML_ASSERT_ASSUME: an assertion that aborts in a
// build without NDEBUG, and in an optimised build an assumption that clang may compile as if it
// always held (undefined behaviour when it does not). Fuzzing found documents that break one
// (a table header whose '[' is followed by a line end). Here every invariant is checked and a
// broken one throws, so such a document is refused instead.
namespace toonray::detail {
struct TomlInvariantBroken : std::runtime_error {
    using std::runtime_error::runtime_error;
};
[[noreturn]] inline void toml_invariant_broken(const char* what) {
    throw TomlInvariantBroken(what);
}
}  // namespace toonray::detail
#pragma push_macro("NDEBUG")
#undef NDEBUG
#define TOML_ASSERT(expr) \
    ((expr) ? static_cast<void>(0) : ::toonray::detail::toml_invariant_broken(#expr))
#include <toml++/toml.h>
#pragma pop_macro("NDEBUG")

#include "toonray/core/error.h"
#include "toonray/core/parse.h"
#include "toonray/frame/settings.h"
#include "toonray/io/file.h"

namespace toonray {
namespace {

std::string place(std::string_view source, const toml::source_region& where) {
    return fmt::format("{}:{}:{}", source, where.begin.line, where.begin.column);
}

// The text of a TOML value as a `.style` match line writes it (line rules).
std::string rule_text(const toml::node& node, const std::string& at) {
    if (const auto* s = node.as_string()) return s->get();
    if (const auto* b = node.as_boolean()) return b->get() ? "yes" : "no";
    if (const auto* i = node.as_integer()) return fmt::format("{}", i->get());
    if (const auto* f = node.as_floating_point())
        return format_number(static_cast<float>(f->get()));
    if (const auto* a = node.as_array()) {
        std::string out;
        for (const toml::node& item : *a) {
            if (item.is_array() || item.is_table())
                throw Error(fmt::format("{}: a list of lists or tables", at));
            out += (out.empty() ? "" : ",") + rule_text(item, at);
        }
        return out;
    }
    throw Error(fmt::format("{}: expected text, a number, yes/no or a list", at));
}

SettingValue setting_value(const toml::node& node, const std::string& at) {
    if (const auto* s = node.as_string()) return s->get();
    if (const auto* b = node.as_boolean()) return b->get();
    if (const auto* i = node.as_integer()) return i->get();
    if (const auto* f = node.as_floating_point()) return f->get();
    if (const auto* a = node.as_array()) {
        std::vector<std::string> items;
        for (const toml::node& item : *a) {
            if (!item.is_string()) throw Error(fmt::format("{}: expected a list of text", at));
            items.push_back(item.as_string()->get());
        }
        return items;
    }
    throw Error(fmt::format("{}: expected a value, got a table", at));
}

void read_table(const toml::table& table, const std::string& prefix, std::string_view source,
                Settings& settings) {
    for (const auto& [key, node] : table) {
        const std::string path =
            prefix.empty() ? std::string(key.str()) : prefix + "." + std::string(key.str());
        const std::string at = place(source, node.source());
        if (path == "lines.rule") {
            const toml::array* rules = node.as_array();
            if (!rules || !rules->is_array_of_tables())
                throw Error(fmt::format("{}: lines.rule: expected [[lines.rule]] tables", at));
            for (std::size_t i = 0; i < rules->size(); ++i) {
                const toml::table& rule = *(*rules)[i].as_table();
                std::vector<std::pair<std::string, std::string>> entries;
                for (const auto& [rule_key, value] : rule) {
                    const std::string key_path =
                        fmt::format("lines.rule[{}].{}", i + 1, rule_key.str());
                    entries.emplace_back(
                        std::string(rule_key.str()),
                        rule_text(value, place(source, value.source()) + ": " + key_path));
                }
                add_line_rule(
                    settings, entries,
                    fmt::format("{}: lines.rule[{}]", place(source, rule.source()), i + 1));
            }
            continue;
        }
        if (const toml::table* inner = node.as_table()) {
            if (find_setting(path))
                throw Error(fmt::format("{}: {}: expected a value, got a table", at, path));
            read_table(*inner, path, source, settings);
            continue;
        }
        if (!find_setting(path))
            throw Error(fmt::format("{}: unknown key '{}'", place(source, key.source()), path));
        try {
            set_setting(settings, path, setting_value(node, path));
        } catch (const Error& e) {
            throw Error(fmt::format("{}: {}", at, e.what()));
        }
    }
}

// ---- Writing ---------------------------------------------------------------------------------

std::string toml_quoted(std::string_view text) {
    std::string out = "\"";
    for (const char c : text) {
        switch (c) {
            case '"': out += "\\\""; break;
            case '\\': out += "\\\\"; break;
            case '\n': out += "\\n"; break;
            case '\t': out += "\\t"; break;
            case '\r': out += "\\r"; break;
            default:
                if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f)
                    out += fmt::format("\\u{:04x}", static_cast<unsigned>(c));
                else out += c;
        }
    }
    return out + "\"";
}

std::string toml_value(const SettingValue& v) {
    return std::visit(
        [](const auto& x) -> std::string {
            using T = std::decay_t<decltype(x)>;
            if constexpr (std::is_same_v<T, bool>) {
                return x ? "true" : "false";
            } else if constexpr (std::is_same_v<T, std::int64_t>) {
                return fmt::format("{}", x);
            } else if constexpr (std::is_same_v<T, double>) {
                // Settings are floats: the shortest text of the float reads back exactly, and
                // TOML needs a point or an exponent to read a float.
                std::string s = format_number(static_cast<float>(x));
                if (s.find_first_of(".eEn") == std::string::npos) s += ".0";
                return s;
            } else if constexpr (std::is_same_v<T, std::string>) {
                return toml_quoted(x);
            } else {
                std::string out = "[";
                for (std::size_t i = 0; i < x.size(); ++i)
                    out += (i ? ", " : "") + toml_quoted(x[i]);
                return out + "]";
            }
        },
        v);
}

// A line rule's value as TOML: yes/no as booleans, numbers as numbers, the rest as text.
std::string rule_toml_value(const std::string& text) {
    if (text == "yes") return "true";
    if (text == "no") return "false";
    float number = 0.0f;
    const auto [p, ec] = std::from_chars(text.data(), text.data() + text.size(), number);
    if (!text.empty() && ec == std::errc() && p == text.data() + text.size() &&
        std::isfinite(number) && format_number(number) == text)
        return toml_value(static_cast<double>(number));
    return toml_quoted(text);
}

}  // namespace

void read_settings(std::string_view text, std::string_view source, Settings& settings) {
    // Settings documents are printable ASCII, tabs and line ends: Debian's toml++ reaches an
    // unreachable point (undefined behaviour) on some other characters and fails an internal
    // assertion on control characters in a table header, both found by fuzzing. TOML allows
    // no raw control character but the tab anywhere, so only the non-ASCII text is a loss.
    std::size_t line = 1, line_start = 0;
    for (std::size_t i = 0; i < text.size(); ++i) {
        const auto c = static_cast<unsigned char>(text[i]);
        if (c == '\n') {
            ++line;
            line_start = i + 1;
        } else if (c >= 0x80) {
            throw Error(
                fmt::format("{}:{}:{}: a character that is not ASCII (settings documents "
                            "are ASCII; a .style file can name other objects)",
                            source, line, i - line_start + 1));
        } else if ((c < 0x20 && c != '\t' && c != '\r') || c == 0x7f) {
            throw Error(
                fmt::format("{}:{}:{}: control character 0x{:02x} (TOML allows none but "
                            "the tab)",
                            source, line, i - line_start + 1, c));
        }
    }
    toml::table table;
    try {
        table = toml::parse(text, source);
    } catch (const toml::parse_error& e) {
        throw Error(fmt::format("{}: {}", place(source, e.source()), e.description()));
    } catch (const detail::TomlInvariantBroken& e) {
        throw Error(
            fmt::format("{}: not a TOML document the reader can read (its check '{}' "
                        "failed; a table header may be unfinished)",
                        source, e.what()));
    }
    read_table(table, "", source, settings);
}

void load_settings(const std::filesystem::path& path, Settings& settings) {
    read_settings(read_file(path), path.string(), settings);
}

std::string settings_toml(const Settings& settings, bool picture_only) {
    std::string out = fmt::format("# toonray {} settings (docs/settings.md)\n", toonray_version());
    std::string section;
    static const Settings defaults;
    for (const Setting& s : settings_table()) {
        if (picture_only && !s.picture) continue;
        if (picture_only && !s.recorded_at_default && s.get(settings) == s.get(defaults)) continue;
        const std::size_t dot = s.key.rfind('.');
        const std::string_view table = s.key.substr(0, dot), key = s.key.substr(dot + 1);
        if (table != section) {
            section = table;
            out += fmt::format("\n[{}]\n", section);
        }
        if (const std::optional<SettingValue> value = s.get(settings))
            out += fmt::format("{} = {}\n", key, toml_value(*value));
        else out += fmt::format("# {} is not set: the default\n", key);
    }
    for (const ink::LineStyleRule& rule : settings.render.lines.ink.styles.rules) {
        out += "\n[[lines.rule]]\n";
        for (const auto& [key, text] : ink::line_style_rule_entries(rule))
            out += fmt::format("{} = {}\n", key, rule_toml_value(text));
    }
    return out;
}

}  // namespace toonray
