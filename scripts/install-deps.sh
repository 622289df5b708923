#!/usr/bin/env bash
# Installs the Debian packages toonray needs, by what they are needed for:
#
#   scripts/install-deps.sh demo      build toonray and make the demo movie (scripts/demo.sh)
#   scripts/install-deps.sh all       also everything the tests use (scripts/test.sh): the test
#                                     and benchmark libraries, clang, a real Slurm and a real
#                                     Blender, and the aarch64 cross build
#   scripts/install-deps.sh aarch64   the aarch64 cross compiler, qemu-user and the arm64
#                                     libraries (Debian multiarch), for the `aarch64` preset
#
# Packages already installed are skipped, so running it again is cheap.
set -euo pipefail

profile=${1:-all}

demo_packages=(
  # build
  build-essential cmake ninja-build pkg-config
  # libraries
  libcli11-dev libfmt-dev libtbb-dev libdeflate-dev libpng-dev libfluidsynth-dev
  # glTF scenes (tinygltf, its JSON and image headers) and multi-layer OpenEXR feature images
  libtinygltf-dev nlohmann-json3-dev libstb-dev libopenexr-dev
  # the settings document (TOML), read with toml++ as a header-only library
  libtomlplusplus-dev
  # the Python module (python/, docs/python.md) and so the Blender render engine: the system
  # Python's headers, pybind11, and numpy, which the module's arrays are
  python3-dev pybind11-dev python3-numpy
  # media: video encoding and the piano sound
  ffmpeg fluid-soundfont-gm
)
test_packages=(
  # tests, benchmarks and the checked formatting
  libgtest-dev libgmock-dev libbenchmark-dev libtinyobjloader-dev libembree-dev clang-format-14
  # the clang build, and fuzzing (scripts/fuzz.sh): clang with libFuzzer and the sanitizer
  # runtimes (libclang-rt is only recommended by clang, so named here), and llvm-symbolizer for
  # readable stack traces
  clang-14 libclang-rt-14-dev llvm-14
  # the cluster integration test starts a real one-node Slurm cluster
  slurm-wlm munge
  # the Blender add-on is tested in a real, headless Blender
  blender
  # the ink lines' SVG is checked against a real SVG renderer (rsvg-convert)
  librsvg2-bin
  # Blender's glTF exporter needs numpy; EXR files are read back by a second tool (oiiotool)
  python3-numpy openimageio-tools
  # the render engine's viewport in a real Blender window without a display: a virtual X
  # server and Mesa's software OpenGL
  xvfb xauth libgl1-mesa-dri
)
# Cross building for 64-bit ARM: the libraries toonray and its unit tests link, for arm64.
aarch64_packages=(
  g++-aarch64-linux-gnu qemu-user
  # SIMDe: the SSE intrinsics on ARM (core/simd_sse.h); headers only, for any architecture
  libsimde-dev
  libfmt-dev:arm64 libtbb-dev:arm64 libdeflate-dev:arm64 libpng-dev:arm64
  libfluidsynth-dev:arm64 libgtest-dev:arm64 libgmock-dev:arm64
  libtinyobjloader-dev:arm64  # the OBJ loader tests compare with it
  libtinygltf-dev:arm64
  # (no libopenexr-dev:arm64: Debian's OpenEXR headers cannot be installed for two architectures
  # at once, so the aarch64 build leaves EXR output out)
)

case "$profile" in
  demo) packages=("${demo_packages[@]}") ;;
  aarch64) packages=(build-essential cmake ninja-build pkg-config libcli11-dev "${aarch64_packages[@]}") ;;
  all) packages=("${demo_packages[@]}" "${test_packages[@]}" "${aarch64_packages[@]}") ;;
  *) echo "install-deps: unknown profile '$profile' (demo, all or aarch64)" >&2; exit 2 ;;
esac

sudo=""
[ "$(id -u)" -eq 0 ] || sudo="sudo"

need_arm64=0
for p in "${packages[@]}"; do [[ $p == *:arm64 ]] && need_arm64=1; done
if [ $need_arm64 = 1 ] && ! dpkg --print-foreign-architectures | grep -qx arm64; then
  $sudo dpkg --add-architecture arm64
fi

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages for '$profile' present"
  exit 0
fi

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
