#pragma once
// Small glTF files built in the tests: a JSON text around binary data given as bytes, written
// as .gltf (data URI) or .glb.

#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

namespace toonray::gltf_test {

inline std::string base64(const std::vector<std::uint8_t>& bytes) {
    static const char* table = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out;
    for (std::size_t i = 0; i < bytes.size(); i += 3) {
        std::uint32_t v = static_cast<std::uint32_t>(bytes[i]) << 16;
        if (i + 1 < bytes.size()) v |= static_cast<std::uint32_t>(bytes[i + 1]) << 8;
        if (i + 2 < bytes.size()) v |= bytes[i + 2];
        out += table[(v >> 18) & 63];
        out += table[(v >> 12) & 63];
        out += i + 1 < bytes.size() ? table[(v >> 6) & 63] : '=';
        out += i + 2 < bytes.size() ? table[v & 63] : '=';
    }
    return out;
}

/// Appends values as little-endian bytes.
template <typename T>
void put(std::vector<std::uint8_t>& bin, std::initializer_list<T> values) {
    for (T v : values) {
        std::uint8_t b[sizeof(T)];
        std::memcpy(b, &v, sizeof(T));
        bin.insert(bin.end(), b, b + sizeof(T));
    }
}

inline void put_u32(std::string& s, std::uint32_t v) {
    for (int i = 0; i < 4; ++i) s.push_back(static_cast<char>((v >> (8 * i)) & 0xff));
}

/// A GLB of `json` (which must give buffers[0] without a uri) and `bin`.
inline std::string glb(std::string json, std::vector<std::uint8_t> bin) {
    while (json.size() % 4) json.push_back(' ');
    while (bin.size() % 4) bin.push_back(0);
    std::string out = "glTF";
    put_u32(out, 2);
    put_u32(out, static_cast<std::uint32_t>(12 + 8 + json.size() + 8 + bin.size()));
    put_u32(out, static_cast<std::uint32_t>(json.size()));
    out += "JSON";
    out += json;
    put_u32(out, static_cast<std::uint32_t>(bin.size()));
    out += std::string("BIN\0", 4);
    out.append(bin.begin(), bin.end());
    return out;
}

/// The data URI of `bin`.
inline std::string data_uri(const std::vector<std::uint8_t>& bin) {
    return "data:application/octet-stream;base64," + base64(bin);
}

/// One triangle: positions (float VEC3, 36 bytes at 0) and unsigned short indices (6 bytes at
/// 36), in one buffer of 44 bytes.
inline std::vector<std::uint8_t> triangle_bin(std::uint16_t last_index = 2) {
    std::vector<std::uint8_t> bin;
    put<float>(bin, {0, 0, 0, 1, 0, 0, 0, 1, 0});
    put<std::uint16_t>(bin, {0, 1, last_index, 0});
    return bin;
}

/// The JSON of triangle_bin's scene; `buffer` is the buffer's extra members (e.g. its uri),
/// `extra` more top-level members.
inline std::string triangle_json(const std::string& buffer, const std::string& extra = "",
                                 const std::string& nodes = R"([{"mesh": 0, "name": "tri"}])",
                                 const std::string& position_count = "3") {
    return R"({"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
  "nodes": )" +
           nodes + R"(,
  "meshes": [{"name": "m", "primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
  "accessors": [
    {"bufferView": 0, "componentType": 5126, "count": )" +
           position_count + R"(, "type": "VEC3"},
    {"bufferView": 1, "componentType": 5123, "count": 3, "type": "SCALAR"}],
  "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 36},
                  {"buffer": 0, "byteOffset": 36, "byteLength": 6}],
  "buffers": [{"byteLength": 44)" +
           buffer + "}]" + extra + "}";
}

}  // namespace toonray::gltf_test
