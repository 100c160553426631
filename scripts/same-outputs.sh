#!/usr/bin/env bash
# Checks that a change left behaviour alone: builds a base revision and the working tree (Release),
# runs the same jobs with both on the bundled assets (sdf by scan conversion and by the exact CPU path,
# sample, preview, info, sim on the CPU reference and the GPU pipeline, export lammps) and compares every
# output file byte for byte.
#
#   scripts/same-outputs.sh [--base REV] [--out DIR] [--no-build]
#
#   --base REV   the revision to compare against (default HEAD: the last commit)
#   --out DIR    where the builds and outputs go (default build-same/)
#   --no-build   reuse the builds already in DIR
#   --binaries A B   compare these two tetrasand executables instead of building (A = base)
#   --sim-tolerance  a sim output folder (sim_*) whose bytes differ is then compared by
#                    scripts/sim_outputs_agree.py: same layout and numbering, values within the round-off
#                    of a changed summation order (its criteria); for changes that reorder float sums
#
# What is masked, because it changes from run to run whatever the code: the 36-character UUID that
# OpenVDB writes into every .vdb header, and body.json's quality.seconds (wall time). Standard output
# is not compared (it prints timings). Exit 0 when every file matches, 1 otherwise, with a list.
# Takes about 10 minutes on 2 cores with warm ccache builds (each build alone ~10 min when cold).
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
base=HEAD
out="$root/build-same"
build=1
bin_base=""
bin_head=""
sim_tolerance=0
while [ $# -gt 0 ]; do
  case "$1" in
    --base) base=$2; shift 2 ;;
    --out) out=$2; shift 2 ;;
    --no-build) build=0; shift ;;
    --binaries) bin_base=$(realpath "$2"); bin_head=$(realpath "$3"); build=0; shift 3 ;;
    --sim-tolerance) sim_tolerance=1; shift ;;
    -h|--help) sed -n '2,19p' "$0"; exit 0 ;;
    *) echo "same-outputs.sh: unknown argument $1" >&2; exit 2 ;;
  esac
done
mkdir -p "$out"
out=$(cd "$out" && pwd)
launcher=()
if command -v ccache >/dev/null; then
  launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCMAKE_C_COMPILER_LAUNCHER=ccache)
  export CCACHE_BASEDIR=${CCACHE_BASEDIR:-$(dirname "$root")}
fi

if [ "$build" = 1 ]; then
  rev=$(git -C "$root" rev-parse --verify "$base^{commit}")
  if [ -d "$out/base-src" ]; then git -C "$root" worktree remove --force "$out/base-src"; fi
  git -C "$root" worktree add --detach "$out/base-src" "$rev" >/dev/null
  echo "base: $base = $rev"
  "$out/base-src/scripts/build.sh" "$out/base" Release -DTETRASAND_BUILD_TESTS=OFF -DTETRASAND_BUILD_BENCH=OFF \
    "${launcher[@]}" >/dev/null
  "$root/scripts/build.sh" "$out/head" Release -DTETRASAND_BUILD_TESTS=OFF -DTETRASAND_BUILD_BENCH=OFF "${launcher[@]}" >/dev/null
fi

