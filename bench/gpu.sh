#!/usr/bin/env bash
# Issue 42 on a lent GPU machine. First random bodies of springs, angle and
# torque joints dropped onto the floor, stepped by the engine on every
# core, by the C on every core and by the GPU, every coordinate compared
# as bits; then whole evaluations: 65,536 soft walkers (random oscillator
# genomes) and 65,536 random evolved bodies (self-contact, spring muscles),
# each evaluated for 10 s by the engine on every core, by the C and by the
# GPU, every fitness compared as bits; the throughput of each.
#
# Builds nothing: it takes the examples built here, carried in an ignored
# folder:
#   cargo build --release -p animats-gpu --example gpu_check --example gpu_evaluate
#   mkdir -p target/carry && cp target/release/examples/gpu_{check,evaluate} target/carry/
#   bench/gpu.sh
# About three minutes on an H100 machine with 16 cores. Exit 1 if any bit
# differs, 2 if no GPU can be used (the message says why).
set -uo pipefail
cd "$(dirname "$0")/.."
bin() {
  local b="target/carry/$1"
  [ -x "$b" ] || b="target/release/examples/$1"
  [ -x "$b" ] || { echo "no $1 binary: build it (see the top of this file)" >&2; exit 2; }
  echo "$b"
}
B=$(bin gpu_check) || exit 2
E=$(bin gpu_evaluate) || exit 2
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
for run in "walker 65536 10" "bodies 65536 10"; do
  echo "== gpu_evaluate $run"
  # shellcheck disable=SC2086
  "$E" $run
  rc=$?
  [ $rc -gt $status ] && status=$rc
done
exit $status
