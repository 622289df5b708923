#!/usr/bin/env bash
# The README's main command: installs dependencies, builds, and makes the demo movie:
# out/entertainer.mp4, the player piano playing the first 30 s of "The Entertainer", with sound.
# Extra arguments go to `toonray demo` (e.g. --full for the whole piece).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh demo
# The demo needs neither the tests nor the benchmarks (nor their libraries).
bash scripts/build.sh -DTOONRAY_BUILD_TESTS=OFF -DTOONRAY_BUILD_BENCH=OFF
./build/apps/toonray demo -o out "$@"
