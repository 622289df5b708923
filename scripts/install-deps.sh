#!/usr/bin/env bash
# Installs the Debian packages toonray needs to build, test and run its demo.
set -euo pipefail

packages=(
  # build
  build-essential cmake ninja-build pkg-config
  # libraries
  libcli11-dev libfmt-dev libtbb-dev libdeflate-dev libpng-dev libfluidsynth-dev
  # tests and benchmarks
  libgtest-dev libgmock-dev libbenchmark-dev libtinyobjloader-dev libembree-dev
  # fuzzing (scripts/fuzz.sh): clang with libFuzzer and the sanitizer runtimes (libclang-rt is
  # only recommended by clang, so named here), and llvm-symbolizer for readable stack traces
  clang-14 libclang-rt-14-dev llvm-14
  # media: video encoding and the piano sound
  ffmpeg fluid-soundfont-gm
  # the cluster integration test starts a real one-node Slurm cluster
  slurm-wlm munge
  # the Blender add-on is tested in a real, headless Blender
  blender
)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages present"
  exit 0
fi

sudo=""
[ "$(id -u)" -eq 0 ] || sudo="sudo"
echo "install-deps: installing ${missing[*]}"
# apt's and dpkg's progress goes to a log, shown only if the install fails.
log=$(mktemp)
trap 'rm -f "$log"' EXIT
if ! { $sudo apt-get update -qq &&
       DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"; } >"$log" 2>&1; then
  cat "$log" >&2
  echo "install-deps: apt-get failed" >&2
  exit 1
fi
echo "install-deps: done"
