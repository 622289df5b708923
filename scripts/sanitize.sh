#!/usr/bin/env bash
# Builds toonray with clang-14, AddressSanitizer, UndefinedBehaviorSanitizer and libFuzzer's
# coverage hooks in build-clang/ (the `clang` CMake preset) and runs the whole unit-test suite
# under them (docs/robustness.md). The same build holds the fuzzers that scripts/fuzz.sh runs,
# and is the project's clang build: one build of the sources serves the three. The Python module
# is not built here: it loads into the system's Python, which is not built with the sanitizers
# (their runtime must be the first library a process loads); it is a thin layer over the
# library that these tests run under the sanitizers.
#
#   scripts/sanitize.sh [extra ctest arguments]
#
# Every sanitizer report is fatal, so a test that triggers one fails. Leaks are reported
# (LeakSanitizer) and fail the test too. The libstdc++ assertions (_GLIBCXX_ASSERTIONS) check
# container bounds as well. The slurm and blender labels are left out: they test integration
# with outside programs (a Slurm cluster the test starts as root, and Blender), need root,
# daemons or a 200 MB program, and take minutes; toonray's own code in them is the same CLI
# the robustness and cli suites already run here.
set -euo pipefail
cd "$(dirname "$0")/.."

launcher=()
if command -v ccache >/dev/null; then launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache); fi

echo "sanitize: configuring build-clang"
cmake --preset clang "${launcher[@]}" >/dev/null

# Test discovery runs the test binaries, so the sanitizer options apply from the build on (the
# test preset sets the same ones for ctest).
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=1:detect_stack_use_after_return=1:check_initialization_order=1:strict_init_order=1}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
export LSAN_OPTIONS=${LSAN_OPTIONS:-suppressions=$(pwd)/scripts/lsan.supp:print_suppressions=0}

# One compile per core: ninja's default (cores + 2) only adds memory and task switching on a
# 2-core machine shared with other work.
echo "sanitize: building (clang-14, ASan + UBSan)"
ninja -C build-clang -j "$(nproc)"

echo "sanitize: running the tests (all but the slurm and blender labels)"
ctest --preset clang --parallel "$(nproc)" "$@"
