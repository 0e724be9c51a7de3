#!/usr/bin/env bash
# Issue 42 on a lent GPU machine: random bodies of springs, angle and
# torque joints (what the C step covers today; the walker needs the floor)
# stepped by the engine on every core, by the C on every core and by the
# GPU, every coordinate compared as bits, and the throughput of each.
#
# Builds nothing: it takes the example built here, carried in an ignored
# folder:
#   cargo build --release -p animats-gpu --example gpu_check
#   mkdir -p target/carry && cp target/release/examples/gpu_check target/carry/
#   bench/gpu.sh          # GPU_CHECK=path/to/gpu_check to choose another
# About a minute on an H100 machine with 16 cores. Exit 1 if any bit
# differs, 2 if no GPU can be used (the message says why).
set -uo pipefail
cd "$(dirname "$0")/.."
B=${GPU_CHECK:-target/carry/gpu_check}
[ -x "$B" ] || B=target/release/examples/gpu_check
[ -x "$B" ] || { echo "no gpu_check binary: build it (see the top of this file)" >&2; exit 2; }
# NVRTC (and its builtins) where the lent machines keep CUDA 13's.
export LD_LIBRARY_PATH="/usr/local/cuda/targets/x86_64-linux/lib:/usr/local/cuda/lib64:${LD_LIBRARY_PATH:-}"
echo "machine: $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //'), $(nproc) cores; $(date -u +%Y-%m-%dT%H:%MZ)"
command -v nvidia-smi >/dev/null && nvidia-smi --query-gpu=name,driver_version,memory.total --format=csv,noheader
status=0
for run in "65536 1000 20" "65536 1000 0" "262144 200 20"; do
  echo "== gpu_check $run"
  # shellcheck disable=SC2086
  "$B" $run
  rc=$?
  [ $rc -gt $status ] && status=$rc
done
exit $status
