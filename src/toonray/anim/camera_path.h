#pragma once
/// Camera paths for animations: keyframes read from a small text file (docs/camera-path.md) and
/// a smooth camera at any time between them.
///
/// Eye, target, up and field of view are each interpolated by a cubic Hermite spline in time
/// whose tangents are Steffen's (1990) monotone slopes: the time-weighted three-point
/// derivative, limited so no component overshoots the keys on either side. Tangents are shared
/// by the segments meeting at a key, so position and velocity are continuous everywhere, also
/// with unevenly spaced key times; a key where a component turns back (or holds) gets a flat
/// tangent in that component, so a camera that holds still between two equal keys really holds.

#include <array>
#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "toonray/core/math.h"
#include "toonray/scene/camera.h"

namespace toonray {

/// One keyframe.
struct CameraKey {
    double time = 0.0;     ///< seconds
    Vec3f eye;             ///< camera position
    Vec3f target;          ///< point looked at
    Vec3f up{0, 1, 0};     ///< roughly up in the image; need not be unit or orthogonal
    float fov = 45.0f;     ///< horizontal field of view, degrees, in (1, 179)
    std::size_t line = 0;  ///< line in the source file, for messages (0 when built in code)
};

/// The camera at one time, in look-at form.
struct CameraPose {
    Vec3f eye;
    Vec3f target;
    Vec3f up;           ///< unit, orthogonal to target - eye
    float fov = 45.0f;  ///< horizontal, degrees
};

/// The seed's camera for a pose: gaze = eye + normalize(target - eye) / tan(fov / 2), so that
/// 2 atan(1 / |gaze - eye|) is the field of view; up as in the pose.
CameraSpec camera_spec(const CameraPose& pose);

class CameraPath {
public:
    CameraPath() = default;

    /// Validates the keys and precomputes tangents. With `loop_period`, time wraps: the path
    /// runs keys.front() .. keys.back() and then back to keys.front(), which it reaches
    /// `loop_period` seconds after it started, with continuous velocity across the wrap.
    /// Throws Error as "source:line: message" (using CameraKey::line): times not increasing;
    /// eye == target; up zero or parallel to the view; fov outside (1, 179); a loop period not
    /// longer than the keys' span; or an interpolated camera between two keys that degenerates
    /// (eye reaching the target, up turning parallel to the view).
    explicit CameraPath(std::vector<CameraKey> keys, std::optional<double> loop_period = {},
                        std::string source = "camera path");

    /// The camera at `time` seconds. Before the first key and after the last the path holds
    /// still (unless it loops). Throws Error when the path has no keys.
    [[nodiscard]] CameraPose pose(double time) const;

    /// camera_spec(pose(time)).
    [[nodiscard]] CameraSpec camera(double time) const { return camera_spec(pose(time)); }

    [[nodiscard]] const std::vector<CameraKey>& keys() const { return keys_; }
    [[nodiscard]] bool empty() const { return keys_.empty(); }
    [[nodiscard]] std::optional<double> loop_period() const { return period_; }
    [[nodiscard]] const std::string& source() const { return source_; }

private:
    static constexpr int kChannels = 10;  // eye xyz, target xyz, up xyz, fov
    using Values = std::array<double, kChannels>;

    [[nodiscard]] Values values_at(double time) const;
    void validate_between_keys() const;

    std::vector<CameraKey> keys_;
    std::vector<Values> values_;    // per key
    std::vector<Values> tangents_;  // per key, units per second
    std::optional<double> period_;
    std::string source_;
};

/// Parses the text format (docs/camera-path.md). `source` names the text in messages, which
/// read "source:line: what was wrong".
CameraPath parse_camera_path(std::string_view text, std::string_view source);

/// Reads and parses a .campath file.
CameraPath load_camera_path(const std::filesystem::path& path);

}  // namespace toonray
