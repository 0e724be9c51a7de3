#!/usr/bin/env bash
# Evolution's scaling with threads (issue 41): the issue's three runs,
# the quadruped's and the walker's again without the winner's checks at
# the end (the issue's figures were measured before evolve checked its
# winner: the checks are serial work the evaluations' scaling leaves out),
# [morphology] runs (bodies and brains evolving: 16 lanes of the body GA;
# the shipped land task, MAP-Elites in one lane, 36 bodies a generation,
# 144, and 36 with its generations overlapping)
# at 1, 2, 4, 8 and 16 threads, wall time and speed-up each, every log
# checked identical; then the schedule model's prediction (`evolve
# --schedule`, recorded in each row's 1-thread run), to set beside the measured.
#
# Builds nothing: it takes the release binary built elsewhere (carry it to
# a many-core machine in an ignored folder):
#   cargo build --release && mkdir -p target/carry && cp target/release/animats target/carry/
#   bench/scaling.sh                    # ANIMATS=path/to/animats to choose another
# Then the machine's ceiling (CEILING=0 leaves it out): the roobot and the
# walker as N independent 1-thread processes at once, N the last thread count;
# and each row once more on N threads with --schedule, whose summed work
# against the first run's says how much slower an evaluation runs with every
# thread busy (about 10 s more on 16 cores).
# About 4 minutes on 16 cores (137 s on the H200 machine's Xeon,
# 2026-11-30, before the two rows without checks, the ceiling and the
# work); prints Markdown tables for PERFORMANCE.md. Needs bash and awk only
# (the lent machines have no bc).
set -euo pipefail
cd "$(dirname "$0")/.."
B=${ANIMATS:-target/carry/animats}
[ -x "$B" ] || B=target/release/animats
[ -x "$B" ] || { echo "no animats binary: build it (cargo build --release)" >&2; exit 2; }
THREADS=${THREADS:-"1 2 4 8 16"}
OUT=$(mktemp -d)
trap 'rm -rf "$OUT"' EXIT
# The land task with its generations overlapping ([archive] overlap).
sed 's/^tournament = 4.*/&\noverlap = true/' scenes/bodies_walk.toml > "$OUT/bodies_walk_overlap.toml"
grep -q '^overlap = true' "$OUT/bodies_walk_overlap.toml" || { echo "scenes/bodies_walk.toml: no tournament line to add overlap after" >&2; exit 2; }
echo "machine: $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //'), $(nproc) cores; $(date -u +%Y-%m-%d)"
# Whether the "cores" are hyperthreads of fewer physical cores (two threads
# of one core share its units: a 16-thread speed-up is then bounded well
# under 16 by the machine, whatever the program does).
if command -v lscpu > /dev/null; then
  lscpu | grep -E '^(Thread\(s\) per core|Core\(s\) per socket|Socket\(s\)|NUMA node\(s\)|CPU max MHz|L2 cache|L3 cache):' | tr -s ' ' | paste -sd ';' -
