#!/usr/bin/env bash
# Command 1 of the README: installs what is missing, builds Release and runs the main job on the
# bundled bunny, then prints where the outputs are.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
"$root/scripts/deps.sh"
"$root/scripts/build.sh" "$root/build-release" Release -DTETRASAND_BUILD_TESTS=OFF
out="$root/out"
mkdir -p "$out"
bin="$root/build-release/bin/tetrasand"
"$bin" devices
"$bin" info "$root/assets/bunny.obj"
if "$bin" sdf --help >/dev/null 2>&1; then
  "$bin" sdf "$root/assets/bunny.obj" -o "$out/bunny.vdb" --resolution 128 --timings
  echo "outputs: $out/bunny.vdb"
fi
if "$bin" sample --help >/dev/null 2>&1; then
  "$bin" sample "$root/assets/bunny.obj" -o "$out" --preview --up 0,1,0  # the Stanford bunny stands on +y
  echo "outputs: $out/bunny.particles.ply $out/bunny.body.json $out/bunny.preview.png"
fi
