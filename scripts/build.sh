#!/usr/bin/env bash
# Configures and builds toonray in Release mode into build/ (or $TOONRAY_BUILD_DIR), through
# ccache when it is installed. Extra arguments go to cmake.
set -euo pipefail
cd "$(dirname "$0")/.."
build_dir="${TOONRAY_BUILD_DIR:-build}"
launcher=()
if command -v ccache >/dev/null; then launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache); fi
cmake -S . -B "$build_dir" -G Ninja -DCMAKE_BUILD_TYPE=Release "${launcher[@]}" "$@"
cmake --build "$build_dir" --parallel "$(nproc)"