# The jobs. $1: the tetrasand binary, $2: the output directory. Small sizes: a few minutes on llvmpipe.
run_jobs() {
  local bin=$1 dir=$2 a="$root/assets"
  rm -rf "$dir"
  mkdir -p "$dir"
  cd "$dir"
  local log="$dir/log.txt"
  # The GPU pipeline by name: since --backend (issue 16) plain `sim` runs the CPU reference on llvmpipe.
  # A base built before it has no --backend, and its plain `sim` is the GPU pipeline.
  local gpu=()
  if "$bin" sim --help 2>/dev/null | grep -- --backend >/dev/null; then gpu=(--backend gpu); fi  # no -q: pipefail
  # The same for `sdf`: since issue 42 plain `sdf` takes the exact CPU path on llvmpipe, so both binaries
  # name the scan conversion, and the CPU path is a job of its own (a base before --backend has neither).
  local scan=() exact=()
  if "$bin" sdf --help 2>/dev/null | grep -- --backend >/dev/null; then scan=(--backend gpu); exact=(--backend cpu); fi
  {
    "$bin" info "$a/bunny.obj" --json >info_bunny.json
    "$bin" info "$a/torus.obj" --json >info_torus.json
    "$bin" sdf "$a/bunny.obj" -o bunny.vdb --resolution 64 "${scan[@]}"
    "$bin" sdf "$a/trefoil.obj" -o trefoil.vdb --resolution 48 --sign winding "${scan[@]}"
    "$bin" sdf "$a/cube.obj" -o cube.vdb --voxel 0.01 --band 2 "${scan[@]}"
    if [ ${#exact[@]} -gt 0 ]; then
      "$bin" sdf "$a/bunny.obj" -o bunny_exact.vdb --resolution 64 "${exact[@]}"
      "$bin" sdf "$a/trefoil.obj" -o trefoil_exact.vdb --resolution 48 --sign winding "${exact[@]}"
    fi
    "$bin" sample "$a/sphere.obj" -o body --count 400 --preview
    "$bin" sample "$a/torus.obj" -o body --count 600 --fill
    "$bin" sample "$a/plate.obj" -o body --count 300 --sign winding --grain-radius 0.005
    "$bin" sample "$a/cube.obj" "$a/trefoil.obj" -o batch --count 300
    "$bin" preview "$a/torus.obj" -o torus.png --size 200x150 --resolution 48
    "$bin" preview bunny.vdb --particles body/sphere.body.json -o vdb_particles.png --size 160x160 --view iso
    "$bin" preview "$a/sphere.obj" --particles body/sphere.body.json -o error.png --size 160x120 --color-by error \
      --resolution 32
    "$bin" preview "$a/cube.obj" -o turn.png --size 96x96 --turntable 3 --contact-sheet --resolution 32 --ortho
    "$bin" sim "$a/scenes/two_grain_collision.toml" -o sim_two --cpu
    "$bin" sim "$a/scenes/free_fall.toml" -o sim_fall_cpu --cpu
    "$bin" sim "$a/scenes/free_fall.toml" -o sim_fall_gpu "${gpu[@]}"
    "$bin" sim "$a/scenes/prop_drop.toml" -o sim_prop_cpu --cpu --duration 0.05
    "$bin" sim "$a/scenes/prop_drop.toml" -o sim_prop_gpu --duration 0.02 "${gpu[@]}"
    "$bin" sim "$a/scenes/prop_drop.toml" -o sim_prop_gpu64 --duration 0.01 --precision double "${gpu[@]}"
    "$bin" sim "$a/scenes/blade.toml" -o sim_blade_cpu --cpu --duration 0.02
    "$bin" sim "$a/scenes/hourglass.toml" -o sim_hourglass_gpu --duration 0.005 "${gpu[@]}"
    printf '%s\n' '' '[output]' 'every = 50' 'frames = true' 'csv = true' >frames.tail
    cat "$a/scenes/free_fall.toml" | sed '/^\[output\]/,$d' >fall_frames.toml
    cat frames.tail >>fall_frames.toml
    "$bin" sim fall_frames.toml -o sim_frames --duration 0.02 "${gpu[@]}"
    "$bin" export lammps "$a/scenes/prop_drop.toml" -o lammps_prop
    "$bin" export lammps "$a/scenes/hourglass.toml" -o lammps_hourglass
  } >"$log" 2>&1 || { echo "a job failed with $bin; see $log" >&2; tail -20 "$log" >&2; return 1; }
  rm -f "$log" frames.tail
  cd - >/dev/null
}

# Copies a tree with the run-to-run varying bytes masked.
normalise() {
  python3 - "$1" <<'EOF'
import json, os, re, sys
root = sys.argv[1]
for dirpath, _, files in os.walk(root):
    for name in files:
        path = os.path.join(dirpath, name)
        if name.endswith(".vdb"):
            data = bytearray(open(path, "rb").read())
            # OpenVDB header: magic (8), file version (4), library version (8), grid offsets flag (1), UUID (36).
            data[21:57] = b"0" * 36
            open(path, "wb").write(bytes(data))
        elif name.endswith(".body.json") or (name.endswith(".json") and "quality" in open(path).read()):
            text = open(path).read()
            text = re.sub(r'("seconds": )[0-9.e+-]+', r'\g<1>0', text)
            open(path, "w").write(text)
        elif name.endswith("summary.csv"):
            lines = open(path).read().splitlines()
            head = lines[0].split(",")
            if "seconds" in head:
                k = head.index("seconds")
                rows = [lines[0]] + [",".join(c if i != k else "0" for i, c in enumerate(l.split(","))) for l in lines[1:]]
                open(path, "w").write("\n".join(rows) + "\n")
EOF
}

given_binaries=$bin_base
bin_base=${bin_base:-$out/base/bin/tetrasand}
bin_head=${bin_head:-$out/head/bin/tetrasand}
for side in base head; do
  bin=$bin_base
  [ "$side" = head ] && bin=$bin_head
  echo "running the jobs with $side ($bin) ..."
  run_jobs "$bin" "$out/out-$side"
  normalise "$out/out-$side"
done

cd "$out"
different=0
files=0
agreeing=()  # sim folders compared within tolerance (--sim-tolerance)
while IFS= read -r f; do
  files=$((files + 1))
  if [ ! -f "out-head/$f" ]; then echo "missing in head: $f"; different=1; continue; fi
  cmp -s "out-base/$f" "out-head/$f" && continue
  folder=${f#./}
  folder=${folder%%/*}
  if [ "$sim_tolerance" = 1 ] && [[ "$folder" == sim_* ]]; then
    [[ " ${agreeing[*]} " == *" $folder "* ]] && continue
    agreeing+=("$folder")
    if python3 "$root/scripts/sim_outputs_agree.py" "out-base/$folder" "out-head/$folder"; then
      echo "agrees within tolerance: $folder"
    else
      different=1
    fi
    continue
  fi
  echo "differs: $f"
  different=1
done < <(cd out-base && find . -type f | sort)
while IFS= read -r f; do
  if [ ! -f "out-base/$f" ]; then echo "only in head: $f"; different=1; fi
done < <(cd out-head && find . -type f | sort)
what="$base and the working tree"
[ -n "$given_binaries" ] && what="$bin_base and $bin_head"
if [ "$different" = 0 ] && [ ${#agreeing[@]} -gt 0 ]; then
  echo "same outputs: all $files files byte-identical between $what, but for ${agreeing[*]}, within the tolerance of scripts/sim_outputs_agree.py"
elif [ "$different" = 0 ]; then
  echo "same outputs: all $files files byte-identical between $what"
else
  echo "outputs differ between $what (trees in $out/out-base and $out/out-head)"
fi
exit "$different"
