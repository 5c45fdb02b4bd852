#!/usr/bin/env bash
# Session 23, device call 5 (H200): what a 24-byte neighbour read would be worth (the untried
# layout u.xyz, v.xyz in 24 B instead of u, v as two float4): a timing-only variant of the short
# loop (-DVB_EXP_V2=1: the neighbour's v read as 8 bytes, float4 + float2 per neighbour, the same
# load shape as the packed layout; wrong forces, never merged) against main's loop, 512k and 1.5M
# cubes, linear + Heun float, three rounds interleaved, --profile in the first.
set -u
G="bash scripts/gpu_run.sh run"
o=$OUT
{
for r in 1 2 3; do
  p=; [ $r = 1 ] && p=--profile
  for v in main v2; do
    opt=; [ $v = v2 ] && opt=-DVB_EXP_V2=1
    echo "== r$r $v"
    VOXBREAST_CL_OPTIONS="$opt" timeout 100 $G voxbreast bench --device gpu --quick --no-study --sizes 80 115 $p --out /tmp/t 2>&1 | grep -E "^block|device alone"
  done
done
} 2>&1 | tee $o/v2_h200.txt
