#!/usr/bin/env bash
# Builds the libFuzzer targets of fuzz/ (clang-14, ASan + UBSan) in build-fuzz/ and runs each for a
# while on a corpus seeded from assets/ and Debian's test models. A benchmark-like script, not part
# of the test suite: its results (executions, crashes, coverage) go to docs/reliability.md.
#   scripts/fuzz.sh [--seconds N] [--runs R] [--jobs J] [TARGET...]
#     --seconds N   run time of each target (default 60)
#     --runs R      stop a target after R executions instead, if that comes first (default: no limit)
#     --jobs J      libFuzzer worker processes per target (default 1)
#     TARGET        fuzz_mesh fuzz_body fuzz_scene fuzz_checkpoint fuzz_vdb fuzz_cli (default: all)
# Prints one line per target and writes them to build-fuzz/fuzz-summary.txt. A crash leaves its input
# in build-fuzz/crashes/TARGET/ (make it a regression test: tests/core/bad_meshes/ for meshes) and
# makes the script exit 1; an input slower than 10 s is kept there too (slow-unit-*), counted apart.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
seconds=60 runs=-1 jobs=1 targets=()
while [ $# -gt 0 ]; do
  case "$1" in
    --seconds) seconds=$2; shift 2 ;;
    --runs) runs=$2; shift 2 ;;
    --jobs) jobs=$2; shift 2 ;;
    -h|--help) sed -n '2,12p' "$0"; exit 0 ;;
    fuzz_*) targets+=("$1"); shift ;;
    *) echo "fuzz.sh: unknown argument '$1' (see --help)" >&2; exit 2 ;;
  esac
