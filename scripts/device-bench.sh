#!/usr/bin/env bash
# The NVIDIA benchmark run of issue 16 in one call of the device tool (at most 8 minutes), prepared here.
# Usage:
#   scripts/device-bench.sh prepare [--build-dir DIR] [--bundle DIR] [--no-build]
#       here: builds Release (build-release), packs into DIR (default .devbundle, git-ignored) what a bare
#       device machine lacks: payload.tar.xz (the executables, stripped; the shared libraries ldd names
#       minus the system and GL/EGL ones; the shaders; CGAL's knot1 and armadillo) and gl/*.deb (libglvnd's
#       EGL/OpenGL loaders, fetched with apt-get download). Prints the bundle's size; fails above the carry limit.
#       The test executables of the GPU agreement tests travel too (the run's selftest part runs them first).
#   scripts/device-bench.sh run [--quick] [--bundle DIR | --build-dir DIR] [--out DIR] [--only PARTS]
#                               [--caps PART=S,...] [--budget S]
#       there (or here with --quick): with a bundle, unpacks it (the .debs into / only where no libEGL is
#       installed), then runs selftest (the GPU agreement tests), SDF, sampler, sim and preview, each under
#       its own time cap (bench/device_bench.py),
#       into DIR/device-bench.json and DIR/device-bench.md (DIR: --out, else $OUT, else ./device-bench-out).
#       Without a bundle it runs the build tree's binaries (default build-release).
#   scripts/device-bench.sh report RESULTS.json [--markdown FILE] [--baseline HERE.json] [--allow-test]
#       here: rewrites the NVIDIA sections (nvidia-sdf, -sampler, -sim, -preview) of docs/benchmarks/device.md;
#       a --quick or non-NVIDIA run only with --allow-test (the ctest writes into a copy).
# One device call (docs/benchmarks.md, "How the figures are made"): carry .devbundle, timeout_s 540, command
#   scripts/device-bench.sh run --bundle .devbundle --out $OUT
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
verb=${1:-}
[ $# -gt 0 ] && shift
# The device machine's python3 is not Debian's; the driver needs the standard library only.
py=/usr/bin/python3
[ -x "$py" ] || py=$(command -v python3)
carry_limit=$((64 * 1024 * 1024))  # bytes: the device tool's limit on the working tree and carried paths together
binaries=(tetrasand tetrasand_bench_sdf tetrasand_bench_sim tetrasand_bench_preview)
# The test executables whose GPU agreement tests the device run's selftest part runs first
# (bench/device_bench.py SELFTESTS); packed when the build has them.
test_binaries=(tetrasand_gpu_tests tetrasand_sdf_tests tetrasand_sampler_tests tetrasand_sim_tests tetrasand_preview_tests)
gl_packages=(libvulkan1 libegl1 libglvnd0 libopengl0 libgl1 libglx0 libgles2)
# What ldd names that the bundle leaves out: the C and C++ runtimes every Linux has, and the GL loaders
# (libglvnd, from gl/*.deb there, so that the NVIDIA driver's own libraries are the ones loaded).
system_libs='^(linux-vdso|ld-linux|libc|libm|libdl|librt|libpthread|libstdc\+\+|libgcc_s|libEGL|libGL|libGLX|libGLdispatch|libOpenGL|libGLESv2)\.'

# cgal_mesh NAME DEST: CGAL's demo mesh NAME.off (Debian libcgal-dev) copied into DEST.
cgal_mesh() {
  local tarball=/usr/share/doc/libcgal-dev/data.tar.gz
  [ -f "$tarball" ] || { echo "device-bench: $tarball not found (Debian package libcgal-dev)" >&2; exit 1; }
  tar -xzf "$tarball" -O "data/meshes/$1.off" >"$2/$1.off"
}

# fetch_gl_debs DEST: the libglvnd loaders as .deb files, from .gl/ (gpu-headless note) or apt-get download.
fetch_gl_debs() {
  mkdir -p "$1"
  if compgen -G "$root/.gl/*.deb" >/dev/null; then
    cp "$root"/.gl/*.deb "$1"/
    return
  fi
  local lists=/tmp/device-bench-apt-lists
  mkdir -p "$lists/partial"
  local o=(-oAPT::Architecture=amd64 -oAPT::Architectures=amd64 "-oDir::State::Lists=$lists")
  apt-get "${o[@]}" update >/dev/null
  (cd "$1" && apt-get "${o[@]}" download "${gl_packages[@]}" >/dev/null) ||
    { echo "device-bench: apt-get download ${gl_packages[*]} failed; put the .debs in $root/.gl/" >&2; exit 1; }
}

# check_libraries STAGE: with STAGE/lib first on the path, every library each executable needs is found
# there or is one of the system ones left out; else the bundle would fail on the device, not here.
check_libraries() {
  local bad
  bad=$(for b in "$1"/bin/*; do LD_LIBRARY_PATH="$1/lib" ldd "$b"; done | awk '$2 == "=>" {print $1, $3}' |
    while read -r name path; do
      echo "$name" | grep -Eq "$system_libs" || [ "${path#"$1"/lib/}" != "$path" ] || echo "$name ($path)"
    done | sort -u)
  [ -z "$bad" ] || { echo "device-bench: not in the bundle: $bad" >&2; exit 1; }
}

# newest_version PREFIX STAGE: the highest symbol version PREFIX.* that STAGE's executables and libraries ask for.
newest_version() {
  for f in "$2"/bin/* "$2"/lib/*; do objdump -T "$f"; done | grep -o "$1\.[0-9.]*" | sort -uV | tail -n 1
}

# stage_payload BUILD STAGE: STAGE/bin (stripped executables), lib, share/tetrasand/shaders, meshes.
stage_payload() {
  mkdir -p "$2/bin" "$2/lib" "$2/share/tetrasand" "$2/meshes"
  for b in "${binaries[@]}"; do
    [ -x "$1/bin/$b" ] || { echo "device-bench: $1/bin/$b not built" >&2; exit 1; }
    strip --strip-unneeded -o "$2/bin/$b" "$1/bin/$b"
  done
  local packed=("${binaries[@]}")
  for b in "${test_binaries[@]}"; do
    [ -x "$1/bin/$b" ] || { echo "device-bench: $1/bin/$b not built: the selftest part will record it missing" >&2; continue; }
    strip --strip-unneeded -o "$2/bin/$b" "$1/bin/$b"
    packed+=("$b")
  done
  cp -r "$1/share/tetrasand/shaders" "$2/share/tetrasand/"
  for b in "${packed[@]}"; do ldd "$1/bin/$b"; done | awk '$2 == "=>" && $3 ~ /^\// {print $3}' | sort -u |
    while read -r lib; do
      basename "$lib" | grep -Eq "$system_libs" || cp -L "$lib" "$2/lib/"
    done
  check_libraries "$2"
  cgal_mesh knot1 "$2/meshes"
  cgal_mesh armadillo "$2/meshes"
}

prepare() {
  local build="$root/build-release" bundle="$root/.devbundle" do_build=1
  while [ $# -gt 0 ]; do
    case "$1" in
      --build-dir) build=$2; shift 2 ;;
      --bundle) bundle=$2; shift 2 ;;
      --no-build) do_build=0; shift ;;
      *) echo "device-bench prepare: unknown option $1" >&2; exit 2 ;;
    esac
  done
  if [ "$do_build" -eq 1 ]; then
    cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=Release -DTETRASAND_BUILD_TESTS=ON -DTETRASAND_BUILD_BENCH=ON >/dev/null
    cmake --build "$build" -j "$(nproc)" --target "${binaries[@]}" "${test_binaries[@]}" tetrasand_shaders >/dev/null
  fi
  if [ -e "$bundle" ] && [ ! -f "$bundle/payload.tar.xz" ] && [ -n "$(ls -A "$bundle")" ]; then
    echo "device-bench: $bundle is not empty and holds no payload.tar.xz: not overwriting it" >&2
    exit 1
  fi
  local stage
  stage=$(mktemp -d "${TMPDIR:-/tmp}/device-bench-stage.XXXXXX")
  stage_payload "$build" "$stage"
  rm -rf "$bundle" && mkdir -p "$bundle"
  tar -c -C "$stage" bin lib share meshes | xz -T0 >"$bundle/payload.tar.xz"
  # What the left-out system libraries must give there (the device image's glibc and libstdc++).
  local needs
  needs="glibc $(newest_version GLIBC_2 "$stage") and libstdc++ $(newest_version GLIBCXX_3 "$stage") or newer"
  rm -rf "$stage"
  fetch_gl_debs "$bundle/gl"
  local size tree debs=("$bundle"/gl/*.deb)
  size=$(du -sb "$bundle" | cut -f1)
  tree=$(cd "$root" && git ls-files -z --cached --others --exclude-standard | du -cb --files0-from=- 2>/dev/null | tail -n 1 | cut -f1)
  echo "device-bench: $bundle is $((size / 1024)) KiB (${#debs[@]} .debs, payload" \
    "$(($(stat -c %s "$bundle/payload.tar.xz") / 1024)) KiB); with the working tree ($((tree / 1024)) KiB)" \
    "$(((size + tree) / 1024)) KiB of the $((carry_limit / 1024)) KiB a call carries"
  echo "device-bench: the device machine needs $needs"
  [ $((size + tree)) -le "$carry_limit" ] || { echo "device-bench: over the carry limit" >&2; exit 1; }
}

# unpack_bundle DIR DEST: the payload into DEST; the GL loaders into / where none is installed (device only).
# DEST/lib goes to the benchmarks' LD_LIBRARY_PATH alone (bench/device_bench.py --libs), not to python3's.
unpack_bundle() {
  [ -f "$1/payload.tar.xz" ] || { echo "device-bench: $1/payload.tar.xz not found (run prepare here first)" >&2; exit 1; }
  mkdir -p "$2" && tar -xJf "$1/payload.tar.xz" -C "$2"
  if ! ldconfig -p | grep 'libEGL\.so\.1 ' >/dev/null; then
    [ "$(id -u)" -eq 0 ] || { echo "device-bench: no libEGL.so.1 here and not root to unpack $1/gl" >&2; exit 1; }
    for f in "$1"/gl/*.deb; do dpkg -x "$f" /; done
    ldconfig
  fi
  local nvidia=/usr/local/nvidia/share/glvnd/egl_vendor.d/10_nvidia.json
  if [ -f "$nvidia" ] && ! compgen -G '/usr/share/glvnd/egl_vendor.d/*nvidia*' >/dev/null &&
    ! compgen -G '/etc/glvnd/egl_vendor.d/*nvidia*' >/dev/null; then
    export __EGL_VENDOR_LIBRARY_FILENAMES=$nvidia
  fi
}

run() {
  local build="$root/build-release" bundle="" out=${OUT:-$PWD/device-bench-out} pass=()
  while [ $# -gt 0 ]; do
    case "$1" in
      --bundle) bundle=$2; shift 2 ;;
      --build-dir) build=$2; shift 2 ;;
      --out) out=$2; shift 2 ;;
      --quick) pass+=("$1"); shift ;;
      --only|--caps|--budget) pass+=("$1" "$2"); shift 2 ;;
      *) echo "device-bench run: unknown option $1" >&2; exit 2 ;;
    esac
  done
  local bin="$build/bin"
  if [ -n "$bundle" ]; then
    local dest
    dest=$(mktemp -d "${TMPDIR:-/tmp}/tetrasand-device.XXXXXX")
    # shellcheck disable=SC2064  # expanded now on purpose: dest is local to this function
    trap "rm -rf '$dest'" EXIT
    unpack_bundle "$bundle" "$dest"
    bin="$dest/bin"
    pass+=(--meshes "$dest/meshes" --libs "$dest/lib")
  fi
  "$py" "$root/bench/device_bench.py" run --bin "$bin" --out "$out" "${pass[@]}"
}

case "$verb" in
  prepare) prepare "$@" ;;
  run) run "$@" ;;
  report) "$py" "$root/bench/device_bench.py" report "$@" ;;
  *) awk 'NR > 1 && !/^#/ {exit} NR > 1 {sub(/^# ?/, ""); print}' "$0" >&2; exit 2 ;;
esac
