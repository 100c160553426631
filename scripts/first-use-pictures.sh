#!/usr/bin/env bash
# Pictures of first use (issue 17), into docs/images/first-use/ (shown in docs/first-use.md, the guide, and
# in docs/benchmarks/history.md, the before/after record of issue 17):
#   dino-before.png   `sample --preview --up 0,1,0`: the old y-up default, CGAL's z-up dino on its side
#   dino-after.png    `sample --preview`: the default +z up, the dino standing
#   drop-before.png   prop_drop's last frame as the old frames showed it: 640x480, no walls, the camera
#                     the old writer fixed at the first frame (the iso view of the first frame's
#                     particles, the emitters' regions and the walls' plane points; computed below from
#                     the first frame's particle dump and given as [output.camera] eye/target)
#   drop-after.png    prop_drop's last frame with the new defaults (960x720, default camera, walls)
#   drop-sheet.png    `tetrasand frames` of the new run: a contact sheet (or movie.mp4 with ffmpeg)
# Usage: scripts/first-use-pictures.sh [TETRASAND]  (default: build-test/bin/tetrasand). Runs the scene on
# the CPU reference (deterministic) and renders through EGL (llvmpipe will do): about a minute or two.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
bin=${1:-$root/build-test/bin/tetrasand}
out=$root/docs/images/first-use
mkdir -p "$out"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

# 1. The dino, sampled once per up axis (same seed and radius; only the preview's up differs).
tar -xzf /usr/share/doc/libcgal-dev/data.tar.gz -C "$tmp" data/meshes/dino.off
"$bin" -q sample "$tmp/data/meshes/dino.off" -o "$tmp/dino-before" --preview --up 0,1,0 --count 3000 > /dev/null
"$bin" -q sample "$tmp/data/meshes/dino.off" -o "$tmp/dino-after" --preview --count 3000 > /dev/null

# $1 shrunk to $2, no wider than $3 pixels (the frames command's contact sheet of one tile).
shrink() {
  mkdir -p "$tmp/shrink" && rm -f "$tmp/shrink"/*
  cp "$1" "$tmp/shrink/frame_000000.png"
  "$bin" -q frames "$tmp/shrink" -o "$2" --tiles 1 --columns 1 --tile-width "$3" --no-labels > /dev/null
}
shrink "$tmp/dino-before/dino.preview.png" "$out/dino-before.png" 480
shrink "$tmp/dino-after/dino.preview.png" "$out/dino-after.png" 480

# 2. prop_drop: the bundled scene with frames on, its body path made absolute.
scene() {  # $1: extra [output] keys and tables
  sed -e "s|\"../bodies/cube.body.json\"|\"$root/assets/bodies/cube.body.json\"|" \
      -e "s|^ply = true|ply = true\nframes = true\n$1|" "$root/assets/scenes/prop_drop.toml"
}
scene "" > "$tmp/after.toml"
"$bin" -q sim "$tmp/after.toml" -o "$tmp/after" --cpu > /dev/null
last=$(ls "$tmp/after"/frame_*.png | tail -1)
shrink "$last" "$out/drop-after.png" 640
"$bin" -q frames "$tmp/after" -o "$out/drop-sheet.png" --tiles 8 --columns 4 --tile-width 192 > /dev/null

# The old writer's camera: preview::frame_box (margin 1.08, fov 30 degrees, aspect 4:3) of the first
# frame's particle spheres, the fill emitter's box and the points of the box's five planes, from the iso
# direction (1, -1, 1) / sqrt 3 with +z up.
camera=$(python3 - "$tmp/after/particles_000000.ply" <<'EOF'
import math, struct, sys
data = open(sys.argv[1], 'rb').read()
head_end = data.index(b'end_header\n') + len(b'end_header\n')
count = int([l for l in data[:head_end].decode().splitlines() if l.startswith('element vertex')][0].split()[2])
lo, hi = [math.inf] * 3, [-math.inf] * 3
def extend(p):
    for k in range(3):
        lo[k], hi[k] = min(lo[k], p[k]), max(hi[k], p[k])
for i in range(count):
    x, y, z, r, _ = struct.unpack_from('<ffffI', data, head_end + 20 * i)
    extend((x - r, y - r, z - r)); extend((x + r, y + r, z + r))
for p in [(-0.1, -0.1, 0.002), (0.1, 0.1, 0.2), (0, 0, 0), (-0.1, 0, 0.3), (0.1, 0, 0.3), (0, -0.1, 0.3), (0, 0.1, 0.3)]:
    extend(p)
centre = [(a + b) / 2 for a, b in zip(lo, hi)]
back = [v / math.sqrt(3) for v in (1, -1, 1)]
up = (0, 0, 1)
cross = lambda a, b: (a[1]*b[2] - a[2]*b[1], a[2]*b[0] - a[0]*b[2], a[0]*b[1] - a[1]*b[0])
dot = lambda a, b: sum(x * y for x, y in zip(a, b))
right = cross(up, back); n = math.sqrt(dot(right, right)); right = [v / n for v in right]
image_up = cross(back, right)
tan_y = math.tan(math.radians(15)); tan_x = tan_y * 4 / 3
need = 0
for i in range(8):
    c = [hi[k] if i >> k & 1 else lo[k] for k in range(3)]
    d = [a - b for a, b in zip(c, centre)]
    need = max(need, dot(d, back) + abs(dot(d, right)) / tan_x, dot(d, back) + abs(dot(d, image_up)) / tan_y)
eye = [c + b * 1.08 * need for c, b in zip(centre, back)]
print('eye = [%.6f, %.6f, %.6f]\ntarget = [%.6f, %.6f, %.6f]' % (*eye, *centre))
EOF
)
scene "walls = false\n[output.camera]\nsize = [640, 480]\n${camera//$'\n'/\\n}" > "$tmp/before.toml"
"$bin" -q sim "$tmp/before.toml" -o "$tmp/before" --cpu > /dev/null
cp "$(ls "$tmp/before"/frame_*.png | tail -1)" "$out/drop-before.png"

ls -l "$out"
echo "old camera of drop-before.png: ${camera//$'\n'/, }"
