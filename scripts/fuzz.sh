#!/usr/bin/env bash
# Builds the libFuzzer targets (fuzz/, clang with ASan + UBSan) and runs each for a while.
#
#   scripts/fuzz.sh [SECONDS] [TARGET...]
#
# SECONDS per target (default 60); TARGETs default to all: obj mtl camera note_script midi
# camera_path options png render shading. Before fuzzing, every target replays its seeds and the inputs
# that once crashed it (tests/robustness/data/fuzz/TARGET). Fails (exit 1) on any crash, leak,
# timeout (an input running over 10 s) or out-of-memory (over 2 GiB) and leaves the input in
# build-fuzz/artifacts/TARGET/; replay it with `build-fuzz/fuzz_TARGET FILE`.
#
# Environment: TOONRAY_FUZZ_BUILD_DIR (default build-fuzz), TOONRAY_FUZZ_PARALLEL (targets run
# at once, default: the number of cores), CXX (default clang++-14, else clang++).
# The working corpus grows in BUILD_DIR/corpus/TARGET and is kept between runs; the committed
# seeds in fuzz/corpus/TARGET are never written.
set -euo pipefail
cd "$(dirname "$0")/.."
root=$(pwd)

seconds=${1:-60}
shift || true
all_targets=(obj mtl camera note_script midi camera_path options png render shading)
targets=("$@")
[ ${#targets[@]} -gt 0 ] || targets=("${all_targets[@]}")
build=${TOONRAY_FUZZ_BUILD_DIR:-build-fuzz}
parallel=${TOONRAY_FUZZ_PARALLEL:-$(nproc)}

if [ -z "${CXX:-}" ]; then
  if command -v clang++-14 >/dev/null; then CXX=clang++-14; else CXX=clang++; fi
fi
command -v "$CXX" >/dev/null || {
  echo "fuzz: $CXX not found; install clang-14 libclang-rt-14-dev llvm-14" >&2
  exit 1
}

echo "fuzz: building the fuzzers in $build with $CXX"
cmake -S fuzz -B "$build" -G Ninja -DCMAKE_CXX_COMPILER="$CXX" >/dev/null
ninja -C "$build" $(printf 'fuzz_%s ' "${targets[@]}") >/dev/null

echo "fuzz: replaying seeds and past crashes"
ctest --test-dir "$build" -L fuzz --output-on-failure --parallel "$parallel" \
  -R "^fuzz_($(IFS='|'; echo "${targets[*]}"))_replay\$"

export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:allocator_may_return_null=0}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}

run_target() {
  local t=$1
  local corpus="$build/corpus/$t" artifacts="$build/artifacts/$t" log="$build/logs/$t.log"
  mkdir -p "$corpus" "$artifacts" "$(dirname "$log")"
  local inputs=("$corpus" "fuzz/corpus/$t")
  [ -d "tests/robustness/data/fuzz/$t" ] && inputs+=("tests/robustness/data/fuzz/$t")
  local dict=()
  [ -f "fuzz/dict/$t.dict" ] && dict=(-dict="fuzz/dict/$t.dict")
  # Only the first directory (the working corpus) receives new inputs.
  if "$build/fuzz_$t" -max_total_time="$seconds" -max_len=8192 -timeout=10 -rss_limit_mb=2048 -malloc_limit_mb=2048 \
       -print_final_stats=1 -artifact_prefix="$artifacts/" "${dict[@]}" "${inputs[@]}" >"$log" 2>&1; then
    local runs rate
    runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
    rate=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$log" | tail -1)
    printf 'fuzz: %-12s ok  %6s s  %10s runs  %7s exec/s  corpus %s\n' "$t" "$seconds" "${runs:-?}" \
      "${rate:-?}" "$(ls "$corpus" | wc -l)"
  else
    printf 'fuzz: %-12s FAILED (log: %s)\n' "$t" "$log"
    grep -E "ERROR|FUZZ_CHECK|runtime error|SUMMARY|Test unit written|timeout|out-of-memory" "$log" | head -20 | sed 's/^/    /'
    return 1
  fi
}

echo "fuzz: ${#targets[@]} targets, $seconds s each, $parallel at a time"
status=0
pids=()
names=()
for t in "${targets[@]}"; do
  run_target "$t" &
  pids+=($!)
  names+=("$t")
  if [ ${#pids[@]} -ge "$parallel" ]; then
    wait "${pids[0]}" || status=1
    pids=("${pids[@]:1}")
    names=("${names[@]:1}")
  fi
done
for p in "${pids[@]}"; do wait "$p" || status=1; done
if [ $status -ne 0 ]; then
  echo "fuzz: FAILED: crashing inputs are in $build/artifacts/; add each to tests/robustness/data/fuzz/TARGET once fixed" >&2
else
  echo "fuzz: all targets passed"
fi
exit $status
