#!/usr/bin/env bash
# The README's main command: installs dependencies, builds, and runs the demo.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
bash scripts/build.sh
mkdir -p out
./build/apps/toonray render tests/data/teapot.obj -o out/teapot.png --aov out/aov
echo "demo: wrote out/teapot.png and its feature images in out/aov/"
