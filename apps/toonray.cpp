// toonray command line: parses arguments into options and calls the library. Errors from the
// library carry file and line; they are caught here once and printed.

#include <CLI/CLI.hpp>
#include <cstdio>
#include <fmt/format.h>
#include <optional>
#include <string>

#include <csignal>

#include "toonray/anim/batch.h"
#include "toonray/anim/demo.h"
#include "toonray/anim/piano_movie.h"
#include "toonray/media/audio.h"
#include "toonray/anim/progress.h"
#include "toonray/core/error.h"
#include "toonray/core/limits.h"
#include "toonray/core/parse.h"
#include "toonray/media/encode.h"
#include "toonray/score/score_io.h"
#include "toonray/render/render_file.h"

namespace {

using namespace toonray;

/// Options shared by every command that renders, kept as text until validated.
struct RenderArgs {
    std::string size = "1280x720";
    std::vector<std::string> lights;
    std::string lights_file;
    std::string ramp;
    bool shadows = false, specular = false, no_textures = false;
    float rim = 0.0f;
    std::string camera;
    std::string background = "1,1,1";
    std::string edges = "robust";
    float depth_threshold = 8.0f;
    float normal_threshold = 4.0f;
    std::string lines = "all";
    float crease_angle = RobustLineSettings{}.crease_angle;
    float depth_step = RobustLineSettings{}.depth_threshold;
    float line_width = RobustLineSettings{}.width;
    std::string line_colour = "0,0,0";
    int samples = RenderSettings{}.samples;
    int threads = 0;
    int leaf_size = Bvh::Config{}.max_leaf_size;
    int png_level = PngOptions{}.level;
    std::string aov_dir;

    void add_to(CLI::App& app) {
        app.add_option("--size", size, "Image size WIDTHxHEIGHT")->capture_default_str();
        app.add_option("--light", lights,
                       "A light, repeatable: x,y,z or point:x,y,z (a point light), dir:x,y,z (a directional "
                       "light shining along the vector), each with an optional @intensity (default: one "
                       "point light at the eye moved by half the scene radius along the camera's up and right)");
        app.add_option("--lights", lights_file,
                       "File of lights, one per line: point x y z [intensity] | directional x y z [intensity]")
            ->check(CLI::ExistingFile);
        app.add_option("--ramp", ramp,
                       "Toon bands LEVELS@THRESHOLDS, e.g. 0.5,0.75,1.0@0.25,0.5 (the seed's ramp, the default): "
                       "diffuse light below the first threshold gives the first level, and so on");
        app.add_flag("--shadows", shadows, "Toon shadows: lights blocked by geometry do not light a point");
        app.add_flag("--specular", specular, "A hard-edged highlight band from the material's Ks and Ns");
        app.add_option("--rim", rim, "Rim band width in [0,1) (0 = off): brightens surfaces seen edge-on")
            ->check(CLI::Range(0.0f, 0.99f))
            ->capture_default_str();
        app.add_flag("--no-textures", no_textures, "Ignore map_Kd textures");
        app.add_option("--camera", camera,
                       "Camera ex,ey,ez,gx,gy,gz,ux,uy,uz: eye, gaze point, up; overrides the "
                       "file's camera block (default: the block, else a camera framing the scene)");
        app.add_option("--background", background, "Background colour r,g,b in [0,1] or #rrggbb")
            ->capture_default_str();
        app.add_option("--edges", edges,
                       "Line mode: robust (supersampled, plane-aware, resolution-independent lines) or "
                       "classic (the seed's Sobel pipeline, exactly)")
            ->check(CLI::IsMember({"robust", "classic"}))
            ->capture_default_str();
        app.add_option("--lines", lines,
                       "Robust: line types to draw, from silhouette,crease,depth,object,material (or all, none)")
            ->capture_default_str();
        app.add_option("--crease-angle", crease_angle,
                       "Robust: angle in degrees between neighbouring surfaces above which a crease is drawn")
            ->check(CLI::Range(0.0f, 180.0f))
            ->capture_default_str();
        app.add_option("--depth-step", depth_step,
                       "Robust: relative jump in depth (second difference of 1/z over 1/z) that makes a depth line")
            ->check(CLI::PositiveNumber)
            ->capture_default_str();
        app.add_option("--line-width", line_width,
                       "Robust: line width in pixels at 720 lines; scales with the image height")
            ->check(CLI::Range(0.0f, 100.0f))
            ->capture_default_str();
        app.add_option("--line-color", line_colour, "Robust: line colour r,g,b in [0,1] or #rrggbb")
            ->capture_default_str();
        app.add_option("--samples", samples,
                       "Robust: samples per pixel on a regular grid (1, 4, 9 or 16); lines and colours are "
                       "filtered down from it")
            ->check(CLI::IsMember({1, 4, 9, 16}))
            ->capture_default_str();
        app.add_option("--depth-threshold", depth_threshold,
                       "Classic mode: Sobel magnitude on the 8-bit depth map above which a pixel is a line")
            ->capture_default_str();
        app.add_option("--normal-threshold", normal_threshold,
                       "Classic mode: Sobel magnitude on the 8-bit normal map above which a pixel is a line")
            ->capture_default_str();
        app.add_option("--aov", aov_dir,
                       "Also write feature images to this directory, named after the output: "
                       "NAME_depth, _normal, _edges, _cel .png, and per mode: classic _edges_depth, "
                       "_edges_normal; robust _lines_silhouette, _lines_crease, _lines_depth, _lines_object, "
                       "_lines_material, _object_id, _material_id");
        app.add_option("--threads", threads, "Threads to use (0 = all)")
            ->check(CLI::Range(0, 1024))
            ->capture_default_str();
        app.add_option("--bvh-leaf-size", leaf_size, "Largest number of triangles in a BVH leaf")
            ->check(CLI::Range(1, 64))
            ->capture_default_str();
        app.add_option("--png-level", png_level, "PNG compression level, 1 (fast) to 12 (small)")
            ->check(CLI::Range(1, 12))
            ->capture_default_str();
    }

