// The settings document from Python: the same keys, values and line rules as the TOML document
// (frame/settings.h), set through the library's own table so that every check and message is
// the command line's.

#include <fmt/format.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include "binding.h"
#include "toonray/core/error.h"
#include "toonray/core/parse.h"
#include "toonray/frame/feature_images.h"
#include "toonray/ink/line_style.h"
#include "toonray/render/line_settings.h"

namespace toonray::python {
namespace {

bool is_path(const py::handle& value) {
    static const py::object path_like = py::module_::import("os").attr("PathLike");
    return py::isinstance<py::str>(value) || py::isinstance(value, path_like);
}

// Whether a value is a whole number or a real one: Python's, and numpy's scalars (which the
// numbers module's abstract classes know).
bool is_integral(const py::handle& value) {
    static const py::object integral = py::module_::import("numbers").attr("Integral");
    return !py::isinstance<py::bool_>(value) && py::isinstance(value, integral);
}

bool is_number(const py::handle& value) {
    static const py::object real = py::module_::import("numbers").attr("Real");
    return !py::isinstance<py::bool_>(value) && py::isinstance(value, real);
}

// A Python number as the settings' text of it: the shortest text of the float, as the TOML
// reader writes a line rule's number.
std::string number_text(const py::handle& value) {
    if (py::isinstance<py::bool_>(value)) return value.cast<bool>() ? "yes" : "no";
    if (is_integral(value))
        return std::to_string(
            py::int_(py::reinterpret_borrow<py::object>(value)).cast<long long>());
    return format_number(py::float_(py::reinterpret_borrow<py::object>(value)).cast<float>());
}

// A setting's value: bool, int, float, str, a list of str; a list or tuple of numbers is the
// comma-separated text of them (colours: (1, 0, 0) is "1,0,0").
SettingValue setting_value(const py::handle& value, const std::string& key) {
    if (py::isinstance<py::bool_>(value)) return value.cast<bool>();
    if (is_integral(value))
        return static_cast<std::int64_t>(
            py::int_(py::reinterpret_borrow<py::object>(value)).cast<long long>());
    if (is_number(value))
        return py::float_(py::reinterpret_borrow<py::object>(value)).cast<double>();
    if (py::isinstance<py::str>(value)) return value.cast<std::string>();
    if (py::isinstance<py::list>(value) || py::isinstance<py::tuple>(value)) {
        const py::sequence items = value.cast<py::sequence>();
        bool numbers = items.size() > 0;
        for (const py::handle item : items) numbers = numbers && is_number(item);
        if (numbers) {
            std::string text;
            for (const py::handle item : items)
                text += (text.empty() ? "" : ",") + number_text(item);
            return text;
        }
        std::vector<std::string> list;
        for (const py::handle item : items) {
            if (!py::isinstance<py::str>(item))
                throw Error(fmt::format("{}: expected a list of text or of numbers", key));
            list.push_back(item.cast<std::string>());
        }
        return list;
    }
    throw Error(
        fmt::format("{}: expected text, a number, true/false or a list, got {}", key,
                    py::str(py::type::handle_of(value).attr("__name__")).cast<std::string>()));
}

// A line rule's value as the text a `.style` match line has.
std::string rule_text(const py::handle& value, const std::string& at) {
    if (py::isinstance<py::str>(value)) return value.cast<std::string>();
    if (py::isinstance<py::bool_>(value) || is_number(value)) return number_text(value);
    if (py::isinstance<py::list>(value) || py::isinstance<py::tuple>(value)) {
        std::string text;
        for (const py::handle item : value.cast<py::sequence>()) {
            if (py::isinstance<py::list>(item) || py::isinstance<py::tuple>(item) ||
                py::isinstance<py::dict>(item))
                throw Error(fmt::format("{}: a list of lists or dicts", at));
            text += (text.empty() ? "" : ",") + rule_text(item, at);
        }
        return text;
    }
    throw Error(fmt::format("{}: expected text, a number, true/false or a list", at));
}

void add_rules(Settings& settings, const py::handle& rules) {
    if (!(py::isinstance<py::list>(rules) || py::isinstance<py::tuple>(rules)))
        throw Error("lines.rule: expected a list of dicts (the [[lines.rule]] tables)");
    std::size_t index = 0;
    for (const py::handle rule : rules.cast<py::sequence>()) {
        ++index;
        const std::string where = fmt::format("lines.rule[{}]", index);
        if (!py::isinstance<py::dict>(rule)) throw Error(where + ": expected a dict");
        std::vector<std::pair<std::string, std::string>> entries;
        for (const auto& [key, value] : rule.cast<py::dict>()) {
            const std::string name = py::str(key).cast<std::string>();
            entries.emplace_back(name, rule_text(value, where + "." + name));
        }
        add_line_rule(settings, entries, where);
    }
}

void read_dict(const py::dict& dict, const std::string& prefix, Settings& settings) {
    for (const auto& [key_object, value] : dict) {
        if (!py::isinstance<py::str>(key_object))
            throw Error(fmt::format("settings keys are text, got {}",
                                    py::repr(key_object).cast<std::string>()));
        const std::string key = key_object.cast<std::string>();
        const std::string path = prefix.empty() ? key : prefix + "." + key;
        if (path == "lines.rule") {
            add_rules(settings, value);
        } else if (py::isinstance<py::dict>(value)) {
            if (find_setting(path))
                throw Error(fmt::format("{}: expected a value, got a dict", path));
            read_dict(value.cast<py::dict>(), path, settings);
        } else {
            set_setting(settings, path, setting_value(value, path));
        }
    }
}

py::object value_object(const std::optional<SettingValue>& value) {
    if (!value) return py::none();
    return std::visit([](const auto& v) -> py::object { return py::cast(v); }, *value);
}

py::dict settings_dict(const Settings& settings) {
    py::dict out;
    for (const Setting& s : settings_table()) out[py::str(s.key)] = value_object(s.get(settings));
    py::list rules;
    for (const ink::LineStyleRule& rule : settings.render.lines.ink.styles.rules) {
        py::dict entries;
        for (const auto& [key, text] : ink::line_style_rule_entries(rule))
            entries[py::str(key)] = text;
        rules.append(entries);
    }
    out["lines.rule"] = rules;
    return out;
}

}  // namespace

Settings settings_from(const py::object& document) {
    Settings settings;
    if (document.is_none()) return settings;
    if (is_path(document)) {
        load_settings(document.cast<std::filesystem::path>(), settings);
    } else if (py::isinstance<py::dict>(document)) {
        read_dict(document.cast<py::dict>(), "", settings);
    } else {
        throw py::type_error("settings: expected None, a dict or the path of a TOML document");
    }
    check_settings(settings);
    return settings;
}

void bind_settings(py::module_& m) {
    m.def(
        "settings",
        [](const py::object& document) { return settings_dict(settings_from(document)); },
        py::arg("document") = py::none(),
        "Every key of the settings document with its value (None: unset, the default) and "
        "'lines.rule', the line rules as dicts of their keys' text: the defaults with `document` "
        "(a dict or a TOML file's path) applied.");
    m.def(
        "settings_toml",
        [](const py::object& document, bool picture_only) {
            return settings_toml(settings_from(document), picture_only);
        },
        py::arg("document") = py::none(), py::arg("picture_only") = false,
        "The settings document as TOML (what `toonray settings` prints, and --settings reads).");
    m.def(
        "setting_keys",
        [] {
            const Settings defaults;
            py::list out;
            for (const Setting& s : settings_table()) {
                py::dict row;
                row["key"] = std::string(s.key);
                row["flag"] = std::string(s.flag.substr(0, s.flag.find(',')));
                row["help"] = std::string(s.help);
                row["picture"] = s.picture;
                row["default"] = value_object(s.get(defaults));
                out.append(row);
            }
            return out;
        },
        "The keys of the settings document in order: dicts of key, flag (the command line's "
        "option), help, picture (whether it can change the picture) and default.");
    m.def(
        "line_rule_keys",
        [] {
            std::vector<std::string> out;
            for (const std::string_view key : ink::line_rule_keys()) out.emplace_back(key);
            return out;
        },
        "The keys a line rule may hold: the matchers, then the style attributes and their "
        "aliases.");
    std::vector<std::string> modes;
    for (const LineMode mode : {LineMode::Ink, LineMode::Robust, LineMode::Classic})
        modes.emplace_back(line_mode_name(mode));
    m.attr("LINE_MODES") = modes;
    std::vector<std::string> types;
    for (unsigned bit = 1; bit & kLineAll; bit <<= 1) types.push_back(format_line_types(bit));
    m.attr("LINE_TYPES") = types;
    m.def(
        "line_layers",
        [](const std::string& mode) {
            // The line types each mode tells apart, as its feature images name them
            // (lines_<type>, and the classic mode's edges_<type>).
            const LineMode line_mode = parse_line_mode(mode, "mode");
            std::vector<std::string> out;
            for (const FeatureImage& image : feature_images()) {
                if (!image.in(line_mode)) continue;
                const std::string_view name = image.name;
                for (const std::string_view prefix : {"lines_", "edges_"})
                    if (name.starts_with(prefix)) out.emplace_back(name.substr(prefix.size()));
            }
            return out;
        },
        py::arg("mode"),
        "The line types a mode draws into layers of their own ('lines.<type>' in a frame's "
        "layers), for a scene without polylines.");
}

}  // namespace toonray::python
