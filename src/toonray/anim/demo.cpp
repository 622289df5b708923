#include "toonray/anim/demo.h"

#include <fmt/format.h>

namespace toonray {

DemoReport run_demo(const Score& score, const CameraPath& camera_path, const DemoOptions& options,
                    DemoObserver* observer) {
    namespace fs = std::filesystem;
    DemoReport report;
    PianoMovieOptions movie = options.movie;
    movie.name = "entertainer";
    movie.output_dir = options.output_dir / "frames";
    movie.export_obj_dir.reset();
    movie.seconds = options.seconds;
    const double seconds =
        options.seconds ? *options.seconds : std::max(0.0, score.duration() - movie.start);
    const int frames = frame_count(seconds, movie.fps);

    // Frames from a longer earlier run would join the movie: remove them.
    std::error_code ec;
    for (int f = frames + 1;; ++f) {
        fs::path stale = movie.output_dir / fmt::format("entertainer_{:06d}.png", f);
        if (!fs::exists(stale, ec)) break;
        fs::remove(stale, ec);
    }

    if (observer) observer->stage(fmt::format("rendering {} frames", frames));
    report.movie = render_piano_movie(score, camera_path, movie, observer);
    if (report.movie.batch.cancelled || report.movie.batch.failed > 0) return report;

    if (observer) observer->stage("synthesising the audio");
    AudioOptions audio;
    audio.soundfont = options.soundfont;
    audio.start = movie.start;
    audio.length = options.seconds;
    report.audio_path = options.output_dir / "entertainer.wav";
    report.audio = render_audio(score, report.audio_path, audio);

    if (observer) observer->stage("encoding the movie");
    EncodeOptions encode;
    encode.frames_dir = movie.output_dir;
    encode.output = options.output_dir / "entertainer.mp4";
    encode.fps = movie.fps;
    encode.audio = report.audio_path;
    encode.start_number = 1;
    report.movie_path = encode.output;
    report.encode = encode_video(encode);
    report.completed = true;
    return report;
}

}  // namespace toonray
