#pragma once
/// The structure of a glTF file's JSON, checked before tinygltf reads it (internal to the
/// scene module). tinygltf refuses some files without saying why (a skin without "joints"),
/// reads others wrongly without a word (an array written as an object, an index written as a
/// string, a glTF 1.0 file), and reports the rest without the JSON path; this check names the
/// path and what is wrong, as "skins[0]: missing "joints" (...)".

#include <optional>
#include <string>
#include <string_view>

namespace toonray::gltf_detail {

/// The first problem found in `json_text` (a .gltf file, or a GLB's JSON chunk) as "PATH:
/// what is wrong", or nullopt when there is none. Checked: the asset and its version (glTF
/// 2.x, minVersion at most 2.0), the properties the glTF 2.0 schema requires, the types of
/// the properties toonray reads, and that data URIs marked base64 are. Text that is not JSON
/// gives nullopt: tinygltf's parser says where it fails.
[[nodiscard]] std::optional<std::string> check_gltf_json(std::string_view json_text);

}  // namespace toonray::gltf_detail
