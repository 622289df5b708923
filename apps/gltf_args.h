#pragma once
/// The glTF options of `render` and `batch`: which animation and camera, and the time.

#include <CLI/CLI.hpp>
#include <optional>
#include <string>

#include "toonray/scene/gltf_animation.h"

namespace toonray::cli {

struct GltfArgs {
    std::string animation, camera_node;
    double fps = 24.0;
    std::optional<double> time;  ///< render: seconds
    std::optional<int> frame;    ///< render: frame, at frame / fps seconds

    /// Adds --animation, --camera-node and --fps; with `one_frame` also --time and --frame.
    void add_to(CLI::App& app, bool one_frame);
    [[nodiscard]] GltfPoseOptions pose() const;
    /// render: the time to pose at (0 when neither --time nor --frame is given).
    [[nodiscard]] double seconds() const;
    /// Whether any glTF option was given (they apply to glTF scenes only).
    [[nodiscard]] bool given() const;
};

}  // namespace toonray::cli
