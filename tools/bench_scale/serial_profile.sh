#!/bin/sh
# serial_profile.sh BIN MESH METHOD [FRAMES]: where a two-worker frame's CPU goes, per thread.
#
# Runs `BIN --meshes MESH --methods METHOD --frames FRAMES --repeats 1 --workers 2` (BIN: a
# bench-scale binary) under `perf record -e cpu-clock --call-graph dwarf` and sorts every CPU
# sample by its stack: the caller's samples inside sc_tissue_step and not under the pool's
# pool_run are the step's serial part (grouped by the function sc_tissue_step called, and for
# the solvers one or two levels further), the rest the caller's share of the jobs, its hand-over
# and wait in pool_run, the worker's job work and its spin between jobs. Printed in CPU ms per
# step (samples / rate / steps; steps = 30 of bench-scale's press + FRAMES). Samples count CPU
# time only: on a loaded machine the wait figures grow, the work figures do not. The tissue's
# build is outside sc_tissue_step ("caller: outside the step"); a stack deeper than the 8 KB
# perf copies (the FEM's cell kernels) cannot be unwound and lands there too, so the job-work
# figures are a lower bound, the serial ones are not affected (shallow stacks).
# Needs perf (linux-perf). Output: TSV lines "ms/step <tab> where".
set -eu
BIN=$1; M=$2; X=$3; F=${4:-40}
RATE=2000
D=$(mktemp /tmp/serial_profile.XXXXXX)
trap 'rm -f "$D" "$D.old"' EXIT
perf record -q -e cpu-clock -F $RATE --call-graph dwarf,8192 -o "$D" -- \
    "$BIN" --meshes "$M" --methods "$X" --frames "$F" --repeats 1 --workers 2 >/dev/null 2>&1
perf script -F tid,ip,sym -i "$D" 2>/dev/null | awk -v rate=$RATE -v steps=$((30 + F)) '
function flush(   i, instep, injob, idle, s2, stage, key) {
  if (ns == 0) return
  instep = 0; injob = 0
  for (i = 1; i <= ns; i++) {
    if (st[i] == "sc_tissue_step") instep = i
    if (st[i] == "pool_run" || st[i] == "worker_main") injob = 1
  }
  idle = st[1] ~ /sched|yield|futex|syscall|schedule|pool_run|worker_main|now_ns|clock_gettime|vdso/
  stage = ""
  if (instep > 1) {
    s2 = st[instep - 1]; stage = s2
    if ((s2 == "step_kinematic" || s2 == "sc_fem_step_kinematic") && instep > 2) stage = s2 ">" st[instep - 2]
    if (instep > 3 && (st[instep - 2] == "sc_msds_implicit_step" || st[instep - 2] == "sc_fem_step_kinematic")) stage = stage ">" st[instep - 3]
  }
  if (tid != main) key = !injob ? "worker: not unwound (deep kernel stack)" : (idle ? "worker: spin / wait between jobs" : "worker: job work")
  else if (instep == 0) key = "caller: outside the step (build, not unwound)"
  else if (injob) key = idle ? "caller: hand-over / wait in pool_run" : "caller: job work"
  else key = "caller SERIAL: " stage
  n[key]++; ns = 0
}
/^ *[0-9]+ *$/ { flush(); tid = $1 + 0; if (main == "" || tid < main) main = tid; next }
/^$/ { flush(); next }
{ ns++; st[ns] = $2 }
END { flush(); for (k in n) printf "%.3f\t%s\n", n[k] / rate / steps * 1000.0, k }' | sort -t '	' -k2
