#include "toonray/anim/camera_path.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <fmt/format.h>
#include <numbers>

#include "toonray/core/error.h"
#include "toonray/core/limits.h"
#include "toonray/core/portable_math.h"
#include "toonray/io/file.h"

namespace toonray {

namespace {

constexpr double kDegrees = std::numbers::pi / 180.0;

/// Ranges that keep the spline's double arithmetic and the float camera finite.
constexpr double kMaxKeyTime = 1e9;    // seconds, about 32 years
constexpr double kMinKeyGap = 1e-6;    // seconds between keys
constexpr double kMaxKeyValue = 1e15;  // eye, target and up coordinates

struct Vec3d {
    double x = 0, y = 0, z = 0;
};
Vec3d operator-(const Vec3d& a, const Vec3d& b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
Vec3d operator*(const Vec3d& a, double s) { return {a.x * s, a.y * s, a.z * s}; }
double dot(const Vec3d& a, const Vec3d& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
double length(const Vec3d& a) { return std::sqrt(dot(a, a)); }
Vec3d cross(const Vec3d& a, const Vec3d& b) {
    return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
Vec3d to_d(const Vec3f& v) { return {v.x, v.y, v.z}; }
Vec3f to_f(const Vec3d& v) {
    return {static_cast<float>(v.x), static_cast<float>(v.y), static_cast<float>(v.z)};
}

double sign(double v) { return v > 0 ? 1.0 : (v < 0 ? -1.0 : 0.0); }

/// Steffen's slope at a key from the secants d0 (from the previous key, over h0 seconds) and d1
/// (to the next, over h1): the slope of the parabola through the three keys, limited to twice
/// the smaller secant, and zero where the secants differ in sign (the key is an extreme).
/// M. Steffen, "A simple method for monotonic interpolation in one dimension", A&A 239 (1990).
double steffen_slope(double d0, double d1, double h0, double h1) {
    const double parabola = (d0 * h1 + d1 * h0) / (h0 + h1);
    return (sign(d0) + sign(d1)) * std::min({std::abs(d0), std::abs(d1), 0.5 * std::abs(parabola)});
}

struct Frame {
    Vec3d dir;  ///< unit view direction
    Vec3d up;   ///< unit, orthogonal to dir
    double view_length = 0;
    double up_sine = 0;  ///< |cross(dir, unit up)| before orthogonalisation
    double up_length = 0;
};

/// Orthonormalises the interpolated values. Lengths are reported so callers can tell how close
/// to degenerate the camera is.
Frame make_frame(const Vec3d& eye, const Vec3d& target, const Vec3d& up) {
    Frame f;
    const Vec3d view = target - eye;
    f.view_length = length(view);
    f.up_length = length(up);
    if (!(f.view_length > 0) || !(f.up_length > 0)) return f;
    f.dir = view * (1.0 / f.view_length);
    const Vec3d u = up * (1.0 / f.up_length);
    f.up_sine = length(cross(f.dir, u));
    const Vec3d ortho = u - f.dir * dot(u, f.dir);
    const double ortho_len = length(ortho);
    if (ortho_len > 0) f.up = ortho * (1.0 / ortho_len);
    return f;
}

}  // namespace

CameraSpec camera_spec(const CameraPose& pose) {
    const Vec3d eye = to_d(pose.eye);
    const Frame f = make_frame(eye, to_d(pose.target), to_d(pose.up));
    if (!(f.view_length > 0)) throw Error("camera: eye and target are the same point");
    if (!(f.up_sine > kMinUpSine)) throw Error("camera: up is parallel to the view direction");
    const double distance = 1.0 / portable::tan(0.5 * pose.fov * kDegrees);
    const Vec3d gaze = {eye.x + f.dir.x * distance, eye.y + f.dir.y * distance,
                        eye.z + f.dir.z * distance};
    return {pose.eye, to_f(gaze), to_f(f.up)};
}

CameraPath::CameraPath(std::vector<CameraKey> keys, std::optional<double> loop_period,
                       std::string source)
    : keys_(std::move(keys)), period_(loop_period), source_(std::move(source)) {
    const std::size_t n = keys_.size();
    if (n == 0) throw Error(fmt::format("{}: no camera keys", source_));
    for (std::size_t i = 0; i < n; ++i) {
        const CameraKey& k = keys_[i];
        auto fail = [&](const std::string& message) { throw_at(source_, k.line, message); };
        if (!std::isfinite(k.time)) fail("key time is not a finite number");
        // Within these ranges the spline's arithmetic cannot overflow: tangents are differences
        // over time gaps, so a gap of 1e-308 s or a span of 2e308 s would give infinities.
        if (!(std::abs(k.time) <= kMaxKeyTime))
            fail(fmt::format("key time {} s is outside -1e9..1e9 s", k.time));
        if (i > 0 && !(k.time > keys_[i - 1].time))
            fail(fmt::format(
                "key times must increase: {} s comes after {} s{}", k.time, keys_[i - 1].time,
                keys_[i - 1].line ? fmt::format(" (line {})", keys_[i - 1].line) : ""));
        if (i > 0 && !(k.time - keys_[i - 1].time >= kMinKeyGap))
            fail(fmt::format(
                "key times must be at least 1 microsecond apart: {} s comes {} s after {} s",
                k.time, k.time - keys_[i - 1].time, keys_[i - 1].time));
        if (!is_finite(k.eye) || !is_finite(k.target) || !is_finite(k.up) || !std::isfinite(k.fov))
            fail("key has a value that is not finite");
        for (const Vec3f* v : {&k.eye, &k.target, &k.up})
            for (int c = 0; c < 3; ++c)
                if (!(std::abs((*v)[c]) <= kMaxKeyValue))
                    fail(fmt::format("key value {} is outside -1e15..1e15", (*v)[c]));
        if (!(k.fov > 1.0f && k.fov < 179.0f))
            fail(fmt::format("fov {} degrees is outside (1, 179)", k.fov));
        const Frame f = make_frame(to_d(k.eye), to_d(k.target), to_d(k.up));
        if (!(f.view_length > 1e-6)) fail("eye and target are the same point");
        if (!(f.up_length > 1e-6)) fail("up vector is zero");
        if (!(f.up_sine > kMinUpSine)) fail("up is parallel to the view direction (eye to target)");
    }
    if (period_) {
        const double span = keys_.back().time - keys_.front().time;
        if (!std::isfinite(*period_) || !(*period_ > span))
            throw Error(located(source_, 0,
                                fmt::format("loop period {} s must be longer than the keys' span "
                                            "{} s: after the last key the path returns to the "
                                            "first (leave out a closing key equal to the first)",
                                            *period_, span)));
        if (!(*period_ - span >= kMinKeyGap) || !(*period_ <= 2 * kMaxKeyTime))
            throw Error(
                located(source_, 0,
                        fmt::format("loop period {} s must exceed the keys' span {} s by at "
                                    "least 1 microsecond and be at most 2e9 s",
                                    *period_, span)));
    }

    values_.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
        const CameraKey& k = keys_[i];
        // Up is interpolated as a unit vector (then renormalised), so keys written as "0 2 0"
        // and "0 1 0" weigh the same.
        const Vec3d up = to_d(k.up) * (1.0 / length(to_d(k.up)));
        values_[i] = {k.eye.x,    k.eye.y, k.eye.z, k.target.x, k.target.y,
                      k.target.z, up.x,    up.y,    up.z,       k.fov};
    }

    // Tangents. The neighbours of a key and the time to them; around the wrap of a loop, the
    // last key's next is the first, one period later.
    tangents_.assign(n, Values{});
    for (std::size_t i = 0; i < n; ++i) {
        const bool has_prev = i > 0 || (period_ && n > 1);
        const bool has_next = i + 1 < n || (period_ && n > 1);
        if (!has_prev || !has_next) continue;  // ends of an open path start and stop at rest
        const std::size_t prev = i > 0 ? i - 1 : n - 1;
        const std::size_t next = i + 1 < n ? i + 1 : 0;
        const double h0 =
            i > 0 ? keys_[i].time - keys_[prev].time : keys_[i].time + *period_ - keys_[prev].time;
        const double h1 = i + 1 < n ? keys_[next].time - keys_[i].time
                                    : keys_[next].time + *period_ - keys_[i].time;
        for (int c = 0; c < kChannels; ++c) {
            const double d0 = (values_[i][c] - values_[prev][c]) / h0;
            const double d1 = (values_[next][c] - values_[i][c]) / h1;
            tangents_[i][c] = steffen_slope(d0, d1, h0, h1);
        }
    }
    validate_between_keys();
}

CameraPath::Values CameraPath::values_at(double time) const {
    const std::size_t n = keys_.size();
    if (n == 0) throw Error(fmt::format("{}: no camera keys", source_));
    const double t0 = keys_.front().time;
    double t = time;
    if (!std::isfinite(t)) return values_.front();  // hold the first key rather than spread NaN
    if (period_) {
        t = t0 + std::fmod(time - t0, *period_);
        if (t < t0) t += *period_;
    } else if (t <= t0) {
        return values_.front();
    } else if (t >= keys_.back().time) {
        return values_.back();
    }
    if (n == 1) return values_.front();

    // The segment [a, b] holding t: the last key at or before t, and the one after (for a loop,
    // after the last key comes the first, one period later).
    const auto it = std::upper_bound(keys_.begin(), keys_.end(), t,
                                     [](double v, const CameraKey& k) { return v < k.time; });
    const std::size_t a = static_cast<std::size_t>(it - keys_.begin()) - 1;
    const std::size_t b = a + 1 < n ? a + 1 : 0;
    const double ta = keys_[a].time;
    const double tb = a + 1 < n ? keys_[b].time : t0 + *period_;
    const double h = tb - ta;
    const double s = std::clamp((t - ta) / h, 0.0, 1.0);
    const double s2 = s * s, s3 = s2 * s;
    const double h00 = 2 * s3 - 3 * s2 + 1, h10 = s3 - 2 * s2 + s;
    const double h01 = -2 * s3 + 3 * s2, h11 = s3 - s2;
    Values v;
    for (int c = 0; c < kChannels; ++c)
        v[c] = h00 * values_[a][c] + h10 * h * tangents_[a][c] + h01 * values_[b][c] +
               h11 * h * tangents_[b][c];
    return v;
}

CameraPose CameraPath::pose(double time) const {
    const Values v = values_at(time);
    const Vec3d eye{v[0], v[1], v[2]}, target{v[3], v[4], v[5]}, up{v[6], v[7], v[8]};
    const Frame f = make_frame(eye, target, up);
    CameraPose p;
    p.eye = to_f(eye);
    p.target = to_f(target);
    // validate_between_keys rules out a degenerate frame; keep the raw up if it ever happens
    // rather than return NaN.
    p.up = f.up_length > 0 && length(f.up) > 0 ? to_f(f.up) : to_f(up);
    p.fov = static_cast<float>(v[9]);
    return p;
}

void CameraPath::validate_between_keys() const {
    const std::size_t n = keys_.size();
    const std::size_t segments = period_ ? (n > 1 ? n : 0) : n - 1;
    constexpr int kSamples = 200;
    for (std::size_t i = 0; i < segments; ++i) {
        const std::size_t j = (i + 1) % n;
        const double ta = keys_[i].time;
        const double tb = i + 1 < n ? keys_[j].time : keys_.front().time + *period_;
        // Scale for "too close": the smaller eye-target distance of the two keys.
        const double view_a = length(to_d(keys_[i].target) - to_d(keys_[i].eye));
        const double view_b = length(to_d(keys_[j].target) - to_d(keys_[j].eye));
        const double min_view = 1e-3 * std::min(view_a, view_b);
        for (int k = 1; k < kSamples; ++k) {
            const double t = ta + (tb - ta) * k / kSamples;
            const Values v = values_at(t);
            const Frame f = make_frame({v[0], v[1], v[2]}, {v[3], v[4], v[5]}, {v[6], v[7], v[8]});
            std::string problem;
            if (!(f.view_length > min_view)) {
                problem = "the eye reaches the target";
            } else if (!(f.up_length > 1e-3)) {
                problem = "the up vector vanishes (the keys' ups point in opposite directions)";
            } else if (!(f.up_sine > kMinUpSine)) {
                problem = "up turns parallel to the view direction";
            }
            if (!problem.empty())
                throw_at(
                    source_, keys_[i].line,
                    fmt::format("between this key ({} s) and the next ({} s{}) {} near {:.3f} s; "
                                "add a key in between or change up",
                                ta, keys_[j].time,
                                keys_[j].line ? fmt::format(", line {}", keys_[j].line) : "",
                                problem, t));
        }
    }
}

// --- The text format ---------------------------------------------------------------------------

namespace {

struct Tokens {
    std::vector<std::string_view> words;
    std::size_t at = 0;
    [[nodiscard]] bool done() const { return at >= words.size(); }
    std::string_view next() { return words[at++]; }
    [[nodiscard]] std::string_view peek() const { return words[at]; }
};

bool is_field_word(std::string_view w) {
    return w == "eye" || w == "target" || w == "up" || w == "fov" || w == "key" || w == "loop";
}

class LineParser {
public:
    LineParser(std::string_view source, std::size_t line) : source_(source), line_(line) {}

    [[noreturn]] void fail(const std::string& message) const { throw_at(source_, line_, message); }

    double number(Tokens& t, std::string_view after, int count) const {
        if (t.done())
            fail(
                fmt::format("expected {} number{} after '{}'", count, count > 1 ? "s" : "", after));
        const std::string_view w = t.next();
        double v = 0;
        const char* end = w.data() + w.size();
        // from_chars rejects a leading '+'; accept it as people write it.
        const char* begin = w.size() > 1 && w[0] == '+' ? w.data() + 1 : w.data();
        auto [p, ec] = std::from_chars(begin, end, v);
        if (ec != std::errc() || p != end || !std::isfinite(v)) {
            if (is_field_word(w))
                fail(fmt::format("expected {} number{} after '{}', found '{}'", count,
                                 count > 1 ? "s" : "", after, w));
            fail(fmt::format("malformed number '{}' after '{}'", w, after));
        }
        return v;
    }

    Vec3f vec3(Tokens& t, std::string_view after) const {
        const double x = number(t, after, 3), y = number(t, after, 3), z = number(t, after, 3);
        return {static_cast<float>(x), static_cast<float>(y), static_cast<float>(z)};
    }

private:
    std::string_view source_;
    std::size_t line_;
};

}  // namespace

CameraPath parse_camera_path(std::string_view text, std::string_view source) {
    if (const std::size_t nul = text.find('\0'); nul != std::string_view::npos)
        throw_at(source,
                 1 + static_cast<std::size_t>(std::count(text.begin(), text.begin() + nul, '\n')),
                 "binary data (NUL byte): not a camera path file");
    std::vector<CameraKey> keys;
    std::optional<double> period;
    std::size_t loop_line = 0;
    Vec3f up{0, 1, 0};  // inherited from the previous key
    float fov = 45.0f;
    std::size_t line_number = 0;
    while (!text.empty()) {
        std::size_t nl = text.find('\n');
        std::string_view line = text.substr(0, nl);
        text.remove_prefix(nl == std::string_view::npos ? text.size() : nl + 1);
        ++line_number;
        if (std::size_t hash = line.find('#'); hash != std::string_view::npos)
            line = line.substr(0, hash);
        Tokens t;
        std::size_t i = 0;
        while (i < line.size()) {
            while (i < line.size() && std::isspace(static_cast<unsigned char>(line[i]))) ++i;
            std::size_t j = i;
            while (j < line.size() && !std::isspace(static_cast<unsigned char>(line[j]))) ++j;
            if (j > i) t.words.push_back(line.substr(i, j - i));
            i = j;
        }
        if (t.done()) continue;

        LineParser p(source, line_number);
        const std::string_view directive = t.next();
        if (directive == "loop") {
            if (period) p.fail(fmt::format("a second 'loop' (the first is on line {})", loop_line));
            period = p.number(t, "loop", 1);
            if (!(*period > 0)) p.fail(fmt::format("loop period {} s must be positive", *period));
            loop_line = line_number;
        } else if (directive == "key") {
            CameraKey key;
            key.line = line_number;
            key.time = p.number(t, "key", 1);
            key.up = up;
            key.fov = fov;
            bool have_eye = false, have_target = false, have_up = false, have_fov = false;
            while (!t.done()) {
                const std::string_view w = t.next();
                auto once = [&](bool& seen) {
                    if (seen) p.fail(fmt::format("'{}' given twice in one key", w));
                    seen = true;
                };
                if (w == "eye") {
                    once(have_eye);
                    key.eye = p.vec3(t, w);
                } else if (w == "target") {
                    once(have_target);
                    key.target = p.vec3(t, w);
                } else if (w == "up") {
                    once(have_up);
                    key.up = p.vec3(t, w);
                } else if (w == "fov") {
                    once(have_fov);
                    key.fov = static_cast<float>(p.number(t, w, 1));
                } else {
                    p.fail(fmt::format(
                        "unknown word '{}' in a key (expected eye, target, up or fov)", w));
                }
            }
            if (!have_eye || !have_target)
                p.fail(fmt::format("key at {} s needs {}", key.time,
                                   !have_eye && !have_target
                                       ? "an eye and a target"
                                       : (!have_eye ? "an eye" : "a target")));
            up = key.up;
            fov = key.fov;
            if (keys.size() >= limits().max_camera_keys)
                p.fail(
                    fmt::format("more than {} camera keys (the limit)", limits().max_camera_keys));
            keys.push_back(key);
        } else {
            p.fail(
                fmt::format("unknown word '{}' (a line is 'key ...' or 'loop PERIOD')", directive));
        }
        if (!t.done()) p.fail(fmt::format("unexpected '{}' at the end of the line", t.peek()));
    }
    if (keys.empty())
        throw Error(located(source, 0, "no camera keys (lines 'key TIME eye ... target ...')"));
    // Checked here too (CameraPath checks it again) to point at the loop line; unordered times
    // are left to CameraPath, which names the key.
    const bool increasing =
        std::adjacent_find(keys.begin(), keys.end(), [](const auto& a, const auto& b) {
            return !(b.time > a.time);
        }) == keys.end();
    if (period && increasing && !(*period > keys.back().time - keys.front().time))
        throw_at(source, loop_line,
                 fmt::format("loop period {} s must be longer than the keys' span {} s: after the "
                             "last key the path returns to the first (leave out a closing key "
                             "equal to the first)",
                             *period, keys.back().time - keys.front().time));
    return CameraPath(std::move(keys), period, std::string(source));
}

CameraPath load_camera_path(const std::filesystem::path& path) {
    return parse_camera_path(read_file(path), path.string());
}

}  // namespace toonray
