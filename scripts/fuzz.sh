#!/usr/bin/env bash
# Builds the libFuzzer targets (fuzz/) in build-clang/ (the `clang` preset: clang-14 with ASan,
# UBSan and libFuzzer's coverage; scripts/sanitize.sh runs the unit tests in the same build) and
# runs each for a while.
#
#   scripts/fuzz.sh [--fast] [SECONDS] [TARGET...]
#
# --fast builds in build-fuzz-fast/ (the `fuzz-fast` preset: libFuzzer's coverage without the
# sanitizers): the render target runs about 4,000 inputs a second against 700, for long runs
# after wrong results (the checks the targets make themselves, such as the accelerator's
# exactness), which a sanitizer build meets only by luck. It finds no memory errors: run the
# default build too. Where this header says build-clang/, read build-fuzz-fast/ then.
#
# SECONDS per target (default 60); TARGETs default to all: obj mtl camera note_script midi
# camera_path options png render shading gltf glb line_style settings tone. Before fuzzing,
# every target replays its seeds and the inputs that once crashed it
# (tests/robustness/data/fuzz/TARGET). Fails (exit 1) on any crash, leak, timeout (an input
# running over TOONRAY_FUZZ_TIMEOUT, 10 s) or out-of-memory (over 2 GiB) and leaves the input in
# build-clang/artifacts/TARGET/; replay it with `build-clang/fuzz/fuzz_TARGET FILE`. Ends with a
# summary: per target the time, executions, executions per second, corpus size and result.
#
# CI (scripts/test.sh) runs every target for 20 s, two at a time. For long runs on a shared
# machine, take only idle CPU: `TOONRAY_FUZZ_TIMEOUT=60 nice -n 19 scripts/fuzz.sh 1800 obj render midi`.
#
# Environment: TOONRAY_FUZZ_PARALLEL (targets run at once, default: the number of cores),
# TOONRAY_FUZZ_TIMEOUT (seconds one input may run, default 10; libFuzzer measures wall time, so
# a niced run on a busy machine wants 60).
# The working corpus grows in build-clang/corpus/TARGET and is kept between runs; the committed
# seeds in fuzz/corpus/TARGET are never written.
set -euo pipefail
cd "$(dirname "$0")/.."

preset=clang
build=build-clang
if [ "${1:-}" = --fast ]; then
  preset=fuzz-fast
  build=build-fuzz-fast
  shift
fi
seconds=${1:-60}
shift || true
all_targets=(obj mtl camera note_script midi camera_path options png render shading gltf glb line_style settings tone)
targets=("$@")
[ ${#targets[@]} -gt 0 ] || targets=("${all_targets[@]}")
parallel=${TOONRAY_FUZZ_PARALLEL:-$(nproc)}
timeout=${TOONRAY_FUZZ_TIMEOUT:-10}

command -v clang++-14 >/dev/null || {
  echo "fuzz: clang++-14 not found; install clang-14 libclang-rt-14-dev llvm-14 (scripts/install-deps.sh does)" >&2
  exit 1
}

echo "fuzz: building the fuzzers in $build (the $preset preset)"
mkdir -p "$build"
# Runs of different targets may share the build directory (a long run of some targets while
# others are fuzzed); one build at a time, so that two ninjas never write the same files.
exec 9>"$build/build.lock"
flock 9
launcher=()
if command -v ccache >/dev/null; then launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache); fi
cmake --preset "$preset" "${launcher[@]}" >/dev/null
# Build output only on failure: the build is long and its warnings are the main build's.
if ! ninja -C "$build" -j "$(nproc)" $(printf 'fuzz_%s ' "${targets[@]}") >"$build/build.log" 2>&1; then
  tail -50 "$build/build.log" >&2
  echo "fuzz: build FAILED (full log: $build/build.log)" >&2
  exit 1
fi
exec 9>&-  # releases the lock

# Leaks are crashes too (ASan's default under libFuzzer, said here so that it stays so; the fast
# build has no ASan, and these are then unused).
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:allocator_may_return_null=0}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}

