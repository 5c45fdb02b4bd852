#!/usr/bin/env bash
# Session 25, device call 9 (H200): the prototype's stage pair (layout 5) built with main's options
# and with each of the fast-math options added: is the prototype's lead over main's step (168 against
# ~190 µs) its build options?
set -u
G="bash scripts/gpu_run.sh run"
o=$OUT
P=docs/results/session25/proto_walk.cl
M="-cl-std=CL1.2 -cl-mad-enable -cl-denorms-are-zero"
{
for r in 1 2; do
for opts in "-cl-fast-relaxed-math -cl-mad-enable -cl-denorms-are-zero" "$M" "$M -cl-no-signed-zeros" "$M -cl-finite-math-only" "$M -cl-unsafe-math-optimizations" "$M -cl-finite-math-only -cl-no-signed-zeros"; do
  echo "== $opts"
  PROTO_OPTS="$opts" timeout 60 $G .device-pkgs/proto_walk 115 2000 $P "5" "1" 128 "0" | grep steps
done; done
} 2>&1 | tee $o/options_h200.txt
