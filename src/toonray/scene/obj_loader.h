#pragma once
/// Wavefront OBJ reading, with the MTL libraries a file names, written for speed (one pass, no
/// per-line allocation; the common lines read without bounds checks, digits 8 at a time; a
/// large text read in chunks on the threads of the current TBB arena, with the same result on
/// any number of them).
///
/// Reads: v (optional w or colour values ignored), vt, vn, f with 3 or more corners in all four
/// index forms (v, v/vt, v//vn, v/vt/vn), negative (relative) indices, o, g, usemtl, mtllib
/// (several files, paths relative to the OBJ), s (accepted, ignored: normals come from vn),
/// l (polylines, kept in Scene::polylines with their object and material; drawn as ink
/// strokes), comments, `\` line continuations, LF, CRLF and CR line endings, a UTF-8 byte-order mark, and the
/// camera block statement `c eye gaze up`. Polygons are triangulated as a fan from their first
/// corner, which is exact for convex polygons. Faces index only vertices defined before them.
/// An object is the run of faces after an `o` or `g` statement, named by it.
///
/// Read as other tools read them, with a warning (file:line) each: a texture or normal index
/// that points at no `vt`/`vn` (the face has no texture coordinates, or uses its geometric
/// normal); a non-finite coordinate (`nan`, `inf`, or beyond a float: faces using the vertex
/// are dropped; a non-finite normal or texture coordinate only takes those from the face);
/// `p` elements (ignored, one warning). `mtllib` names may escape spaces (`my\ file.mtl`).
/// A vertex index of 0 or out of range stays an error.

#include <cstddef>
#include <filesystem>
#include <string_view>

#include "toonray/core/error.h"
#include "toonray/core/limits.h"
#include "toonray/scene/scene.h"

namespace toonray {

struct ObjOptions {
    bool load_materials = true;  ///< follow mtllib statements
    /// Line length, vertex and triangle counts, the memory estimate (docs/robustness.md).
    /// Default: the process-wide limits at the time the options are made.
    Limits limits = toonray::limits();
};

/// Loads an OBJ file and the MTL files it names (each once). Clears `scene` first but keeps its
/// allocations, so a batch of frames reuses memory. Throws Error("file:line: reason") on
/// malformed input, LimitError when the input exceeds a limit of `options.limits`; a missing
/// MTL file or unknown material is a warning (at most 100 warnings per file, then a count of
/// the rest).
void load_obj(const std::filesystem::path& path, Scene& scene, Warnings& warnings,
              const ObjOptions& options = {});

/// Parses OBJ text already in memory; `path` names it in messages and anchors mtllib paths.
void parse_obj(std::string_view text, const std::filesystem::path& path, Scene& scene,
               Warnings& warnings, const ObjOptions& options = {});

}  // namespace toonray
