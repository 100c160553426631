#!/bin/bash
# A/B on reference/bed.toml, pinned to core 0: A = main at a5e488a (built in a second worktree, same
# flags), B = a copy of branch cpuround3's build at the commit under test, L = LAMMPS serial (Debian's lmp)
# on the deck of `tetrasand export lammps`. usage: ab.sh ROUNDS LABEL B_BINARY [same|agree]
# same: every output of A and B compared with cmp; agree: run scripts/sim_outputs_agree.py after.
# A 5th argument replaces A (a copy of an earlier commit's build, to measure one change alone).
rounds=${1:-3}; label=${2:-ab}; B=${3:-/work/wt-cpuround3/build/bin/tetrasand}; check=${4:-same}
scene=/work/wt-cpuround3/assets/scenes/reference/bed.toml
A=${5:-/work/wt-cpuround3-base/build/bin/tetrasand}
out=/tmp/r3/runs/$label; mkdir -p $out
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
  if [ "$check" = same ]; then
    same=yes; for f in $out/A$r/*; do cmp -s $f $out/B$r/$(basename $f) || same=no; done
    echo "round $r: all $(ls $out/A$r | wc -l) output files of A and B identical: $same"
  fi
done
echo "end $(date -u +%T) load $(cut -d' ' -f1-3 /proc/loadavg)"
