#!/usr/bin/env bash
# The README's test command: installs dependencies, builds, and runs every test.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
bash scripts/build.sh
ctest --test-dir "${TOONRAY_BUILD_DIR:-build}" --output-on-failure --parallel "$(nproc)" --timeout 900
