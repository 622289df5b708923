#!/usr/bin/env bash
# The benchmark in one command (docs/performance.md): configures an optimised build in
# build-bench/, builds the CLI and the benchmarks, and prints every table:
#
#   stages     toonray_bench: parse, BVH build, trace, shade, edges, PNG, whole frame, each
#              against its reference (tinyobjloader, Embree, libpng) on the teapot, the
#              generated 35k-triangle scene, a piano frame and a 1M-triangle sphere
#   rays       toonray_accel_bench: primary-ray throughput (single rays and tiles) and BVH build
#              against Embree's rtcIntersect1 / rtcIntersect8 and builder, on the teapot, a
#              70k-triangle mesh, the piano and a 1M-triangle sphere (needs libembree-dev)
#   frame      bench/frame.py: `toonray render` at 1280x720 on one thread, whole process, in the
#              default (ink), robust and classic modes, against toonray_reference_classic
#              (bench/reference_classic.cpp: tinyobjloader + Embree + libpng, the classic
#              pipeline), interleaved, medians of 5, on the generated 70k-triangle scan, the
#              teapot and a piano frame (needs libembree-dev)
#   memory     bench/frame.py memory: peak RSS of 4K and 8K default frames of a 65k-triangle
#              mesh and of 720p frames of one triangle
#   scale      bench/scale.py: frame time from 10k to 4M triangles and from 720p to 4K (table,
#              CSV and an SVG plot)
#   animation  bench/animation.py: 2,229 piano frames in the default and classic modes
#              (TOONRAY_ANIMATION_ROBUST=1 adds robust), `toonray batch` over OBJ files and
#              `toonray piano` in memory (exports 4.7 GB of OBJ files once, into build-bench/)
# results.md ends with a table of every target figure, met or missed (bench/summary.py).
#
#   bash bench/run.sh                     # all six parts (about 25 minutes on 2 cores)
#   bash bench/run.sh stages rays         # some parts
#   bash bench/run.sh frame bunny.obj     # OBJ files given are timed by the frame part too
#   bash bench/run.sh --quick             # correctness checks only, small (what CI runs)
#   TOONRAY_BENCH_REPEATS=31 bash bench/run.sh stages
#
# Everything is also written to build-bench/results/ (results.md with all tables,
# scale.csv, scale.svg). Timings on a shared machine are noisy: the tables report medians; run
# again on an idle machine for figures worth quoting.
set -euo pipefail

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${TOONRAY_BENCH_BUILD_DIR:-$root/build-bench}"
jobs="${TOONRAY_BENCH_JOBS:-$(nproc)}"
repeats="${TOONRAY_BENCH_REPEATS:-15}"
frame_repeats="${TOONRAY_BENCH_REPEATS:-5}"

quick=0
parts=()
extra_scenes=()
for arg in "$@"; do
    case "$arg" in
        --quick) quick=1 ;;
        stages | rays | frame | memory | scale | animation) parts+=("$arg") ;;
        *.obj) extra_scenes+=("$(realpath "$arg")") ;;
        *) echo "run.sh: unknown argument '$arg' (parts: stages rays frame memory scale animation; --quick; FILE.obj)" >&2; exit 2 ;;
    esac