    FileRenderOptions resolve() const {
        FileRenderOptions o;
        ImageSize s = parse_image_size(size, "--size");
        o.settings.width = s.width;
        o.settings.height = s.height;
        for (const std::string& l : lights) o.settings.shading.lights.push_back(parse_light(l));
        if (!lights_file.empty()) {
            auto from_file = load_lights(lights_file);
            o.settings.shading.lights.insert(o.settings.shading.lights.end(), from_file.begin(), from_file.end());
        }
        if (!ramp.empty()) o.settings.shading.ramp = parse_ramp(ramp);
        o.settings.shading.shadows = shadows;
        o.settings.shading.specular = specular;
        o.settings.shading.rim = rim;
        o.settings.shading.textures = !no_textures;
        if (!camera.empty()) o.camera = parse_camera_spec(camera);
        o.settings.background = parse_colour(background, "--background");
        o.settings.edges = edges == "classic" ? EdgeMode::Classic : EdgeMode::Robust;
        o.settings.lines.types = parse_line_types(lines);
        o.settings.lines.crease_angle = crease_angle;
        o.settings.lines.depth_threshold = depth_step;
        o.settings.lines.width = line_width;
        o.settings.lines.colour = parse_colour(line_colour, "--line-color");
        o.settings.samples = samples;
        o.settings.depth_threshold = depth_threshold;
        o.settings.normal_threshold = normal_threshold;
        o.settings.threads = threads;
        o.bvh.max_leaf_size = leaf_size;
        o.png.level = png_level;
        if (!aov_dir.empty()) o.aov_dir = aov_dir;
        return o;
    }
};

void print_warnings(const Warnings& warnings) {
    for (const auto& w : warnings) fmt::print(stderr, "toonray: warning: {}\n", w);
}

/// Limits on what inputs may ask for (docs/robustness.md), as text until validated.
struct LimitArgs {
    std::string triangles, vertices, pixels, memory, input_size;

    void add_to(CLI::App& app) {
        const Limits d;
        app.add_option("--max-triangles", triangles,
                       fmt::format("Largest scene, in triangles (default {}; k, M, G suffixes)", d.max_triangles))
            ->group("Limits");
        app.add_option("--max-vertices", vertices,
                       fmt::format("Most OBJ v, vn and vt statements, each (default {})", d.max_vertices))
            ->group("Limits");
        app.add_option("--max-image-pixels", pixels,
                       fmt::format("Largest image, width x height (default {} = 8192x8192)", d.max_image_pixels))
            ->group("Limits");
        app.add_option("--max-memory", memory,
                       "Memory the estimate of a run may reach (frame buffers and scenes of all frames in "
                       "flight), e.g. 4G (default: 3/4 of physical memory)")
            ->group("Limits");
        app.add_option("--max-input-size", input_size,
                       fmt::format("Largest input file: OBJ, MTL, score, camera path (default {})",
                                   format_bytes(d.max_input_bytes)))
            ->group("Limits");
    }

