#!/bin/bash
for who in A B A B; do
  bin=/work/wt-cpuspeed-base/build/bin/tetrasand_bench_sim; [ $who = B ] && bin=/work/wt-cpuspeed/build/bin/tetrasand_bench_sim
  echo "$who start $(date -u +%T) load $(cut -d' ' -f1-3 /proc/loadavg)"
  LP_NUM_THREADS=1 timeout 400 $bin --grains 64000 --seconds 2 --min-steps 2 2>&1 | grep -E "grains +64000" 
done
echo "end $(date -u +%T) load $(cut -d' ' -f1-3 /proc/loadavg)"