done
[ ${#parts[@]} -gt 0 ] || parts=(stages rays frame memory scale animation)

mkdir -p "$build"
cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release \
    -DTOONRAY_BUILD_BENCH=ON -DTOONRAY_BUILD_TESTS=OFF >"$build/configure.log" 2>&1 ||
    { cat "$build/configure.log"; exit 1; }
targets=(toonray_cli toonray_bench)
if grep -q "Embree .* found" "$build/configure.log"; then
    targets+=(toonray_accel_bench toonray_reference_classic)
fi
cmake --build "$build" -j "$jobs" --target "${targets[@]}"

results="$build/results"
mkdir -p "$results"
report="$results/results.md"
{
    echo "# toonray benchmark results"
    echo
    echo "$(date -u '+%Y-%m-%d %H:%M UTC'), commit $(git -C "$root" rev-parse --short HEAD 2>/dev/null || echo unknown)$(git -C "$root" diff --quiet 2>/dev/null || echo ' (with uncommitted changes)'),"
    echo "$(grep -m1 'model name' /proc/cpuinfo | sed 's/.*: //'), $(nproc) hardware threads, load average $(cut -d' ' -f1-3 /proc/loadavg) at the start."
    echo
} >"$report"

cli="$build/apps/toonray"
reference="$build/bench/toonray_reference_classic"
# The generated scenes (scene35k.obj, scan70k.obj) and a piano frame (34,476 triangles, with its
# camera block), made once.
generated() { "$build/bench/toonray_bench" --generate "$build/bench/stages"; }
piano_frame() {
    local piano="$build/bench/stages/piano/keys_000001.obj"
    [ -f "$piano" ] || "$cli" piano --export-obj "$(dirname "$piano")" --start 6 --seconds 0.04 --quiet
    echo "$piano"
}
# The parts that need Embree (the reference programs) say so and are skipped without it.
have() {
    [ -x "$1" ] && return 0
    echo "run.sh: Embree is not installed (libembree-dev): skipping the $2 part" >&2
    return 1
}
for part in "${parts[@]}"; do
    echo "== $part"
    case "$part" in
        stages)
            mkdir -p "$build/bench/stages"
            if [ $quick = 1 ]; then
                "$build/bench/toonray_bench" --quick --work-dir "$build/bench/stages"
            else
                # The teapot and the generated 35k scene, then the scenes of the frame and
                # scale targets: a piano frame (34,476 triangles, exported by the CLI) and the
                # 1M-triangle sphere of bench/scale.py.
                scenes=("$root/tests/data/teapot.obj" "$(generated | grep scene35k)")
                sphere=$(python3 "$root/bench/scale.py" --write-sphere 1000000 --work-dir "$build/bench/scale")
                scenes+=("$(piano_frame)" "$sphere")
                "$build/bench/toonray_bench" --repeats "$repeats" --work-dir "$build/bench/stages" \
                    --markdown "$results/stages.md" "${scenes[@]}"
                { echo "## Stages"; echo; cat "$results/stages.md"; echo; } >>"$report"
            fi ;;
        rays)
            have "$build/bench/toonray_accel_bench" rays || continue
            if [ $quick = 1 ]; then
                "$build/bench/toonray_accel_bench" --quick --piano "$(piano_frame)"
            else
                "$build/bench/toonray_accel_bench" --repeats "$repeats" --piano "$(piano_frame)" |
                    tee "$results/rays.txt"
                { echo "## Rays and BVH build against Embree"; echo;
                  sed -n '/^Mrays\/s (one thread/,$p' "$results/rays.txt"; echo; } >>"$report"
            fi ;;
        frame)
            have "$reference" frame || continue
            scan="$(generated | grep scan70k)"
            if [ $quick = 1 ]; then
                python3 "$root/bench/frame.py" check --toonray "$cli" --reference "$reference" \
                    --work-dir "$build/bench/frame-check" "$scan" "$root/tests/data/teapot.obj"
            else
                python3 "$root/bench/frame.py" frame --toonray "$cli" --reference "$reference" \
                    --work-dir "$build/bench/frame" --repeats "$frame_repeats" \
                    --markdown "$results/frame.md" --json "$results/frame.json" \
                    "$scan" "$root/tests/data/teapot.obj" "$(piano_frame)" "${extra_scenes[@]}"
                { echo "## Frame against the reference"; echo; cat "$results/frame.md"; echo; } >>"$report"
            fi ;;
        memory)
            have "$reference" memory || continue
            quick_flag=()
            [ $quick = 1 ] && quick_flag=(--quick)
            python3 "$root/bench/frame.py" memory --toonray "$cli" --reference "$reference" \
                --work-dir "$build/bench/memory" "${quick_flag[@]}" \
                --markdown "$results/memory.md" --json "$results/memory.json"
            if [ $quick = 0 ]; then
                { echo "## Memory"; echo; cat "$results/memory.md"; echo; } >>"$report"
            fi ;;
        scale)
            if [ $quick = 1 ]; then
                python3 "$root/bench/scale.py" --toonray "$cli" --work-dir "$build/bench/scale" --quick
            else
                python3 "$root/bench/scale.py" --toonray "$cli" --work-dir "$build/bench/scale" \
                    --repeats "${TOONRAY_SCALE_REPEATS:-5}" --markdown "$results/scale.md" \
                    --csv "$results/scale.csv" --svg "$results/scale.svg"
                { echo "## Scale"; echo; cat "$results/scale.md"; echo; } >>"$report"
            fi ;;
        animation)
            frames=2229
            [ $quick = 1 ] && frames=24
            robust_flag=()
            [ "${TOONRAY_ANIMATION_ROBUST:-0}" = 1 ] && robust_flag=(--robust)
            python3 "$root/bench/animation.py" --toonray "$cli" --work-dir "$build/bench/animation" \
                --frames "$frames" --markdown "$results/animation.md" --json "$results/animation.json" \
                "${robust_flag[@]}"
            { echo "## Animation"; echo; cat "$results/animation.md"; echo; } >>"$report" ;;
    esac
done
if [ $quick = 0 ]; then
    python3 "$root/bench/summary.py" "$results" --parts "${parts[@]}" >"$results/targets.md"
    { echo "## Targets"; echo; cat "$results/targets.md"; echo; } >>"$report"
    echo
    echo "== targets"
    cat "$results/targets.md"
fi
echo
echo "results in $results/ (results.md has every table)"