    /// Sets the process-wide limits; call before any work.
    void apply() const {
        Limits l = limits();
        if (!triangles.empty()) l.max_triangles = parse_count(triangles, "--max-triangles");
        if (!vertices.empty()) l.max_vertices = parse_count(vertices, "--max-vertices");
        if (!pixels.empty()) l.max_image_pixels = parse_count(pixels, "--max-image-pixels");
        if (!memory.empty()) l.max_memory = parse_bytes(memory, "--max-memory");
        if (!input_size.empty()) l.max_input_bytes = parse_bytes(input_size, "--max-input-size");
        set_limits(l);
    }
};

// Set by SIGINT/SIGTERM: long runs finish the frames in flight and stop.
std::atomic<bool> g_stop{false};

extern "C" void request_stop(int) { g_stop = true; }

void install_stop_handlers() {
    struct sigaction sa {};
    sa.sa_handler = request_stop;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGINT, &sa, nullptr);
    sigaction(SIGTERM, &sa, nullptr);
}

struct BatchArgs {
    std::string name;
    int first = 1, last = 1;
    std::string input = ".", output = ".";
    std::string pattern, output_pattern, shard;
    int jobs = 0;
    bool resume = false, fail_fast = false, quiet = false;

    void add_to(CLI::App& app) {
        app.add_option("name", name, "Animation name: frame N is read from NAME_NNNNNN.obj, "
                                     "NAME_NNNN.obj, NAMEN.obj or NAME_N.obj, the first that exists")
            ->required();
        app.add_option("first", first, "First frame number")->required()->check(CLI::NonNegativeNumber);
        app.add_option("last", last, "Last frame number (inclusive)")->required()->check(CLI::NonNegativeNumber);
        app.add_option("-i,--input", input, "Directory of the frame OBJ files")->capture_default_str();
        app.add_option("-o,--output", output, "Directory for the PNG frames (created if missing)")
            ->capture_default_str();
        app.add_option("--pattern", pattern, "Input file pattern, e.g. 'keys_%06d.obj'");
        app.add_option("--output-pattern", output_pattern, "Output file pattern (default: NAME_%06d.png)");
        app.add_option("--jobs", jobs, "Frames rendered at once (0 = one per core)")
            ->check(CLI::Range(0, 256))
            ->capture_default_str();
        app.add_option("--shard", shard,
                       "Render shard K of N (K/N): frames at positions K-1, K-1+N, ... of the range. "
                       "Default: from SLURM_ARRAY_TASK_ID/COUNT/MIN when set, else all frames");
        app.add_flag("--resume", resume, "Skip frames whose PNG already exists and is valid");
        app.add_flag("--fail-fast", fail_fast, "Stop at the first frame that fails");
        app.add_flag("-q,--quiet", quiet, "No progress output (failures are still reported)");
    }
};

}  // namespace

/// Progress of `toonray demo`: the frame bar, and a line per stage.
class DemoProgress : public DemoObserver {
public:
    DemoProgress(int frames, bool quiet) : frames_(frames, stderr, quiet), quiet_(quiet) {}
    void frame_done(int frame, FrameStatus status, const std::string& message) override {
        frames_.frame_done(frame, status, message);
    }
    void warning(int frame, const std::string& message) override { frames_.warning(frame, message); }
    void stage(const std::string& what) override {
        if (!quiet_) fmt::print(stderr, "toonray: demo: {}\n", what);
    }
    void finish(const BatchReport& report) { frames_.finish(report); }

private:
    ProgressReporter frames_;
    bool quiet_;
};

/// Options of `piano` and `demo`.
struct PianoArgs {
    std::string score, camera_path, soundfont, export_obj, audio;
    double start = 0.0, seconds = 0.0, fps = 24.0;
    std::string name = "keys";
    int jobs = 0;
    bool resume = false, quiet = false;

