#!/bin/bash
# A/B at 64k on llvmpipe, back to back: baseline (main 0141393) then this branch.
date; uptime
LP_NUM_THREADS=1 TETRASAND_SHADER_DIR=/work/baseline-0141393/shaders timeout 900 /work/baseline-0141393/tetrasand_bench_sim --grains 64000 --seconds 2 --timings --csv /tmp/gpulists-bench/ab_base64k.csv
date; uptime
LP_NUM_THREADS=1 timeout 900 /work/wt-gpulists/build-dev/bin/tetrasand_bench_sim --grains 64000 --seconds 2 --timings --csv /tmp/gpulists-bench/ab_new64k.csv
date; uptime
