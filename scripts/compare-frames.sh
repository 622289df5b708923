#!/usr/bin/env bash
# Renders the same frames with every build and instruction set at hand and compares the PNGs
# byte for byte (docs/cluster.md, "Mixed clusters"): the x86-64 build with each accelerator
# kernel the CPU runs (TOONRAY_ACCEL_ISA = sse4.2, avx2, avx512) and, when given, the aarch64
# build under qemu-aarch64. Scenes: the teapot, spot, tests/data/scene/mixed.obj (several
# materials), a piano frame exported by each build itself (so its OBJ, which piano posing
# computes, is compared too) and tests/data/gltf/instances.gltf (instances through the two-level
# BVH), in the three line modes (classic, robust, ink), and with shadows and the specular band.
#
# Usage: scripts/compare-frames.sh [X86_BUILD_DIR [AARCH64_BUILD_DIR]]   (default: build, none)
# Environment: TOONRAY_COMPARE_DIR, where the frames go (default: a temporary directory, removed
# when everything matches); TOONRAY_COMPARE_SIZE (default 640x360).
# Exit status 1 when any file differs, naming each one.
set -euo pipefail
cd "$(dirname "$0")/.."

x86_build=${1:-build}
arm_build=${2:-}
size=${TOONRAY_COMPARE_SIZE:-640x360}
out=${TOONRAY_COMPARE_DIR:-$(mktemp -d /tmp/toonray-frames.XXXXXX)}
mkdir -p "$out"

# The configurations: NAME then the command prefix that runs toonray.
configs=()
runners=()
add_config() { configs+=("$1"); runners+=("$2"); }
flags=$(grep -m1 '^flags' /proc/cpuinfo 2>/dev/null || true)
has() { for f in "$@"; do [[ " $flags " == *" $f "* ]] || return 1; done; }
x86=$x86_build/apps/toonray
add_config x86-sse4.2 "env TOONRAY_ACCEL_ISA=sse4.2 $x86"
if has avx2 fma bmi1 bmi2; then add_config x86-avx2 "env TOONRAY_ACCEL_ISA=avx2 $x86"; fi
if has avx2 fma bmi1 bmi2 avx512f avx512vl avx512bw avx512dq; then
  add_config x86-avx512 "env TOONRAY_ACCEL_ISA=avx512 $x86"
fi
if [ -n "$arm_build" ]; then
  # The multiarch loader with the multiarch libc (cmake/aarch64-linux-gnu.cmake says why).
  qemu_prefix=/
  [ -e /lib/ld-linux-aarch64.so.1 ] || qemu_prefix=/usr/aarch64-linux-gnu
  add_config aarch64 "qemu-aarch64 -L $qemu_prefix $arm_build/apps/toonray"
fi

# The renders: NAME, scene ("piano" for the build's own piano export), options.
renders=(
  "teapot_robust|tests/data/teapot.obj|--edges robust"
  "teapot_classic|tests/data/teapot.obj|--edges classic"
  "spot_robust|tests/data/spot.obj|--edges robust"
  "spot_classic|tests/data/spot.obj|--edges classic"
  "mixed_robust|tests/data/scene/mixed.obj|--edges robust --shadows --specular --rim 0.3"
  "mixed_classic|tests/data/scene/mixed.obj|--edges classic --shadows --specular"
  "piano_robust|piano|--edges robust --shadows --specular"
  "piano_classic|piano|--edges classic"
  "teapot_ink|tests/data/teapot.obj|--edges ink"
  "piano_ink|piano|--edges ink --shadows"
  "instances_ink|tests/data/gltf/instances.gltf|--edges ink --shadows"
  "instances_robust|tests/data/gltf/instances.gltf|--edges robust --specular"
  "instances_classic|tests/data/gltf/instances.gltf|--edges classic --shadows"
)

for i in "${!configs[@]}"; do
  name=${configs[$i]}
  run=${runners[$i]}
  dir=$out/$name
  mkdir -p "$dir"
  start=$SECONDS
  # Frame 6 of a 0.25 s export from 4 s into the score (24 fps): keys and hammers in motion.
  $run piano --export-obj "$dir/piano" --start 4 --seconds 0.25 -q
  for r in "${renders[@]}"; do
    IFS='|' read -r rname scene opts <<<"$r"
    [ "$scene" = piano ] && scene=$dir/piano/keys_000006.obj
    # shellcheck disable=SC2086
    $run render "$scene" -o "$dir/$rname.png" --size "$size" $opts >/dev/null
  done
  echo "compare-frames: $name rendered in $((SECONDS - start)) s"
done

status=0
ref=${configs[0]}
for name in "${configs[@]:1}"; do
  for f in "$out/$ref"/*.png "$out/$ref"/piano/*; do
    rel=${f#"$out/$ref/"}
    if ! cmp -s "$f" "$out/$name/$rel"; then
      echo "compare-frames: DIFFERENT: $name/$rel vs $ref/$rel"
      status=1
    fi
  done
done
n=$(ls "$out/$ref"/*.png | wc -l)
if [ $status = 0 ]; then
  echo "compare-frames: ${#configs[@]} configurations (${configs[*]}), $n frames each and the piano OBJs: identical"
  [ -z "${TOONRAY_COMPARE_DIR:-}" ] && rm -rf "$out"
else
  echo "compare-frames: frames kept in $out"
fi
exit $status
