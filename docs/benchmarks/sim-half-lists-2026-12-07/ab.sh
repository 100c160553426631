#!/bin/bash
# A/B: base (main at faf7526) vs branch, and LAMMPS serial, on reference/bed.toml, pinned to core 0.
# usage: ab.sh ROUNDS LABEL
# A: tetrasand built at faf7526 (before the half lists) and copied aside; B: the branch's build; L: LAMMPS.
# Set 1 and 2 of ab_bed.log ran B at 35a4ab5, set 3 at the commit that stores touching pairs compactly.
rounds=${1:-3}; label=${2:-ab}
scene=/work/wt-cpuspeed/assets/scenes/reference/bed.toml
A=/tmp/cs_base/bin/tetrasand
B=/work/wt-cpuspeed/build/bin/tetrasand
out=/tmp/cs_runs/$label; mkdir -p $out
[ -f $out/deck/in.tetrasand ] || $A export lammps $scene -o $out/deck >/dev/null
echo "start $(date -u +%T) load $(cut -d' ' -f1-3 /proc/loadavg)"
for r in $(seq 1 $rounds); do
  for who in A B L; do
    case $who in
      A) cmd=(taskset -c 0 $A sim $scene -o $out/A$r --backend cpu) ;;
      B) cmd=(taskset -c 0 $B sim $scene -o $out/B$r --backend cpu) ;;
      L) cmd=(bash -c "cd $out/deck && taskset -c 0 lmp -in in.tetrasand -log log.lammps -screen none") ;;
    esac
    rm -rf $out/$who$r
    /usr/bin/time -f "$who round $r: wall %e s user %U s sys %S s" "${cmd[@]}" > $out/$who$r.log 2> $out/$who$r.time
    tail -1 $out/$who$r.time
  done
  same=yes; for f in $out/A$r/*; do cmp -s $f $out/B$r/$(basename $f) || same=no; done
  echo "round $r: all $(ls $out/A$r | wc -l) output files of A and B identical: $same"
done
echo "end $(date -u +%T) load $(cut -d' ' -f1-3 /proc/loadavg)"
