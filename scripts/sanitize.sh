#!/usr/bin/env bash
# Builds toonray with AddressSanitizer and UndefinedBehaviorSanitizer (gcc) in build-asan/ and
# runs the whole unit-test suite under them (docs/robustness.md). The Python module is not built
# here: it loads into the system's Python, which is not built with the sanitizers (their runtime
# must be the first library a process loads); it is a thin layer over the library that these
# tests run under the sanitizers.
#
#   scripts/sanitize.sh [extra ctest arguments]
#
# Every sanitizer report is fatal, so a test that triggers one fails. Leaks are reported
# (LeakSanitizer) and fail the test too. The libstdc++ assertions (_GLIBCXX_ASSERTIONS) check
# container bounds as well. The slurm and blender labels are left out: they test integration
# with outside programs (a Slurm cluster the test starts as root, and Blender), need root,
# daemons or a 200 MB program, and take minutes; toonray's own code in them is the same CLI
# the robustness and cli suites already run here.
#
# Environment: TOONRAY_ASAN_BUILD_DIR (default build-asan), CXX (default g++).
set -euo pipefail
cd "$(dirname "$0")/.."
build=${TOONRAY_ASAN_BUILD_DIR:-build-asan}
sanitizers="-fsanitize=address,undefined,float-cast-overflow -fno-sanitize-recover=all"

launcher=()
if command -v ccache >/dev/null; then launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache); fi

echo "sanitize: configuring $build"
cmake -S . -B "$build" -G Ninja "${launcher[@]}" -DTOONRAY_WARNINGS_AS_ERRORS=ON \
  -DCMAKE_CXX_COMPILER="${CXX:-g++}" \
  -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g" \
  -DCMAKE_CXX_FLAGS="$sanitizers -fno-omit-frame-pointer -D_GLIBCXX_ASSERTIONS" \
  -DCMAKE_EXE_LINKER_FLAGS="$sanitizers" \
  -DCMAKE_SHARED_LINKER_FLAGS="$sanitizers" \
  -DTOONRAY_BUILD_TESTS=ON -DTOONRAY_BUILD_BENCH=OFF -DTOONRAY_BUILD_PYTHON=OFF >/dev/null

# Test discovery runs the test binaries, so the sanitizer options apply from the build on.
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=1:detect_stack_use_after_return=1:check_initialization_order=1:strict_init_order=1}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
export LSAN_OPTIONS=${LSAN_OPTIONS:-suppressions=$(pwd)/scripts/lsan.supp:print_suppressions=0}

# One compile per core: ninja's default (cores + 2) only adds memory and task switching on a
# 2-core machine shared with other work.
echo "sanitize: building (ASan + UBSan)"
ninja -C "$build" -j "$(nproc)"

echo "sanitize: running the tests (all but the slurm and blender labels)"
ctest --test-dir "$build" --output-on-failure --parallel "$(nproc)" --timeout 900 -LE "slurm|blender" "$@"
