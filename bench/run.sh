#!/usr/bin/env bash
# The stage benchmark in one command: configures an optimised build in build-bench/, builds the
# benchmark and the CLI, and prints the per-stage table for the teapot and the generated
# 35k-triangle scene (docs/performance.md explains the rows).
#
#   bash bench/run.sh                 # 15 repeats, 1280x720
#   bash bench/run.sh --repeats 31    # any toonray_bench option is passed through
#   bash bench/run.sh --quick         # correctness checks only
#
# Timings on a shared machine are noisy: the table reports medians and half the interquartile
# range; run it again when the machine is idle for figures worth quoting.
set -euo pipefail

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="$root/build-bench"
jobs="${TOONRAY_BENCH_JOBS:-$(nproc)}"

mkdir -p "$build"
cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release \
    -DTOONRAY_BUILD_BENCH=ON -DTOONRAY_BUILD_TESTS=OFF >"$build/configure.log" 2>&1 ||
    { cat "$build/configure.log"; exit 1; }

cmake --build "$build" -j "$jobs" --target toonray_bench
# The end-to-end row times the real CLI. It links every module, some of which may be mid-change;
# without it the benchmark still runs and says the row was skipped.
if ! cmake --build "$build" -j "$jobs" --target toonray_cli >"$build/cli-build.log" 2>&1; then
    echo "run.sh: the CLI did not build (see $build/cli-build.log); the CLI row will be skipped" >&2
    rm -f "$build/apps/toonray"
fi

work="$build/bench"
mkdir -p "$work"
cd "$work"
"$build/bench/toonray_bench" --work-dir "$work" --markdown "$work/results.md" "$@"
echo
echo "table also written to $work/results.md"
