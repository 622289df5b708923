#!/usr/bin/env bash
# The README's test command (and CI's): installs dependencies, builds, and runs every test; then
# the hardening checks of docs/robustness.md: the unit-test suite under ASan + UBSan
# (scripts/sanitize.sh) and every fuzz target for a short while (scripts/fuzz.sh), which also
# replays the inputs that once crashed them.
#
# Environment: TOONRAY_BUILD_DIR (default build), TOONRAY_ASAN_BUILD_DIR (build-asan),
# TOONRAY_FUZZ_BUILD_DIR (build-fuzz); TOONRAY_FUZZ_SECONDS, each target's fuzzing time (default
# 45: ten targets, two at a time, about 4 minutes); TOONRAY_TEST_HARDENING=0 skips the
# sanitizer and fuzz stages (15 to 20 minutes on an idle 2-core machine, mostly building) for a
# quick local run.
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
bash scripts/build.sh -DTOONRAY_BUILD_TESTS=ON -DTOONRAY_BUILD_BENCH=ON
stage_done "the Release build"
ctest --test-dir "${TOONRAY_BUILD_DIR:-build}" --output-on-failure --parallel "$(nproc)" --timeout 900
stage_done "the tests"

if [ "${TOONRAY_TEST_HARDENING:-1}" = 0 ]; then
  echo "test: sanitizer and fuzz stages skipped (TOONRAY_TEST_HARDENING=0)"
  exit 0
fi
bash scripts/sanitize.sh
stage_done "the sanitizer build and tests"
bash scripts/fuzz.sh "${TOONRAY_FUZZ_SECONDS:-45}"
stage_done "the fuzzer build and fuzzing"
