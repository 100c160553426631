#!/usr/bin/env bash
# Cold and warm starts of the demo's job, `sample assets/bunny.obj --preview --up 0,1,0` (scripts/demo.sh),
# on llvmpipe: the whole command's wall time and the GL programs compiled and linked, each with its seconds
# (the debug lines of gpu/gl.cpp; a binary without them shows none). Three shader-cache states:
#   disabled  MESA_SHADER_CACHE_DISABLE=true: every program compiled, and no program binary formats at all
#   cold      an empty MESA_SHADER_CACHE_DIR (a new user's first run)
#   warm      the same directory again
# Each run gets its own XDG_CACHE_HOME, so no cache of the tool's own carries over.
# Usage: bench/preview_cold_start.sh TETRASAND_BINARY [EXTRA SAMPLE ARGS...]   (e.g. --backend gpu)
set -euo pipefail
bin=$(realpath "$1")
shift
root=$(cd "$(dirname "$0")/.." && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
run() {  # NAME, then env assignments
  local name=$1
  shift
  local start end
  start=$(date +%s.%N)
  env "$@" XDG_CACHE_HOME="$work/xdg-$name" TETRASAND_LOG=debug LP_NUM_THREADS="${LP_NUM_THREADS:-2}" \
    "$bin" sample "$root/assets/bunny.obj" -o "$work/out-$name" --preview --up 0,1,0 "${EXTRA[@]}" \
    >"$work/$name.log" 2>&1
  end=$(date +%s.%N)
  local programs linked
  programs=$(grep -c "compiled and linked" "$work/$name.log" || true)
  linked=$({ grep -o "compiled and linked .* in [0-9.]* s" "$work/$name.log" || true; } |
    awk '{s += $(NF-1)} END {printf "%.2f", s}')
  printf "%-9s wall %7.2f s   programs %3s   compile+link %7s s\n" "$name" "$(echo "$end - $start" | bc)" \
    "$programs" "$linked"
  grep -o "compiled and linked .* in [0-9.]* s" "$work/$name.log" | sed 's/^/    /' || true
}
EXTRA=("$@")
run disabled MESA_SHADER_CACHE_DISABLE=true
run cold MESA_SHADER_CACHE_DIR="$work/mesa"
run warm MESA_SHADER_CACHE_DIR="$work/mesa"