done
[ ${#targets[@]} -gt 0 ] || targets=(fuzz_mesh fuzz_body fuzz_scene fuzz_checkpoint fuzz_vdb fuzz_cli)
dir="$root/build-fuzz"
if ! command -v clang++-14 >/dev/null || [ ! -e /usr/lib/llvm-14/lib/clang/14.0.6/lib/linux/libclang_rt.fuzzer-x86_64.a ]; then
  echo "fuzz.sh: needs clang-14 and libFuzzer: apt-get install clang-14 libclang-rt-14-dev" >&2; exit 1
fi
launcher=()
command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCMAKE_C_COMPILER_LAUNCHER=ccache)

cmake -S "$root" -B "$dir" -DCMAKE_BUILD_TYPE=Fuzz -DCMAKE_C_COMPILER=clang-14 -DCMAKE_CXX_COMPILER=clang++-14 \
  -DTETRASAND_BUILD_FUZZ=ON -DTETRASAND_BUILD_TESTS=OFF -DTETRASAND_BUILD_BENCH=OFF "${launcher[@]}" >/dev/null
cmake --build "$dir" -j "$(nproc 2>/dev/null || echo 2)" --target "${targets[@]}"

models=/usr/share/assimp/models
# Seeds: small files only (libFuzzer mutates best below a few kB; -max_len bounds them anyway).
small_files() { find "$@" -maxdepth 1 -type f -size -64k 2>/dev/null | sort; }

seed_fuzz_mesh() {  # the first byte picks the extension, in fuzz_mesh.cpp's order
  # Only small files (under 4 KiB, at most 8 a format, the smallest first; the smallest file of a
  # format that has none that small): an execution's time grows with the input, and inputs of the
  # size of Debian's bunny made mesh executions 90-250 ms. -max_len (mesh_max_len) bounds mutations.
  local out=$1 i=0 ext byte f files
  for ext in obj ply stl off gltf glb; do
    byte=$(printf '\\%03o' "$i")
    files=$({ find "$root/assets" "$models/${ext^^}" -maxdepth 1 -type f 2>/dev/null; find "$models/glTF2" -type f; } \
      | grep -i "\.$ext\$" | xargs -r stat -c '%s %n' | sort -n)
    while read -r _ f; do
      [ -n "$f" ] || continue
      { printf "$byte"; cat "$f"; } >"$out/$ext-$(basename "$f")"
    done < <({ echo "$files" | awk '$1 < 4096' | head -8; echo "$files" | head -1; } | sort -u)
    i=$((i + 1))
  done
  for f in "$root"/tests/core/bad_meshes/*.ply; do { printf '\001'; cat "$f"; } >"$out/bad-$(basename "$f")"; done
}
seed_fuzz_body() {
  local out=$1 name
  for name in cube plate; do
    { cat "$root/assets/bodies/$name.body.json"; printf '\000'; cat "$root/assets/bodies/$name.particles.ply"; } \
      | sed "s/$name.particles.ply/cube.particles.ply/" >"$out/$name"
  done
}
seed_fuzz_scene() { cp "$root"/assets/scenes/*.toml "$root"/fuzz/regressions/fuzz_scene/* "$1/"; }
# Edits of the base checkpoint fuzz_checkpoint.cpp makes (12-byte records); the empty input resumes it as is.
seed_fuzz_checkpoint() { cp "$root"/fuzz/regressions/fuzz_checkpoint/* "$1/"; }
seed_fuzz_vdb() {
  # TETRASAND_BIN: a tetrasand binary to write the seed .vdb files with (default: build-test's).
  local out=$1 bin="${TETRASAND_BIN:-$root/build-test/bin/tetrasand}"
  if [ -x "$bin" ]; then
    "$bin" -q sdf "$root/assets/cube.obj" -o "$out/cube.vdb" --resolution 6 --band 2 || true
    "$bin" -q sdf "$root/assets/torus.obj" -o "$out/torus.vdb" --resolution 8 --band 2 || true
  fi
  printf 'BD\x9a\x2b\x20\x56\x00\x00' >"$out/magic"
}
seed_fuzz_cli() {
  local out=$1 i=0 line
  while IFS= read -r line; do
    printf '%s' "$line" | tr ' ' '\n' >"$out/line$i"; i=$((i + 1))
  done <<'LINES'
info assets/cube.obj --density 1500 --scale 0.001
sdf assets/cube.obj -o x.vdb --voxel 0.1 --band 3 --padding 4 --max-slab-mb 64
sample assets/cube.obj -o out --radius 0.05 --coverage 1.2 --rounds 3 --probes 1000 --seed 7
sample assets/cube.obj -o out --count 500 --density 2000 --grain-radius 0.01 --sdf-budget-mib 256
preview assets/cube.obj -o x.png --eye 1,2,3 --target 0,0,0 --fov 40 --turntable 4 --color-max 0.5
preview assets/cube.obj -o x.png --up 0,0,1 --light 1,1,1 --resolution 32 --scale 2 --particle-radius 0.1
sim assets/scenes/pile.toml --duration 0.5 --cpu
--device 0 devices
LINES
}

# One process in the foreground unless --jobs asks for more (libFuzzer then logs each to fuzz-N.log).
parallel=()
[ "$jobs" -le 1 ] || parallel=(-jobs="$jobs" -workers="$jobs")
summary="$dir/fuzz-summary.txt"
: >"$summary"
status=0
for target in "${targets[@]}"; do
  corpus="$dir/corpus/$target" crashes="$dir/crashes/$target"
  mkdir -p "$corpus" "$crashes"
  seeds=$(mktemp -d)
  "seed_$target" "$seeds"
  log="$dir/$target.log"
  # Mesh inputs are kept small (see seed_fuzz_mesh); the other readers' seeds are up to 64 kB.
  max_len=65536
  [ "$target" != fuzz_mesh ] || max_len=4096
  dict=()
  [ ! -f "$root/fuzz/$target.dict" ] || dict=(-dict="$root/fuzz/$target.dict")
  start=$(date +%s)
  # Run from the repository root: the command-line seeds name assets/ relatively.
  (cd "$root" && ASAN_OPTIONS=detect_leaks=0:allocator_may_return_null=1 "$dir/bin/$target" \
    -max_total_time="$seconds" -runs="$runs" -max_len="$max_len" -rss_limit_mb=4096 -timeout=30 -print_final_stats=1 \
    "${parallel[@]}" "${dict[@]}" -artifact_prefix="$crashes/" "$corpus" "$seeds") >"$log" 2>&1 || true
  elapsed=$(($(date +%s) - start))
  rm -rf "$seeds"
  logs=("$log")
  [ "$jobs" -le 1 ] || logs+=("$root"/fuzz-*.log)
  executed=$({ grep -h 'stat::number_of_executed_units' "${logs[@]}" || true; } | awk '{s += $2} END {print s + 0}')
  cov=$({ grep -ho 'cov: [0-9]*' "${logs[@]}" || true; } | tail -1 | awk '{print $2}')
  # Findings: crash-, leak-, timeout- (over 30 s) and oom- (over 4 GiB) files; slow-unit- files (over
  # 10 s) are counted apart.
  found=$(find "$crashes" -type f ! -name 'slow-unit-*' | wc -l)
  slow=$(find "$crashes" -type f -name 'slow-unit-*' | wc -l)
  line=$(printf '%-11s %5d s  %10d executions  %6d exec/s  cov %6s  corpus %5d  crashes %d  slow units %d' \
    "$target" "$elapsed" "$executed" $((executed / (elapsed > 0 ? elapsed : 1))) "${cov:-?}" \
    "$(find "$corpus" -type f | wc -l)" "$found" "$slow")
  echo "$line" | tee -a "$summary"
  [ "$found" -eq 0 ] || status=1
done
rm -f "$root"/fuzz-*.log
exit $status
