#pragma once
/// Wavefront OBJ and MTL writing: the inverse of obj_loader, so that a written scene loads back
/// with bit-identical numbers.
///
/// Layout of the OBJ: a header comment, `mtllib`, all `v`, `vt` and `vn` in scene order (so
/// index i of the scene is OBJ index i + 1), then the faces in triangle order with an `o` line
/// whenever the object changes and a `usemtl` line whenever the material changes, then the
/// camera block (when the scene has a camera):
///
///     # Camera start
///     v ex ey ez
///     v gx gy gz
///     vn ux uy uz
///     c -2 -1 -1
///     # Camera end
///
/// The camera block comes last so that it does not shift the indices of the scene's own
/// vertices: loading the file gives the same positions and normals followed by the camera's two
/// points and its up vector.
///
/// Numbers are written in the shortest form that reads back to the same float (fmt `{}`), so
/// write -> load is exact. Material 0 (the loader's default material) is not written to the
/// MTL; faces using it get a bare `usemtl`. Object and material names must survive the loader's
/// trimming (non-empty, no `#`, no line breaks, no leading or trailing white space); other
/// names throw Error rather than silently loading back as something else.

#include <filesystem>
#include <memory>
#include <string>
#include <string_view>

#include "toonray/scene/scene.h"

namespace toonray {

struct ObjWriteOptions {
    bool write_normals = true;    ///< `vn` and the `//vn` corners, when triangles have normals
    bool write_texcoords = true;  ///< `vt` and the `/vt` corners, when triangles have them
    bool write_camera = true;     ///< the camera block, when the scene has a camera
    /// Also (re)write the MTL file next to the OBJ. The OBJ names it (`mtllib`) either way when
    /// the scene has materials, so a frame sequence can write it once and then only OBJs.
    bool write_mtl = true;
};

/// The MTL file name used for an OBJ path: the same stem with the extension `.mtl`.
std::filesystem::path mtl_path_for(const std::filesystem::path& obj_path);

/// Formats the OBJ text into `out` (replacing its contents, keeping its capacity).
/// `mtl_name` is written as the `mtllib` statement; empty writes none.
/// Throws Error for non-finite numbers, out-of-range indices and unwritable names.
void format_obj(const Scene& scene, std::string_view mtl_name, std::string& out,
                const ObjWriteOptions& options = {});

/// Formats the MTL text for materials 1.. of `scene` into `out`. Texture paths (`map_kd`, which
/// the loader resolved relative to the MTL it read) are written relative to `mtl_dir`, the
/// directory the new MTL goes to.
void format_mtl(const Scene& scene, const std::filesystem::path& mtl_dir, std::string& out);

/// Writes scenes as OBJ + MTL, keeping its text between calls: when the next scene has the same
/// triangles (an animation frame), the face lines are reused, and so is the text of every vertex
/// and normal whose value has not changed (compared bit for bit). The output is the same as
/// format_obj's; only the work differs.
class ObjWriter {
public:
    ObjWriter();
    ~ObjWriter();
    ObjWriter(ObjWriter&&) noexcept;
    ObjWriter& operator=(ObjWriter&&) noexcept;

    /// Writes `obj_path` and (when options.write_mtl and the scene has materials besides the
    /// default) mtl_path_for(obj_path), each atomically: a reader never sees a half-written
    /// file. Throws Error on failure.
    void write(const std::filesystem::path& obj_path, const Scene& scene,
               const ObjWriteOptions& options = {});

    /// Formats the OBJ text as format_obj does, reusing what it can from the previous call.
    const std::string& format(const Scene& scene, std::string_view mtl_name,
                              const ObjWriteOptions& options = {});

    struct Cache;  ///< implementation detail (obj_writer.cpp)

private:
    std::unique_ptr<Cache> cache_;  ///< text and values of the previous call
    std::unique_ptr<Cache> next_;   ///< being built by this call
    std::string mtl_;
};

/// One-off convenience: ObjWriter{}.write(obj_path, scene, options).
void write_obj(const std::filesystem::path& obj_path, const Scene& scene,
               const ObjWriteOptions& options = {});

}  // namespace toonray
