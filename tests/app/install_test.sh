#!/usr/bin/env bash
# `cmake --install` into a fresh prefix, then run the installed executable with no hint where its
# shaders are: it must find share/tetrasand/shaders beside itself and run a GPU stage from there.
#   install_test.sh <build-dir> <source-dir>
set -euo pipefail
build=$1; source=$2
prefix=$(mktemp -d)
trap 'rm -rf "$prefix"' EXIT
cmake --install "$build" --prefix "$prefix" > /dev/null
unset TETRASAND_SHADER_DIR
# Mesa may answer a compile from its disk cache; this test is about which file is read.
export MESA_SHADER_CACHE_DISABLE=true
test -x "$prefix/bin/tetrasand"
test -f "$prefix/share/tetrasand/shaders/sdf/scan_convert.geom"
# --backend gpu: the scan conversion reads the kernels (plain sdf takes the exact CPU path on a software
# renderer).
"$prefix/bin/tetrasand" sdf "$source/assets/cube.obj" -o "$prefix/cube.vdb" --resolution 16 --backend gpu \
    --scan compute
test -s "$prefix/cube.vdb"
# Proof that it read the installed copy (the build tree is a fallback): break the installed kernel of
# the compute scan (asked for: --scan auto may pick either after its calibration), and the same run must
# now fail with a shader error naming it.
echo "this line is deliberately not GLSL (install_test);" >> "$prefix/share/tetrasand/shaders/sdf/scan_bricks.comp"
if "$prefix/bin/tetrasand" sdf "$source/assets/cube.obj" -o "$prefix/cube2.vdb" --resolution 16 --backend gpu \
    --scan compute >"$prefix/log" 2>&1; then
  echo "the installed executable did not read its installed shaders" >&2; exit 1
fi
grep -q "scan_bricks.comp" "$prefix/log" || { cat "$prefix/log" >&2; exit 1; }
echo "installed tetrasand ran its shaders from $prefix/share/tetrasand/shaders"