fi
rows=(
  "roobot|--optimiser cma-es --lanes 16 --generations 40 --seed 1"
  "walker|scenes/walker.toml --optimiser cma-es --lanes 16 --generations 10 --seed 1"
  "quadruped3|scenes/quadruped3_gait.toml --optimiser cma-es --lanes 16 --generations 5 --seed 1"
  "quadruped3_no_check|scenes/quadruped3_gait.toml --optimiser cma-es --lanes 16 --generations 5 --seed 1 --no-check"
  "walker_no_check|scenes/walker.toml --optimiser cma-es --lanes 16 --generations 10 --seed 1 --no-check"
  "bodies_walk|scenes/bodies_walk.toml --optimiser body-ga --lanes 16 --generations 2 --seed 1"
  "bodies_map|scenes/bodies_walk.toml --generations 20 --seed 1 --no-check"
  "bodies_map_144|scenes/bodies_walk.toml --population 144 --generations 5 --seed 1 --no-check"
  "bodies_map_overlap|$OUT/bodies_walk_overlap.toml --generations 20 --seed 1 --no-check"
)
header="| run |"; rule="|---|"
for t in $THREADS; do header+=" $t |"; rule+="---|"; done
echo; echo "$header speed-up at ${THREADS##* } |"; echo "$rule---|"
for row in "${rows[@]}"; do
  name=${row%%|*}; args=${row#*|}
  line="| $name |"; first=""; last=""
  for t in $THREADS; do
    # The first run records its schedule too (the log is the same bits
    # with the flag; the recording costs a clock read per evaluation).
    sched=""
    [ "$t" = "${THREADS%% *}" ] && sched="--schedule"
    start=$(date +%s.%N)
    # shellcheck disable=SC2086
    "$B" evolve $args --threads "$t" $sched --out "$OUT/$name-$t" > "$OUT/$name-$t.txt" 2>&1
    wall=$(awk -v a="$start" -v b="$(date +%s.%N)" 'BEGIN { print b - a }')
    [ -z "$first" ] && first=$wall
    last=$wall
    if ! cmp -s "$OUT/$name-${THREADS%% *}/log.csv" "$OUT/$name-$t/log.csv"; then
      echo "$name: the log at $t threads differs from the first" >&2; exit 1
    fi
    line+=" $(printf '%.2f' "$wall") s |"
  done
  echo "$line $(awk -v a="$first" -v b="$last" 'BEGIN { printf "%.1f", a / b }')× |"
done
# The machine's own ceiling: N independent copies of a 1-thread run at once
# (separate processes, nothing shared but the machine) against one alone.
# N × alone / together is the most N threads can give this workload here:
# shared caches, memory, hyperthreads and clocks that drop with more busy
# cores all show in it; the rows above are judged against it.
N=${THREADS##* }
if [ "${CEILING:-1}" != 0 ] && [ "$N" -gt 1 ]; then
  echo
  echo "machine ceiling: $N copies of a 1-thread run at once, against one alone (--no-check)"
  echo "| run | one alone | $N at once | ceiling at $N |"
  echo "|---|---|---|---|"
  # The first two rows: the roobot and the walker.
  for row in "${rows[0]}" "${rows[1]}"; do
    name=${row%%|*}; args=${row#*|}
    start=$(date +%s.%N)
    # shellcheck disable=SC2086
    "$B" evolve $args --no-check --threads 1 --out "$OUT/ceiling-$name-alone" > /dev/null 2>&1
    alone=$(awk -v a="$start" -v b="$(date +%s.%N)" 'BEGIN { print b - a }')
    start=$(date +%s.%N)
    pids=()
    for k in $(seq 1 "$N"); do
      # shellcheck disable=SC2086
      "$B" evolve $args --no-check --threads 1 --out "$OUT/ceiling-$name-$k" > /dev/null 2>&1 &
      pids+=($!)
    done
    for p in "${pids[@]}"; do wait "$p"; done
    together=$(awk -v a="$start" -v b="$(date +%s.%N)" 'BEGIN { print b - a }')
    for k in $(seq 1 "$N"); do
      cmp -s "$OUT/ceiling-$name-alone/log.csv" "$OUT/ceiling-$name-$k/log.csv" ||
        { echo "$name: copy $k's log differs from the run alone" >&2; exit 1; }
    done
    echo "| $name | $(printf '%.2f' "$alone") s | $(printf '%.2f' "$together") s | $(awk -v n="$N" -v a="$alone" -v t="$together" 'BEGIN { printf "%.1f", n * a / t }')× |"
  done
fi
# How much slower each evaluation runs with every thread busy: the work
# the schedule records (every piece's own wall time, summed) in a run on
# the most threads, against the first run's. 1.0× is no slowdown; what is
# above it is contention (caches, memory, clocks), not waiting.
if [ "$N" != "${THREADS%% *}" ]; then
  echo
  echo "evaluation work at $N threads against ${THREADS%% *} (evolve --schedule, a run of its own; work summed over pieces):"
  echo "| run | work at ${THREADS%% *} | work at $N | per-piece slowdown |"
  echo "|---|---|---|---|"
  work() { sed -n 's/.* \([0-9.]*\) s of work in .*/\1/p' "$1" | head -1; }
  for row in "${rows[@]}"; do
    name=${row%%|*}; args=${row#*|}
    # shellcheck disable=SC2086
    "$B" evolve $args --threads "$N" --schedule --out "$OUT/$name-work" > "$OUT/$name-work.txt" 2>&1
    cmp -s "$OUT/$name-${THREADS%% *}/log.csv" "$OUT/$name-work/log.csv" ||
      { echo "$name: the log of the run with --schedule at $N threads differs" >&2; exit 1; }
    a=$(work "$OUT/$name-${THREADS%% *}.txt"); b=$(work "$OUT/$name-work.txt")
    echo "| $name | $a s | $b s | $(awk -v a="$a" -v b="$b" 'BEGIN { printf "%.2f", b / a }')× |"
  done
fi
echo
echo "schedule model (evolve --schedule), from each row's ${THREADS%% *}-thread run above:"
for row in "${rows[@]}"; do
  name=${row%%|*}
  echo "== $name"
  sed -n '/^schedule:/,/^wrote .*schedule.csv/p' "$OUT/$name-${THREADS%% *}.txt"
done
