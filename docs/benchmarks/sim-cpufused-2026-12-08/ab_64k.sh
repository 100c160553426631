#!/bin/bash
# tetrasand_bench_sim --grains 64000 (settled bed, CPU reference on TBB, 2 shared cores; the GPU pipeline
# on llvmpipe in the same run), alternating A = main at bcbf881 and B = branch cpufused.
for who in A B A B; do
  bin=/work/wt-cpufused-base/build/bin/tetrasand_bench_sim; [ $who = B ] && bin=/work/wt-cpufused/build/bin/tetrasand_bench_sim
  echo "$who start $(date -u +%T) load $(cut -d' ' -f1-3 /proc/loadavg)"
  LP_NUM_THREADS=1 timeout 400 $bin --grains 64000 --seconds 2 --min-steps 2 2>&1 | grep -E "grains|64000"
done
echo "end $(date -u +%T) load $(cut -d' ' -f1-3 /proc/loadavg)"
