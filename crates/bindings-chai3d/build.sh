#!/usr/bin/env bash
# Builds the CHAI3D binding into target/bindings-chai3d: CHAI3D's core once into the
# cache (.ci/install-chai3d), the C API (cargo) and its header (`needle header`), then
# CMake: libneedle_chai3d.a, the headless tests (replay_golden, replay_insertion,
# readme_example) and, when GLFW and OpenGL are found, the windowed needle_chai3d_device.
# Prints the build folder on stdout.
#
# Usage: build.sh [--build-dir DIR] [CMake -D options...]
#   --build-dir DIR   the CMake build folder (default target/bindings-chai3d/build)
#   e.g. -DNEEDLE_CHAI3D_DEVICE_EXAMPLE=ON (GLFW required) or OFF
# The C API and the needle command build with cargo's profile $NEEDLE_CARGO_PROFILE
# (default release; .ci/test passes ci, the profile its workspace tests built).
set -euo pipefail
root="$(cd "$(dirname "$0")/../.." && pwd)"
out="$root/target/bindings-chai3d"
build="$out/build"
if [ "${1:-}" = --build-dir ]; then
  build="$2"
  shift 2
fi
chai3d="$("$root/.ci/install-chai3d")"
cd "$root"
profile="${NEEDLE_CARGO_PROFILE:-release}"
cargo build --profile "$profile" -q -p needle-capi -p needle-cli
"target/$profile/needle" header --out "$out/include" >&2
cmake -S crates/bindings-chai3d -B "$build" -DCMAKE_BUILD_TYPE=Release -DCHAI3D_ROOT="$chai3d" \
  -DNEEDLE_CAPI_LIB="$root/target/$profile/libneedle_capi.a" -DNEEDLE_INCLUDE_DIR="$out/include" "$@" >&2
cmake --build "$build" -j"$(nproc)" >&2
echo "$build"
