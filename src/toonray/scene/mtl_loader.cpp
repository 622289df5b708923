#include "toonray/scene/mtl_loader.h"

#include <fmt/format.h>
#include <string>
#include <unordered_map>

#include "toonray/core/limits.h"
#include "toonray/io/file.h"
#include "toonray/scene/obj_lexer.h"
#include "toonray/scene/read_checks.h"

namespace toonray {

using namespace wavefront;

void parse_mtl(std::string_view text, const std::filesystem::path& path,
               std::vector<Material>& materials, Warnings& warnings) {
    const std::string file = path.string();
    refuse_binary(text, file, "an MTL");
    const Limits& lim = limits();
    LineReader reader(text, file, lim.max_line_bytes);
    std::string_view line;
    std::size_t line_number = 0;
    Material* current = nullptr;
    Material ignored;  // receives the statements of a name defined again
    WarningSink warn(warnings, file);
    std::unordered_map<std::string, std::size_t> index;
    for (std::size_t i = 0; i < materials.size(); ++i) index[materials[i].name] = i;
    MemoryCheck memory;

    while (reader.next(line, line_number)) {
        Tokens t(line);
        if (t.at_end()) continue;
        std::string_view kw = t.next();
        LineParser parse(file, line_number);
        if (kw == "newmtl") {
            std::string_view name = t.rest();
            if (name.empty()) parse.fail("'newmtl' needs a material name");
            std::string key(name);
            if (index.contains(key)) {
                // The first definition wins, in this file or an earlier library, as in
                // tinyobjloader: replacing it would recolour the faces already given it.
                warn.add(located(
                    file, line_number,
                    fmt::format("material '{}' defined again; the first definition is kept", key)));
                ignored = Material{key};
                current = &ignored;
            } else {
                check_indexable(parse, materials.size() + 1, "materials");
                if (memory.due(materials.size()))
                    check_memory(text.size() + materials.size() * kNamedBytes,
                                 fmt::format("{}: {} materials", file, materials.size()));
                index.emplace(key, materials.size());
                materials.push_back(Material{key});
                current = &materials.back();
            }
            continue;
        }
        if (kw != "Kd" && kw != "Ka" && kw != "Ks" && kw != "Ns" && kw != "d" && kw != "Tr" &&
            kw != "illum" && kw != "map_Kd")
            continue;  // unknown statements are ignored by design
        if (!current) parse.fail(fmt::format("'{}' before any 'newmtl'", kw));
        if (kw == "Kd" || kw == "Ka" || kw == "Ks") {
            Tokens probe = t;
            std::string_view first = probe.next();
            if (first == "spectral" || first == "xyz") continue;  // not supported; keep default
            Vec3f c;
            c.x = parse.number(t, kw);
            // "Kd r" alone means r = g = b (MTL specification).
            if (t.at_end()) {
                c.y = c.z = c.x;
            } else {
                c.y = parse.number(t, kw);
                c.z = parse.number(t, kw);
            }
            (kw == "Kd" ? current->kd : kw == "Ka" ? current->ka : current->ks) = c;
        } else if (kw == "Ns") {
            current->ns = parse.number(t, kw);
        } else if (kw == "d") {
            Tokens probe = t;
            if (probe.next() == "-halo") t.next();
            current->d = parse.number(t, kw);
        } else if (kw == "Tr") {
            current->d = 1.0f - parse.number(t, kw);
        } else if (kw == "illum") {
            // The specification has models 0 to 10; any whole number that fits is kept.
            const float v = parse.number(t, kw);
            if (!(v >= -1e9f && v <= 1e9f))
                parse.fail(fmt::format("illumination model {} out of range", v));
            current->illum = static_cast<int>(v);
        } else if (kw == "map_Kd") {
            // Options (-s 1 1 1, -clamp on, ...) come first; the file name is the last token.
            std::string_view rest = t.rest();
            std::size_t cut = rest.find_last_of(" \t");
            std::string_view name = cut == std::string_view::npos ? rest : rest.substr(cut + 1);
            if (name.empty()) parse.fail("'map_Kd' needs a file name");
            current->map_kd = (path.parent_path() / std::string(name)).string();
        }
    }
}

void load_mtl_library(const std::filesystem::path& path, std::vector<Material>& materials,
                      Warnings& warnings, std::string_view obj_file, std::size_t obj_line) {
    std::string text;
    try {
        text = read_file(path);
    } catch (const Error& e) {
        warnings.push_back(located(obj_file, obj_line,
                                   fmt::format("cannot read material library '{}' ({}); faces "
                                               "using its materials get the default material",
                                               path.string(), e.what())));
        return;
    }
    parse_mtl(text, path, materials, warnings);
}

}  // namespace toonray
