#!/usr/bin/env bash
# Regenerates assets/*.obj from core/primitives.cpp (the bunny comes from scripts/bunny_to_obj.js).
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cmake -S "$root" -B "$root/build-assets" -DCMAKE_BUILD_TYPE=Release -DTETRASAND_BUILD_TESTS=OFF -DTETRASAND_BUILD_BENCH=OFF >/dev/null
cmake --build "$root/build-assets" --target tetrasand_make_assets -j "$(nproc)"
"$root/build-assets/bin/tetrasand_make_assets" "$root/assets"
