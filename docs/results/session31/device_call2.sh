#!/usr/bin/env bash
# Session 31, device call 2 (H200): timing-only variants of the gather floor
# (floor_variants.diff on top of the floor's commit, VB_FLOOR_VARIANT): what each part of the
# step's memory work costs at 512k and 1.5M. 0 the floor as committed; 1 no grid reads (the full
# cube's neighbour index computed); 2 the predictor's neighbours in the packed layout (6 words, as
# the corrector's); 3 no neighbour velocity; 4 no neighbour reads (own data only: the step's 168 B
# streamed); 5 the 26 grid entries only.
set -u
o=$OUT
{
for v in 0 1 2 3 4 5 0; do
  echo "== variant $v"
  VOXBREAST_CL_OPTIONS=-DVB_FLOOR_VARIANT=$v bash scripts/gpu_run.sh run voxbreast bench --device gpu --quick --no-study --sizes 80 115 --out /tmp/b 2>&1 | grep -E "^block|gather floor|copy bandwidth"
done
} 2>&1 | tee $o/floor_variants_call2_h200.txt