    void add_common(CLI::App& app) {
        app.add_option("--camera-path", camera_path,
                       "Camera path file (docs/camera-path.md; default: the built-in path)");
        app.add_option("--fps", fps, "Frames per second")->check(CLI::Range(0.001, 1000.0))->capture_default_str();
        app.add_option("--start", start, "Score time of the first frame, seconds")
            ->check(CLI::NonNegativeNumber)
            ->capture_default_str();
        app.add_option("--jobs", jobs, "Frames rendered at once (0 = one per core)")
            ->check(CLI::Range(0, 256))
            ->capture_default_str();
        app.add_option("--soundfont", soundfont, "SoundFont for the audio (default: FluidR3 GM)");
        app.add_flag("--resume", resume, "Skip frames whose PNG already exists and is valid");
        app.add_flag("-q,--quiet", quiet, "No progress output");
    }
};

Score load_score_or_demo(const std::string& path) {
    if (path.empty()) return load_demo_score();
    Warnings warnings;
    Score score = load_score(path, &warnings);
    print_warnings(warnings);
    return score;
}

PianoMovieReport run_piano_movie(const Score& score, const PianoArgs& args, PianoMovieOptions options) {
    CameraPath path = args.camera_path.empty() ? load_demo_camera_path() : load_camera_path(args.camera_path);
    options.start = args.start;
    options.fps = args.fps;
    options.jobs = args.jobs;
    options.resume = args.resume;
    install_stop_handlers();
    options.cancel = &g_stop;
    double seconds = options.seconds ? *options.seconds
                                     : std::max(0.0, (score.notes.empty() ? 0.0 : score.duration()) - options.start);
    ProgressReporter progress(frame_count(seconds, options.fps), stderr, args.quiet);
    PianoMovieReport report = render_piano_movie(score, path, options, &progress);
    progress.finish(report.batch);
    if (report.dropped_holes)
        fmt::print(stderr, "toonray: warning: {} roll holes did not fit the hole pool\n", report.dropped_holes);
    return report;
}

AudioOptions audio_options(const Score& score, const PianoArgs& args, std::optional<double> seconds) {
    AudioOptions audio;
    audio.soundfont = args.soundfont;
    audio.start = args.start;
    audio.length = seconds;
    // The soundtrack is synthesised in memory (16-bit stereo, then its WAV copy): a score that
    // lasts for days must fail here, not in an allocation.
    const double length = seconds ? *seconds : std::max(score.end_time, score.duration()) - args.start + 5.0;
    const double bytes = std::max(0.0, length) * audio.sample_rate * 2 * 2 * 2;
    check_memory(bytes < 1.8e19 ? static_cast<std::uint64_t>(bytes) : UINT64_MAX,
                 fmt::format("the soundtrack ({:.0f} s)", length));
    return audio;
}

