#include "toonray/scene/gltf_json_check.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cstdint>
#include <fmt/format.h>
#include <initializer_list>
#include <limits>
#include <nlohmann/json.hpp>

namespace toonray::gltf_detail {
namespace {

using nlohmann::json;

// What a property holds. tinygltf reads indices into int and sizes into size_t; a value of
// another type it reads as absent, or refuses the file without a reason.
enum class Kind { Index, Size, Boolean, Number, String, Object, Array, Indices, Numbers, Strings };

struct Property {
    const char* name;
    Kind kind;
    bool required = false;
};

// The first problem found, thrown from where it is found to check_gltf_json.
struct Problem {
    std::string text;
};

[[noreturn]] void fail(const std::string& at, const std::string& what) {
    throw Problem{fmt::format("{}: {}", at, what)};
}

// A value as a message quotes it: scalars as JSON, containers and long strings by their type.
std::string describe(const json& v) {
    if (v.is_array()) return "an array";
    if (v.is_object()) return "an object";
    if (v.is_string() && v.get_ref<const std::string&>().size() > 40) return "a long string";
    return v.dump(-1, ' ', false, json::error_handler_t::replace);
}

const char* kind_name(Kind kind) {
    switch (kind) {
        case Kind::Index: return "an index";
        case Kind::Size: return "a size (a non-negative integer)";
        case Kind::Boolean: return "true or false";
        case Kind::Number: return "a number";
        case Kind::String: return "a string";
        case Kind::Object: return "an object";
        default: return "an array";
    }
}

// The kind of each element of an array kind; other kinds give themselves.
Kind element_kind(Kind kind) {
    switch (kind) {
        case Kind::Indices: return Kind::Index;
        case Kind::Numbers: return Kind::Number;
        case Kind::Strings: return Kind::String;
        default: return kind;
    }
}

bool holds(const json& v, Kind kind) {
    const bool natural =
        v.is_number_unsigned() || (v.is_number_integer() && v.get<std::int64_t>() >= 0);
    switch (kind) {
        case Kind::Index:
            return natural && v.get<std::uint64_t>() <=
                                  static_cast<std::uint64_t>(std::numeric_limits<int>::max());
        case Kind::Size: return natural;
        case Kind::Boolean: return v.is_boolean();
        case Kind::Number: return v.is_number();
        case Kind::String: return v.is_string();
        case Kind::Object: return v.is_object();
        default: return v.is_array();
    }
}

[[noreturn]] void fail_kind(const json& v, const std::string& at, Kind kind) {
    fail(at, fmt::format("{} is not {}", describe(v), kind_name(kind)));
}

void check_value(const json& v, const std::string& at, Kind kind) {
    if (!holds(v, kind)) fail_kind(v, at, kind);
    const Kind element = element_kind(kind);
    if (element != kind)
        for (std::size_t k = 0; k < v.size(); ++k)
            if (!holds(v[k], element)) fail_kind(v[k], fmt::format("{}[{}]", at, k), element);
}

std::string join(const std::string& at, const char* name) {
    return at.empty() ? name : at + "." + name;
}

// The member `name` of `o`, or nullptr.
const json* member(const json& o, const char* name) {
    const auto it = o.find(name);
    return it == o.end() ? nullptr : &*it;
}

// The required properties of the object `o` at `at` are there, and each property listed has
// its kind.
void check_properties(const json& o, const std::string& at,
                      std::initializer_list<Property> properties) {
    for (const Property& p : properties) {
        if (const json* v = member(o, p.name)) check_value(*v, join(at, p.name), p.kind);
        else if (p.required) fail(at, fmt::format("missing \"{}\"", p.name));
    }
}

// Each value of the object `o` at `at` is an index (a primitive's attributes, a morph target).
void check_index_map(const json& o, const std::string& at) {
    for (const auto& [name, value] : o.items()) check_value(value, at + "." + name, Kind::Index);
}

// Calls check(item, path) for each item of the array `o[name]`, which must hold objects.
template <typename Check>
void each_object(const json& o, const std::string& at, const char* name, Check&& check) {
    const json* items = member(o, name);
    if (!items) return;
    const std::string where = join(at, name);
    if (at.empty() && items->is_object())
        fail(where,
             "an object where an array is expected (glTF 1.0 names its objects; glTF 2.0 lists "
             "them)");
    check_value(*items, where, Kind::Array);
    for (std::size_t i = 0; i < items->size(); ++i) {
        const std::string item_at = fmt::format("{}[{}]", where, i);
        check_value((*items)[i], item_at, Kind::Object);
        check((*items)[i], item_at);
    }
}

// A version "major.minor" this reader reads: glTF 2.x (later minor versions stay compatible),
// and for the minVersion a file needs, at most 2.0.
void check_version(const json& version, const std::string& at, bool minimum) {
    check_value(version, at, Kind::String);
    const std::string& text = version.get_ref<const std::string&>();
    const char* end = text.data() + text.size();
    unsigned major = 0, minor = 0;
    const auto [dot, major_error] = std::from_chars(text.data(), end, major);
    bool valid = major_error == std::errc() && dot != end && *dot == '.';
    if (valid) {
        const auto [last, minor_error] = std::from_chars(dot + 1, end, minor);
        valid = minor_error == std::errc() && last == end;
    }
    if (!valid)
        fail(at, fmt::format("{} is not a version (major.minor, \"2.0\")", describe(version)));
    if (major != 2 || (minimum && minor != 0))
        fail(at, fmt::format("{}: only glTF 2.0 is read", describe(version)));
}

void check_asset(const json& doc) {
    const json* asset = member(doc, "asset");
    if (!asset) fail("asset", R"(missing (a glTF 2.0 file has "asset": {"version": "2.0"}))");
    check_value(*asset, "asset", Kind::Object);
    const json* version = member(*asset, "version");
    if (!version) fail("asset", R"(missing "version")");
    if (!version->is_string())
        fail("asset.version",
             fmt::format(R"({} is not a string ("2.0" for glTF 2.0))", describe(*version)));
    check_version(*version, "asset.version", false);
    if (const json* min = member(*asset, "minVersion"))
        check_version(*min, "asset.minVersion", true);
}

// Whether a data URI's payload is base64 (RFC 4648 alphabet, '=' padding only at the end).
bool is_base64(std::string_view text) {
    std::size_t end = text.size();
    int padding = 0;
    while (end > 0 && text[end - 1] == '=' && padding < 2) --end, ++padding;
    if (text.size() % 4 != 0) return false;
    return std::all_of(text.begin(), text.begin() + static_cast<std::ptrdiff_t>(end), [](char c) {
        return std::isalnum(static_cast<unsigned char>(c)) || c == '+' || c == '/';
    });
}

// tinygltf's message for a data URI that is not base64 names neither the buffer nor the
// image, and quotes the whole URI.
void check_data_uri(const json& o, const std::string& at) {
    const json* uri = member(o, "uri");
    if (!uri) return;
    const std::string& text = uri->get_ref<const std::string&>();
    const std::size_t comma = text.find(',');
    if (text.rfind("data:", 0) == 0 && comma != std::string::npos &&
        text.substr(0, comma).find(";base64") != std::string::npos &&
        !is_base64(std::string_view(text).substr(comma + 1)))
        fail(at + ".uri", "the data URI's payload is not base64");
}

void check_camera(const json& camera, const std::string& at) {
    check_properties(camera, at, {{"type", Kind::String, true}});
    const std::string& type = camera["type"].get_ref<const std::string&>();
    if (type == "perspective") {
        check_properties(camera, at, {{"perspective", Kind::Object, true}});
        check_properties(camera["perspective"], at + ".perspective",
                         {{"yfov", Kind::Number, true},
                          {"znear", Kind::Number, true},
                          {"zfar", Kind::Number},
                          {"aspectRatio", Kind::Number}});
    } else if (type == "orthographic") {
        check_properties(camera, at, {{"orthographic", Kind::Object, true}});
        check_properties(camera["orthographic"], at + ".orthographic",
                         {{"xmag", Kind::Number, true},
                          {"ymag", Kind::Number, true},
                          {"zfar", Kind::Number, true},
                          {"znear", Kind::Number, true}});
    } else {
        fail(at + ".type",
             fmt::format(R"({} is not "perspective" or "orthographic")", describe(camera["type"])));
    }
}

// Required properties as the glTF 2.0 schema gives them, and the kinds of the properties
// toonray reads, item by item, in the schema's order of the top-level arrays.
void check_document(const json& doc) {
    check_asset(doc);
    check_properties(doc, "",
                     {{"scene", Kind::Index},
                      {"extensionsUsed", Kind::Strings},
                      {"extensionsRequired", Kind::Strings}});
    each_object(doc, "", "accessors", [](const json& a, const std::string& at) {
        check_properties(a, at,
                         {{"bufferView", Kind::Index},
                          {"byteOffset", Kind::Size},
                          {"componentType", Kind::Index, true},
                          {"normalized", Kind::Boolean},
                          {"count", Kind::Size, true},
                          {"type", Kind::String, true},
                          {"sparse", Kind::Object}});
        if (const json* sparse = member(a, "sparse")) {
            const std::string s = at + ".sparse";
            check_properties(*sparse, s,
                             {{"count", Kind::Index, true},
                              {"indices", Kind::Object, true},
                              {"values", Kind::Object, true}});
            check_properties((*sparse)["indices"], s + ".indices",
                             {{"bufferView", Kind::Index, true},
                              {"byteOffset", Kind::Index},
                              {"componentType", Kind::Index, true}});
            check_properties((*sparse)["values"], s + ".values",
                             {{"bufferView", Kind::Index, true}, {"byteOffset", Kind::Index}});
        }
    });
    each_object(doc, "", "animations", [](const json& a, const std::string& at) {
        check_properties(a, at, {{"channels", Kind::Array, true}, {"samplers", Kind::Array, true}});
        each_object(a, at, "channels", [](const json& c, const std::string& c_at) {
            check_properties(c, c_at,
                             {{"sampler", Kind::Index, true}, {"target", Kind::Object, true}});
            check_properties(c["target"], c_at + ".target",
                             {{"node", Kind::Index}, {"path", Kind::String, true}});
        });
        each_object(a, at, "samplers", [](const json& s, const std::string& s_at) {
            check_properties(s, s_at,
                             {{"input", Kind::Index, true},
                              {"interpolation", Kind::String},
                              {"output", Kind::Index, true}});
        });
    });
    each_object(doc, "", "buffers", [](const json& b, const std::string& at) {
        check_properties(b, at, {{"uri", Kind::String}, {"byteLength", Kind::Size, true}});
        check_data_uri(b, at);
    });
    each_object(doc, "", "bufferViews", [](const json& v, const std::string& at) {
        check_properties(v, at,
                         {{"buffer", Kind::Index, true},
                          {"byteOffset", Kind::Size},
                          {"byteLength", Kind::Size, true},
                          {"byteStride", Kind::Size}});
    });
    each_object(doc, "", "cameras", check_camera);
    each_object(doc, "", "images", [](const json& i, const std::string& at) {
        check_properties(i, at, {{"uri", Kind::String}, {"bufferView", Kind::Index}});
        check_data_uri(i, at);
    });
    each_object(doc, "", "materials", [](const json& m, const std::string& at) {
        check_properties(m, at, {{"pbrMetallicRoughness", Kind::Object}});
        const json* pbr = member(m, "pbrMetallicRoughness");
        if (!pbr) return;
        const std::string p = at + ".pbrMetallicRoughness";
        check_properties(*pbr, p,
                         {{"baseColorFactor", Kind::Numbers}, {"baseColorTexture", Kind::Object}});
        if (const json* texture = member(*pbr, "baseColorTexture"))
            check_properties(*texture, p + ".baseColorTexture",
                             {{"index", Kind::Index, true}, {"texCoord", Kind::Index}});
    });
    each_object(doc, "", "meshes", [](const json& m, const std::string& at) {
        check_properties(m, at, {{"primitives", Kind::Array, true}, {"weights", Kind::Numbers}});
        each_object(m, at, "primitives", [](const json& p, const std::string& p_at) {
            check_properties(p, p_at,
                             {{"attributes", Kind::Object, true},
                              {"indices", Kind::Index},
                              {"material", Kind::Index},
                              {"mode", Kind::Index},
                              {"targets", Kind::Array}});
            check_index_map(p["attributes"], p_at + ".attributes");
            each_object(p, p_at, "targets", check_index_map);
        });
    });
    each_object(doc, "", "nodes", [](const json& n, const std::string& at) {
        check_properties(n, at,
                         {{"camera", Kind::Index},
                          {"children", Kind::Indices},
                          {"skin", Kind::Index},
                          {"matrix", Kind::Numbers},
                          {"mesh", Kind::Index},
                          {"rotation", Kind::Numbers},
                          {"scale", Kind::Numbers},
                          {"translation", Kind::Numbers},
                          {"weights", Kind::Numbers}});
    });
    each_object(doc, "", "samplers", [](const json&, const std::string&) {});
    each_object(doc, "", "scenes", [](const json& s, const std::string& at) {
        check_properties(s, at, {{"nodes", Kind::Indices}});
    });
    each_object(doc, "", "skins", [](const json& s, const std::string& at) {
        if (!member(s, "joints") && (member(s, "jointNames") || member(s, "bindShapeMatrix")))
            fail(at,
                 R"(missing "joints" (jointNames and bindShapeMatrix are glTF 1.0; a glTF 2.0 )"
                 R"(skin lists its joint nodes by index in "joints", and its bind shape is part )"
                 R"(of "inverseBindMatrices"))");
        check_properties(s, at,
                         {{"inverseBindMatrices", Kind::Index},
                          {"skeleton", Kind::Index},
                          {"joints", Kind::Indices, true}});
    });
    each_object(doc, "", "textures", [](const json& t, const std::string& at) {
        check_properties(t, at, {{"sampler", Kind::Index}, {"source", Kind::Index}});
    });
    const json* extensions = member(doc, "extensions");
    const json* lights = extensions && extensions->is_object()
                             ? member(*extensions, "KHR_lights_punctual")
                             : nullptr;
    if (lights && lights->is_object())
        each_object(*lights, "extensions.KHR_lights_punctual", "lights",
                    [](const json& l, const std::string& at) {
                        check_properties(l, at,
                                         {{"type", Kind::String, true},
                                          {"color", Kind::Numbers},
                                          {"intensity", Kind::Number},
                                          {"range", Kind::Number}});
                        if (l["type"] == "spot")
                            check_properties(l, at, {{"spot", Kind::Object, true}});
                    });
}

}  // namespace

std::optional<std::string> check_gltf_json(std::string_view json_text) {
    const json doc = json::parse(json_text.begin(), json_text.end(), nullptr, false);
    if (!doc.is_object()) return std::nullopt;  // not JSON, or not an object: tinygltf says which
    try {
        check_document(doc);
    } catch (const Problem& problem) {
        return problem.text;
    }
    return std::nullopt;
}

}  // namespace toonray::gltf_detail
