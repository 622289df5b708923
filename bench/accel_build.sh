#!/usr/bin/env bash
# Builds bench/accel_embree_compare by hand against a toonray build tree (default build-accel/):
#   bash bench/accel_build.sh [build-dir] [extra g++ flags...]
# then runs nothing; the binary is <build-dir>/accel_embree_compare. Needs libembree-dev.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${1:-$root/build-accel}"
shift || true
lib="$build/src/toonray"
g++ -std=c++20 -O3 -DNDEBUG -march=x86-64-v2 -ffp-contract=off "$@" -I"$root/src" \
    -DTOONRAY_SOURCE_DIR="\"$root\"" \
    "$root/bench/accel_embree_compare.cpp" "$root/bench/accel_legacy.cpp" \
    -o "$build/accel_embree_compare" \
    "$lib/libtoonray_render.a" "$lib/libtoonray_scene.a" "$lib/libtoonray_accel.a" \
    "$lib/libtoonray_io.a" "$lib/libtoonray_core.a" \
    -lembree3 -ltbb -lfmt -lpng -ldeflate -lpthread
echo "built $build/accel_embree_compare"
