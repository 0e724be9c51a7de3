#!/usr/bin/env python3
"""Replays a one-lane run's schedule.csv on 1-64 workers, as `evolve
--schedule`'s model does (the lane's ask, its children made side by side,
its evaluations side by side in the order they started, its tell; greedy
list scheduling), and again with each evaluation's finer runs (a robust
scene's runs at half the step) as a piece of their own that may run
beside the evaluation's first run: every needed finer run started at once
and none wasted, an upper bound of what starting them early could give.

    git apply bench/finer/finer_trace.patch && cargo build --release -p animats
    target/release/animats evolve scenes/bodies_walk.toml --generations 60 --seed 1 \\
        --threads 2 --schedule --no-check --out run 2> run.err
    python3 bench/finer/replay.py run/schedule.csv run.err

The patch makes each traced evaluation print `FINER,lane,generation,
candidate,seconds` on stderr: the seconds its finer runs took.
"""
import collections
import csv
import heapq
import sys


def list_schedule(durations, workers):
    free = [0.0] * workers
    end = 0.0
    for d in durations:
        t = heapq.heappop(free) + d
        end = max(end, t)
        heapq.heappush(free, t)
    return end


def main(schedule, stderr):
    finer = {}
    for line in open(stderr):
        if line.startswith("FINER,"):
            _, k, g, i, f = line.strip().split(",")
            finer[(int(k), int(g), int(i))] = float(f)
    gens = collections.defaultdict(lambda: {"serial": 0.0, "vary": [], "eval": []})
    lanes = set()
    for r in csv.DictReader(open(schedule)):
        lanes.add(r["lane"])
        g, piece, s = int(r["generation"]), r["piece"], float(r["seconds"])
        if piece in ("ask", "tell"):
            gens[g]["serial"] += s
        elif piece == "vary":
            gens[g]["vary"].append(s)
        elif piece == "evaluate":
            key = (int(r["lane"]), g, int(r["candidate"]))
            gens[g]["eval"].append((int(r["position"]), s, finer.get(key)))
    if len(lanes) != 1:
        sys.exit(f"{schedule}: {len(lanes)} lanes; this replay is for one lane")
    missing = sum(1 for G in gens.values() for e in G["eval"] if e[2] is None)
    if missing:
        sys.exit(f"{stderr}: no FINER line for {missing} evaluations (is the patch applied?)")

    def wall(workers, split):
        t = 0.0
        for g in sorted(gens):
            G = gens[g]
            t += G["serial"] + list_schedule(G["vary"], workers)
            ev = sorted(G["eval"])
            if split:
                durations = sorted(
                    (d for _, s, f in ev for d in (s - f, f) if d > 0), reverse=True
                )
            else:
                durations = [s for _, s, _ in ev]
            t += list_schedule(durations, workers)
        return t

    work = wall(1, False)
    with_finer = [f for G in gens.values() for _, _, f in G["eval"] if f > 1e-4]
    print(
        f"{sum(len(G['eval']) for G in gens.values())} evaluations, {len(with_finer)} with finer runs "
        f"({sum(with_finer):.3f} s of {work:.3f} s of work)"
    )
    print("workers  as recorded         finer runs beside their first")
    for w in (1, 2, 4, 8, 16, 32, 64):
        a, b = wall(w, False), wall(w, True)
        print(f"{w:>7}  {a:8.3f} s {work / a:6.2f}×   {b:8.3f} s {work / b:6.2f}×")


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit("usage: replay.py RUN/schedule.csv RUN.err")
    main(sys.argv[1], sys.argv[2])
