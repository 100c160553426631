#!/usr/bin/env bash
# Command 2 of the README (and all that .ci/run does): installs what is missing, builds with warnings
# as errors and runs the whole suite through ctest. Exits non-zero on any failure.
#   scripts/test.sh              Release build in build-test/
#   scripts/test.sh --sanitize   ASan + UBSan build in build-sanitize/
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
type=Release; dir="$root/build-test"
if [ "${1:-}" = "--sanitize" ]; then type=Sanitize; dir="$root/build-sanitize"; fi
"$root/scripts/deps.sh"
# With the benchmarks: the device run's --quick form (ctest DeviceBench.*, ~3 min on 2 cores) runs
# here too, so a device call is known to work before a device is lent (issue 43).
"$root/scripts/build.sh" "$dir" "$type" -DTETRASAND_WERROR=ON -DTETRASAND_BUILD_BENCH=ON
jobs=$(nproc 2>/dev/null || echo 2)
# llvmpipe renders with one thread per core; ctest runs that many tests side by side already.
export LP_NUM_THREADS=${LP_NUM_THREADS:-1}
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=0}
cd "$dir"
ctest --output-on-failure -j "$jobs" --timeout 900
