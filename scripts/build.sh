#!/usr/bin/env bash
# Configures and builds one build directory. Usage: scripts/build.sh <build-dir> <build-type> [cmake args...]
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
dir=$1; type=$2; shift 2
jobs=$(nproc 2>/dev/null || echo 2)
cmake -S "$root" -B "$dir" -DCMAKE_BUILD_TYPE="$type" "$@"
cmake --build "$dir" -j "$jobs"
