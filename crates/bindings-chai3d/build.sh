#!/usr/bin/env bash
# Builds the CHAI3D binding into target/bindings-chai3d: CHAI3D's core once into the
# cache (.ci/install-chai3d), the C API (cargo) and its header (`needle header`), then
# CMake: libneedle_chai3d.a, replay_golden (the headless test), needle_chai3d_device.
# Prints the build folder on stdout.
set -euo pipefail
root="$(cd "$(dirname "$0")/../.." && pwd)"
chai3d="$("$root/.ci/install-chai3d")"
out="$root/target/bindings-chai3d"
cd "$root"
cargo build --release -q -p needle-capi -p needle-cli
target/release/needle header --out "$out/include" >&2
cmake -S crates/bindings-chai3d -B "$out/build" -DCMAKE_BUILD_TYPE=Release -DCHAI3D_ROOT="$chai3d" \
  -DNEEDLE_CAPI_LIB="$root/target/release/libneedle_capi.a" -DNEEDLE_INCLUDE_DIR="$out/include" >&2
cmake --build "$out/build" -j"$(nproc)" >&2
echo "$out/build"
