#!/usr/bin/env bash
# What the aarch64 path of the SSE code costs, measured on x86 (docs/accel.md, "Other CPUs"):
# builds a copy of the CLI whose SSE translation units (core/simd_sse.h users: the sse4.2
# traversal kernels, tile ray directions, the classic line pipeline) use
# SIMDe's portable implementation (TOONRAY_SIMD_SIMDE, i.e. SIMDE_NO_NATIVE: plain C++ lane
# loops the compiler vectorises for x86-64-v2) instead of the intrinsics, and counts the
# instructions of the same renders with both under callgrind (one thread, sse4.2 kernels).
# Also checks that both give the same PNGs.
#
# Usage: scripts/measure-simde.sh [BUILD_DIR]   (a configured Release build; default build)
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build}
out=$(mktemp -d /tmp/toonray-simde.XXXXXX)
ninja -C "$build" toonray_cli >/dev/null

# Recompile the simd_sse.h users with -DTOONRAY_SIMD_SIMDE, as the build compiles them.
# (Not accel/bvh.cpp: TBB includes the x86 headers there, which SIMDe's aliases cannot replace.)
sources=(accel/kernels_sse.cpp render/trace.cpp render/classic.cpp)
objects=()
for s in "${sources[@]}"; do
  obj=$out/$(basename "$s").o
  cmd=$(python3 -c "
import json, re
for e in json.load(open('$build/compile_commands.json')):
    if e['file'].endswith('/src/toonray/$s'):
        print(re.sub(r' -o \S+ ', ' -DTOONRAY_SIMD_SIMDE -o $obj ', e['command'])); break")
  (cd "$build" && eval "$cmd")
  objects+=("$obj")
done
# Link a copy of the CLI with those objects in front of the libraries.
link=$(ninja -C "$build" -t commands apps/toonray | tail -n 1)
link=${link#: && }
link=${link%%&& :*}
link=${link/ -o apps\/toonray / -o $out\/toonray-simde ${objects[*]} }
(cd "$build" && eval "$link")

renders=(
  "tests/data/teapot.obj --edges classic"
  "tests/data/teapot.obj"
  "tests/data/spot.obj --shadows"
)
printf '%-42s %16s %16s %8s\n' render intrinsics simde ratio
for r in "${renders[@]}"; do
  counts=()
  for variant in native simde; do
    bin=$build/apps/toonray
    [ $variant = simde ] && bin=$out/toonray-simde
    # shellcheck disable=SC2086
    TOONRAY_ACCEL_ISA=sse4.2 valgrind --tool=callgrind --callgrind-out-file="$out/cg.$variant" \
      "$bin" render $r -o "$out/$variant.png" --size 640x360 --threads 1 >/dev/null 2>&1
    counts+=("$(grep -m1 '^summary:' "$out/cg.$variant" | awk '{print $2}')")
  done
  cmp -s "$out/native.png" "$out/simde.png" || { echo "measure-simde: $r: the PNGs differ" >&2; exit 1; }
  printf '%-42s %16s %16s %8s\n' "$r" "${counts[0]}" "${counts[1]}" \
    "$(python3 -c "print(f'{${counts[1]} / ${counts[0]}:.2f}')")"
done
rm -rf "$out"
