#!/usr/bin/env bash
# One entry point for the comparisons and reports (docs/benchmarks.md, docs/validation.md).
# Usage: scripts/bench.sh [sim|sim-accuracy|peers-sim|validation|sdf|all] [--build-dir DIR] [--no-build] [--grains LIST] [--cases 'MESH@R1,R2 ...']
#   sim         Cundall number (grain-steps/s) of the GPU pipeline and the CPU reference on the same
#               settled beds, 1k to 1M grains (--grains 1000,8000 for fewer), memory per grain
#               -> the Cundall table and plot in section sim of docs/benchmarks.md      (~8 min, 2 cores)
#   sim-accuracy  E, dt and precision (CPU reference, GPU float, GPU double) against largest overlap,
#               energy drift (no-dissipation box) and angle of repose (150-grain heap)
#               -> the accuracy table and plots in section sim of docs/benchmarks.md   (~15 min, 2 cores)
#   peers-sim   tetrasand (CPU reference, GPU pipeline) against LAMMPS on the same scenes, one run:
#               grain-steps/s as ratios, settled bed height, rebound, angle of repose
#               -> section peers-sim of docs/benchmarks.md                              (~5 min, 2 cores)
#   validation  restitution, angle of repose, silo discharge (Beverloo), contact-force distribution,
#               column collapse, GPU pipeline against CPU reference (heap, silo, bed)
#               -> docs/validation.md and docs/validation/*.png   (~15 min CPU runs + ~30 min GPU runs on llvmpipe)
#   sdf         SDF construction three ways per mesh and grid in one run: GPU scan conversion, CPU exact
#               (CGAL, all cores), OpenVDB meshToLevelSet (all cores), errors against exact; default
#               knot1, armadillo (libcgal-demo) and a 1.3M-triangle icosphere:8 at 64^3..1024^3
#               (--cases 'knot1@64,128 icosphere:8@64' for fewer; NAME = libcgal-demo mesh, or a path)
#               -> section sdf of docs/benchmarks.md, docs/benchmarks/sdf_error_vs_time.png
#               (not in `all`: over an hour on llvmpipe, 2 cores)
# Exit status: 0 when every physical comparison is within its stated tolerance, 1 otherwise.
# Other benchmarks (sampling) have their own bench programs; see docs/benchmarks.md.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
what=${1:-all}
[ $# -gt 0 ] && shift
build="$root/build-release"
do_build=1
sdf_cases="knot1@64,128,256,512,1024 armadillo@64,128,256,512,1024 icosphere:8@64,128,256,512,1024"
grains=1000,8000,64000,512000,1000000
while [ $# -gt 0 ]; do
  case "$1" in
    --build-dir) build=$2; shift 2 ;;
    --no-build) do_build=0; shift ;;
    --cases) sdf_cases=$2; shift 2 ;;
    --grains) grains=$2; shift 2 ;;
    *) echo "bench: unknown option $1" >&2; exit 2 ;;
  esac
done
case "$what" in sim|sim-accuracy|peers-sim|validation|sdf|all) ;; *) echo "bench: unknown benchmark '$what'" >&2; exit 2 ;; esac

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

if [ "$what" = sim ] || [ "$what" = all ]; then
  "$bin/tetrasand_bench_sim" --grains "$grains" --csv "$work/sim.csv"
  "$py" "$root/bench/plot_sim.py" "$work/sim.csv" "$root/docs" "scripts/bench.sh sim --grains $grains"
  echo "bench: wrote the Cundall table of docs/benchmarks.md and docs/benchmarks/sim_cundall.png"
fi
if [ "$what" = sim-accuracy ] || [ "$what" = all ]; then
  "$bin/tetrasand_bench_sim_accuracy" "$work/sim-accuracy" all
  "$py" "$root/bench/plot_sim_accuracy.py" "$work/sim-accuracy" "$root/docs"
  echo "bench: wrote the accuracy table of docs/benchmarks.md and docs/benchmarks/sim_accuracy_*.png"
fi
if [ "$what" = peers-sim ] || [ "$what" = all ]; then
  "$py" "$root/bench/peers/sim_peers.py" "$bin" "$work/peers-sim" --markdown "$root/docs/benchmarks.md" || status=1
fi
if [ "$what" = validation ] || [ "$what" = all ]; then
  "$bin/tetrasand_validation_runs" "$work/validation" all
  "$py" "$root/bench/validation/report.py" "$work/validation" "$root/docs" >/dev/null
  echo "bench: wrote docs/validation.md"
fi
if [ "$what" = sdf ]; then
  # libcgal-demo's meshes: where the tests unpacked them, else unpacked here.
  meshes="$build/test-data/cgal/data/meshes"
  if [ ! -d "$meshes" ]; then
    tarball=/usr/share/doc/libcgal-dev/data.tar.gz
    [ -f "$tarball" ] || { echo "bench: $tarball not found (Debian package libcgal-dev)" >&2; exit 1; }
    mkdir -p "$work/cgal" && tar -xzf "$tarball" -C "$work/cgal" data/meshes
    meshes="$work/cgal/data/meshes"
  fi
  resolved=()
  for c in $sdf_cases; do
    name=${c%@*}
    case "$name" in icosphere:*|*/*) resolved+=("$c") ;; *) resolved+=("$meshes/$name.off@${c#*@}") ;; esac
  done
  load_start=$(cut -d' ' -f1-3 /proc/loadavg)
  # Progress (stderr) to the terminal and to sdf.err, which names the GL renderer.
  { "$bin/tetrasand_bench_sdf" "${resolved[@]}" --csv "$work/sdf.csv" 2>&1 1>&3 | tee "$work/sdf.err" >&2; } 3>&1 ||
    { echo "bench: tetrasand_bench_sdf failed (see $work/sdf.err); reporting the rows it finished" >&2; status=1; }
  load_end=$(cut -d' ' -f1-3 /proc/loadavg)
  renderer=$(sed -n 's/^renderer: //p' "$work/sdf.err" | head -n 1)
  "$py" "$root/bench/plot_sdf.py" "$work/sdf.csv" "$root/docs/benchmarks/sdf_error_vs_time.png"
  "$py" "$root/bench/sdf_report.py" "$work/sdf.csv" --markdown "$root/docs/benchmarks.md" --renderer "$renderer" \
    --command "scripts/bench.sh sdf --cases '$sdf_cases'" --planned "${resolved[@]}" \
    --load "$load_start (1/5/15 min) at the start, $load_end at the end" --notes "$root/bench/sdf_notes.md" >/dev/null
  echo "bench: wrote section sdf of docs/benchmarks.md and docs/benchmarks/sdf_error_vs_time.png"
fi
exit $status