int main(int argc, char** argv) {
    CLI::App app{"toonray: a toon ray tracer. OBJ/MTL scenes in, cel-shaded and outlined PNG out."};
    app.require_subcommand(1);
    app.set_version_flag("--version", "toonray 0.1.0");

    RenderArgs render_args;
    std::string render_input, render_output;
    CLI::App* render = app.add_subcommand("render", "Render one OBJ scene to a PNG image");
    render->add_option("scene", render_input, "OBJ file (with its camera block, if any)")
        ->required()
        ->check(CLI::ExistingFile);
    render->add_option("-o,--output", render_output, "Output PNG file")->required();
    render_args.add_to(*render);
    LimitArgs limit_args;  // one set, shared by the commands that read inputs
    limit_args.add_to(*render);

    RenderArgs batch_render_args;
    BatchArgs batch_args;
    CLI::App* batch = app.add_subcommand(
        "batch", "Render numbered frames NAME FIRST LAST to a PNG sequence (all render options apply)");
    batch_args.add_to(*batch);
    batch_render_args.add_to(*batch);
    limit_args.add_to(*batch);

    std::string encode_dir, encode_output, encode_audio;
    double encode_fps = 24.0;
    int encode_start = -1;
    CLI::App* encode = app.add_subcommand(
        "encode", "Compile a PNG sequence into an H.264 MP4 (yuv420p) with ffmpeg, optionally with audio");
    encode->add_option("frames", encode_dir, "Directory holding one numbered PNG sequence")
        ->required()
        ->check(CLI::ExistingDirectory);
    encode->add_option("-o,--output", encode_output, "MP4 file to write")->required();
    encode->add_option("--fps", encode_fps, "Frames per second")
        ->check(CLI::Range(0.001, 1000.0))
        ->capture_default_str();
    encode->add_option("--audio", encode_audio, "Soundtrack (WAV or anything ffmpeg reads), aligned with frame 0");
    encode->add_option("--start-number", encode_start, "First frame number (default: the lowest present)")
        ->check(CLI::NonNegativeNumber);

    std::string convert_input, convert_output;
    CLI::App* score = app.add_subcommand("score", "Work with scores (note scripts and MIDI files)");
    score->require_subcommand(1);
    CLI::App* convert = score->add_subcommand(
        "convert", "Convert between a MIDI file and a note script, losslessly where the script can say it "
                   "(the output's extension chooses: .mid/.midi or .notes)");
    convert->add_option("input", convert_input, "Score to read (MIDI or note script)")
        ->required()
        ->check(CLI::ExistingFile);
    convert->add_option("output", convert_output, "Score to write")->required();
    limit_args.add_to(*convert);

    PianoArgs piano_args;
    RenderArgs piano_render_args;
    std::string piano_output;
    CLI::App* piano = app.add_subcommand(
        "piano", "Render the procedural player piano playing a score, or export its frames as OBJ files");
    piano->add_option("--score", piano_args.score,
                      "Score: a MIDI file or a note script (default: the built-in Entertainer)");
    piano->add_option("-o,--output", piano_output, "Directory for the PNG frames");
    piano->add_option("--export-obj", piano_args.export_obj,
                      "Instead of rendering, write one OBJ + MTL per frame with its camera block to this "
                      "directory (render them with `toonray batch NAME 1 N`)");
    piano->add_option("--seconds", piano_args.seconds, "Length in seconds (default: to the end of the music)")
        ->check(CLI::PositiveNumber);
    piano->add_option("--name", piano_args.name, "Frame file name prefix")->capture_default_str();
    piano->add_option("--audio", piano_args.audio, "Also write the soundtrack of the same stretch to this WAV");
    piano_args.add_common(*piano);
    piano_render_args.add_to(*piano);
    limit_args.add_to(*piano);

    PianoArgs demo_args;
    RenderArgs demo_render_args;
    std::string demo_output = "out";
    bool demo_full = false;
    demo_args.seconds = 30.0;
    CLI::App* demo = app.add_subcommand(
        "demo", "The main job: a movie of the player piano playing Scott Joplin's \"The Entertainer\", "
                "with sound (frames in DIR/frames, DIR/entertainer.wav, DIR/entertainer.mp4)");
    demo->add_option("-o,--output", demo_output, "Output directory")->capture_default_str();
    demo->add_flag("--full", demo_full, "The whole piece (about 4 min 13 s) instead of the first seconds");
    demo->add_option("--seconds", demo_args.seconds, "Length in seconds")
        ->check(CLI::PositiveNumber)
        ->capture_default_str();
    demo->add_option("--score", demo_args.score, "Play another score (MIDI or note script)");
    demo_args.add_common(*demo);
    demo_render_args.add_to(*demo);
    limit_args.add_to(*demo);

    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        return app.exit(e);
    }

    try {
        limit_args.apply();
        if (*render) {
            FileRenderOptions options = render_args.resolve();
            {  // The frame buffers come first: the loader counts them in its memory estimate.
                Limits l = limits();
                l.reserved_memory = plan_frame_jobs(options.settings, 1, 1).frame_bytes;
                set_limits(l);
            }
            Warnings warnings;
            FileRenderer renderer;
            renderer.render(render_input, render_output, options, warnings);
            print_warnings(warnings);
        } else if (*batch) {
            BatchOptions options;
            options.name = batch_args.name;
            options.first = batch_args.first;
            options.last = batch_args.last;
            options.input_dir = batch_args.input;
            options.output_dir = batch_args.output;
            if (!batch_args.pattern.empty()) options.input_pattern = batch_args.pattern;
            if (!batch_args.output_pattern.empty()) options.output_pattern = batch_args.output_pattern;
            options.render = batch_render_args.resolve();
            options.jobs = batch_args.jobs;
            options.resume = batch_args.resume;
            options.fail_fast = batch_args.fail_fast;
            if (!batch_args.shard.empty()) {
                options.shard = parse_shard(batch_args.shard);
            } else if (auto slurm = shard_from_environment()) {
                options.shard = *slurm;
            }
            install_stop_handlers();
            options.cancel = &g_stop;
            auto frames = shard_frames(options.first, options.last, options.shard);
            ProgressReporter progress(static_cast<int>(frames.size()), stderr, batch_args.quiet);
            BatchReport report = run_batch(options, &progress);
            progress.finish(report);
            if (report.cancelled) return 130;
            return report.failed > 0 ? 1 : 0;
        } else if (*piano) {
            if (piano_output.empty() == piano_args.export_obj.empty())
                throw Error("piano: give exactly one of --output DIR (render PNG frames) or --export-obj DIR");
            Score score = load_score_or_demo(piano_args.score);
            PianoMovieOptions options;
            options.name = piano_args.name;
            options.output_dir = piano_output;
            if (!piano_args.export_obj.empty()) options.export_obj_dir = piano_args.export_obj;
            if (piano_args.seconds > 0) options.seconds = piano_args.seconds;
            options.render = piano_render_args.resolve();
            std::optional<AudioOptions> audio_opts;  // checked before the frames are rendered
            if (!piano_args.audio.empty()) audio_opts = audio_options(score, piano_args, options.seconds);
            PianoMovieReport report = run_piano_movie(score, piano_args, options);
            if (report.batch.cancelled) return 130;
            if (report.batch.failed > 0) return 1;
            if (audio_opts) {
                AudioResult audio = render_audio(score, piano_args.audio, *audio_opts);
                print_warnings(audio.warnings);
            }
        } else if (*demo) {
            Score score = load_score_or_demo(demo_args.score);
            CameraPath path = demo_args.camera_path.empty() ? load_demo_camera_path()
                                                            : load_camera_path(demo_args.camera_path);
            DemoOptions options;
            options.output_dir = demo_output;
            options.seconds = demo_full ? std::optional<double>() : std::optional<double>(demo_args.seconds);
            options.soundfont = demo_args.soundfont;
            options.movie.render = demo_render_args.resolve();
            options.movie.start = demo_args.start;
            options.movie.fps = demo_args.fps;
            options.movie.jobs = demo_args.jobs;
            options.movie.resume = demo_args.resume;
            install_stop_handlers();
            options.movie.cancel = &g_stop;
            double seconds = options.seconds ? *options.seconds : std::max(0.0, score.duration() - demo_args.start);
            // Checked before run_demo starts: the frame count (a score may last centuries) and
            // the soundtrack's memory.
            const int frames = checked_frame_count(seconds, demo_args.fps);
            (void)audio_options(score, demo_args, options.seconds);
            DemoProgress progress(frames, demo_args.quiet);
            DemoReport report = run_demo(score, path, options, &progress);
            progress.finish(report.movie.batch);
            if (report.movie.batch.cancelled) return 130;
            if (!report.completed) return 1;
            print_warnings(report.audio.warnings);
            fmt::print(stderr, "toonray: demo: wrote {} ({} frames, {:.1f} s, {} triangles)\n",
                       report.movie_path.string(), report.encode.frames.count, report.encode.duration,
                       report.movie.triangles);
        } else if (*convert) {
            Warnings warnings;
            convert_score(convert_input, convert_output, &warnings);
            print_warnings(warnings);
        } else if (*encode) {
            EncodeOptions options;
            options.frames_dir = encode_dir;
            options.output = encode_output;
            options.fps = encode_fps;
            options.audio = encode_audio;
            if (encode_start >= 0) options.start_number = encode_start;
            EncodeResult result = encode_video(options);
            fmt::print(stderr, "toonray: wrote {}: {} frames ({}), {:.2f} s{}\n", encode_output,
                       result.frames.count, result.frames.pattern(), result.duration,
                       encode_audio.empty() ? "" : ", with audio");
        }
    } catch (const Error& e) {
        fmt::print(stderr, "toonray: error: {}\n", e.what());
        return 1;
    } catch (const std::exception& e) {
        fmt::print(stderr, "toonray: error: {}\n", e.what());
        return 1;
    }
    return 0;
}
