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
#   scale      bench/scale.py: frame time from 10k to 4M triangles and from 720p to 4K (table,
#              CSV and an SVG plot)
#   animation  bench/animation.py: 2,229 piano frames, `toonray batch` over OBJ files and
#              `toonray piano` in memory (exports 4.7 GB of OBJ files once, into build-bench/)
#
#   bash bench/run.sh                     # all four parts (about 20 minutes on 2 cores)
#   bash bench/run.sh stages rays         # some parts
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

quick=0
parts=()
for arg in "$@"; do
    case "$arg" in
        --quick) quick=1 ;;
        stages | rays | scale | animation) parts+=("$arg") ;;
        *) echo "run.sh: unknown argument '$arg' (parts: stages rays scale animation; --quick)" >&2; exit 2 ;;
    esac
done
[ ${#parts[@]} -gt 0 ] || parts=(stages rays scale animation)

mkdir -p "$build"
cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release \
    -DTOONRAY_BUILD_BENCH=ON -DTOONRAY_BUILD_TESTS=OFF >"$build/configure.log" 2>&1 ||
    { cat "$build/configure.log"; exit 1; }
targets=(toonray_cli toonray_bench)
if grep -q "Embree .* found" "$build/configure.log"; then targets+=(toonray_accel_bench); fi
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
for part in "${parts[@]}"; do
    echo "== $part"
    case "$part" in
        stages)
            mkdir -p "$build/bench/stages"
            if [ $quick = 1 ]; then
                "$build/bench/toonray_bench" --quick --work-dir "$build/bench/stages"
            else
                # The teapot and the generated 35k scene, then the scenes of issue #6's frame and
                # scale targets: a piano frame (34,476 triangles, exported by the CLI) and the
                # 1M-triangle sphere of bench/scale.py.
                scenes=("$root/tests/data/teapot.obj"
                        "$("$build/bench/toonray_bench" --generate "$build/bench/stages" | grep scene35k)")
                piano="$build/bench/stages/piano/keys_000001.obj"
                [ -f "$piano" ] || "$cli" piano --export-obj "$(dirname "$piano")" --start 6 --seconds 0.04 --quiet
                sphere=$(python3 "$root/bench/scale.py" --write-sphere 1000000 --work-dir "$build/bench/scale")
                scenes+=("$piano" "$sphere")
                "$build/bench/toonray_bench" --repeats "$repeats" --work-dir "$build/bench/stages" \
                    --markdown "$results/stages.md" "${scenes[@]}"
                { echo "## Stages"; echo; cat "$results/stages.md"; echo; } >>"$report"
            fi ;;
        rays)
            if [ ! -x "$build/bench/toonray_accel_bench" ]; then
                echo "run.sh: Embree is not installed (libembree-dev): skipping the ray benchmark" >&2
                continue
            fi
            if [ $quick = 1 ]; then
                "$build/bench/toonray_accel_bench" --quick
            else
                "$build/bench/toonray_accel_bench" --repeats "$repeats" | tee "$results/rays.txt"
                { echo "## Rays and BVH build against Embree"; echo;
                  sed -n '/^Mrays\/s (one thread/,$p' "$results/rays.txt"; echo; } >>"$report"
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
            python3 "$root/bench/animation.py" --toonray "$cli" --work-dir "$build/bench/animation" \
                --frames "$frames" --markdown "$results/animation.md"
            { echo "## Animation"; echo; cat "$results/animation.md"; echo; } >>"$report" ;;
    esac
done
echo
echo "results in $results/ (results.md has every table)"
