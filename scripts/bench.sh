#!/usr/bin/env bash
# One entry point for the comparisons and reports (docs/benchmarks.md, docs/validation.md).
# Usage: scripts/bench.sh [peers-sim|validation|all] [--build-dir DIR] [--no-build]
#   peers-sim   tetrasand (CPU reference, GPU pipeline) against LAMMPS on the same scenes, one run:
#               grain-steps/s as ratios, settled bed height, rebound, angle of repose
#               -> section peers-sim of docs/benchmarks.md                              (~5 min, 2 cores)
#   validation  restitution, angle of repose, silo discharge (Beverloo), contact-force distribution
#               -> docs/validation.md and docs/validation/*.png                         (~8 min, 2 cores)
# Exit status: 0 when every physical comparison is within its stated tolerance, 1 otherwise.
# Other benchmarks (SDF, sampling) have their own bench programs; see docs/benchmarks.md.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
what=${1:-all}
[ $# -gt 0 ] && shift
build="$root/build-release"
do_build=1
while [ $# -gt 0 ]; do
  case "$1" in
    --build-dir) build=$2; shift 2 ;;
    --no-build) do_build=0; shift ;;
    *) echo "bench: unknown option $1" >&2; exit 2 ;;
  esac
done
case "$what" in peers-sim|validation|all) ;; *) echo "bench: unknown benchmark '$what'" >&2; exit 2 ;; esac

# The bench's own packages (not needed to build or test): LAMMPS, numpy, matplotlib.
bench_packages=(lammps openmpi-bin python3-numpy python3-matplotlib)
missing=()
for p in "${bench_packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  if [ "$(id -u)" -ne 0 ]; then
    echo "bench: missing Debian packages: ${missing[*]}; run as root: apt-get install -y ${missing[*]}" >&2
    exit 1
  fi
  DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends "${missing[@]}"
fi

if [ "$do_build" -eq 1 ]; then
  "$root/scripts/build.sh" "$build" Release >/dev/null
fi
bin="$build/bin"
work=$(mktemp -d "${TMPDIR:-/tmp}/tetrasand-bench.XXXXXX")
echo "bench: work files in $work"
status=0
# numpy and matplotlib are Debian's: run the system interpreter, not a pyenv one.
py=/usr/bin/python3

if [ "$what" = peers-sim ] || [ "$what" = all ]; then
  "$py" "$root/bench/peers/sim_peers.py" "$bin" "$work/peers-sim" --markdown "$root/docs/benchmarks.md" || status=1
fi
if [ "$what" = validation ] || [ "$what" = all ]; then
  "$bin/tetrasand_validation_runs" "$work/validation" all
  "$py" "$root/bench/validation/report.py" "$work/validation" "$root/docs" >/dev/null
  echo "bench: wrote docs/validation.md"
fi
exit $status