echo "fuzz: replaying seeds and past crashes"
ctest --test-dir "$build" -L fuzz --output-on-failure --parallel "$parallel" \
  -R "^fuzz_($(IFS='|'; echo "${targets[*]}"))_replay\$"

# One result file per target, so that runs of different targets may share the build directory.
results="$build/results"
mkdir -p "$results"
for t in "${targets[@]}"; do rm -f "$results/$t"; done

# Fuzzes one target; writes "time runs rate corpus result" to $results/TARGET.
run_target() {
  local t=$1
  local corpus="$build/corpus/$t" artifacts="$build/artifacts/$t" log="$build/logs/$t.log"
  mkdir -p "$corpus" "$artifacts" "$(dirname "$log")"
  local inputs=("$corpus" "fuzz/corpus/$t")
  [ -d "tests/robustness/data/fuzz/$t" ] && inputs+=("tests/robustness/data/fuzz/$t")
  local dict=()
  [ -f "fuzz/dict/$t.dict" ] && dict=(-dict="fuzz/dict/$t.dict")
  local start result=ok
  start=$(date +%s)
  # Only the first directory (the working corpus) receives new inputs.
  "$build/fuzz/fuzz_$t" -max_total_time="$seconds" -max_len=8192 -timeout="$timeout" -rss_limit_mb=2048 -malloc_limit_mb=2048 \
    -print_final_stats=1 -artifact_prefix="$artifacts/" "${dict[@]}" "${inputs[@]}" >"$log" 2>&1 || result=FAILED
  local elapsed=$(($(date +%s) - start)) runs rate
  runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
  rate=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$log" | tail -1)
  if [ -z "$runs" ]; then
    # No final statistics after a crash: take the last status line ("#RUNS ... exec/s: N ...").
    runs=$(grep -o '^#[0-9]*' "$log" | tail -1 | tr -d '#')
    rate=$(grep -o 'exec/s: [0-9]*' "$log" | tail -1 | sed 's/exec\/s: //')
  fi
  echo "$elapsed ${runs:-?} ${rate:-?} $(find "$corpus" -type f | wc -l) $result" >"$results/$t"
  if [ $result = ok ]; then
    printf 'fuzz: %-12s ok      %5s s  %10s runs  %6s exec/s\n' "$t" "$elapsed" "${runs:-?}" "${rate:-?}"
  else
    printf 'fuzz: %-12s FAILED after %s s (log: %s)\n' "$t" "$elapsed" "$log"
    grep -E "ERROR|FUZZ_CHECK|runtime error|SUMMARY|Test unit written|timeout|out-of-memory" "$log" | head -20 | sed 's/^/    /'
    return 1
  fi
}

echo "fuzz: ${#targets[@]} targets, $seconds s each, $parallel at a time"
status=0
pids=()
for t in "${targets[@]}"; do
  run_target "$t" &
  pids+=($!)
  if [ ${#pids[@]} -ge "$parallel" ]; then
    wait "${pids[0]}" || status=1
    pids=("${pids[@]:1}")
  fi
done
for p in "${pids[@]}"; do wait "$p" || status=1; done

echo
echo "fuzz: summary ($parallel targets at a time; exec/s is per target)"
printf '  %-12s %7s %12s %8s %8s  %s\n' target time executions exec/s corpus result
passed=0
for t in "${targets[@]}"; do
  read -r elapsed runs rate corpus result <"$results/$t" || { elapsed=? runs=? rate=? corpus=? result=FAILED; }
  printf '  %-12s %5s s %12s %8s %8s  %s\n' "$t" "$elapsed" "$runs" "$rate" "$corpus" "$result"
  [ "$result" != ok ] || passed=$((passed + 1))
done
echo "fuzz: $passed passed, $((${#targets[@]} - passed)) failed"
if [ $status -ne 0 ]; then
  echo "fuzz: FAILED: crashing inputs are in $build/artifacts/; add each to tests/robustness/data/fuzz/TARGET once fixed" >&2
else
  echo "fuzz: all targets passed"
fi
exit $status
