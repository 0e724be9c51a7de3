"""pyribs's QD scores on the benchmark of its own examples/sphere.py: the
reference for crates/evolve/tests/qd.rs.

    python3 -m venv venv && venv/bin/pip install "ribs==0.12.0" numpy
    venv/bin/python crates/evolve/tests/reference/pyribs.py > crates/evolve/tests/reference/pyribs.json

The benchmark as sphere.py has it: 100-D sphere shifted to 2.048 and
normalised to [0, 100], measures the sums of the first and last 50 clipped
genes (a gene outside [-5.12, 5.12] counts as 5.12 / x), a 100 x 100
GridArchive over [-256, 256]^2, x0 = 0. Its two configurations:

- map_elites: one GaussianEmitter, sigma 0.5, 540 solutions an iteration;
- cma_me_imp: 15 EvolutionStrategyEmitters, sigma0 0.5, ranker "2imp",
  selection "filter", restart "no_improvement", 36 solutions each.

The budget is ITERATIONS iterations (540 evaluations each), not sphere.py's
10,000, so that CI can regenerate these figures in about a minute; 10 seeds
each, the median QD score (pyribs's: objectives offset by 0).
"""
import json
import sys

import numpy as np
import ribs
from ribs.archives import GridArchive
from ribs.emitters import EvolutionStrategyEmitter, GaussianEmitter
from ribs.schedulers import Scheduler

DIM = 100
ITERATIONS = int(sys.argv[1]) if len(sys.argv) > 1 else 100
SEEDS = range(1, 11)


def sphere(solutions):
    shift = 5.12 * 0.4
    worst = (-5.12 - shift) ** 2 * DIM
    raw = np.sum(np.square(solutions - shift), axis=1)
    objectives = (raw - worst) / (0.0 - worst) * 100
    clipped = solutions.copy()
    mask = (clipped < -5.12) | (clipped > 5.12)
    clipped[mask] = 5.12 / clipped[mask]
    measures = np.stack(
        (np.sum(clipped[:, : DIM // 2], axis=1), np.sum(clipped[:, DIM // 2 :], axis=1)),
        axis=1,
    )
    return objectives, measures


def scheduler(algorithm, seed):
    bound = DIM / 2 * 5.12
    archive = GridArchive(
        solution_dim=DIM, dims=(100, 100), ranges=[(-bound, bound)] * 2, seed=seed
    )
    seeds = np.random.SeedSequence(seed)
    x0 = np.zeros(DIM)
    if algorithm == "map_elites":
        emitters = [
            GaussianEmitter(archive, x0=x0, sigma=0.5, batch_size=540, seed=s)
            for s in seeds.spawn(1)
        ]
    else:
        emitters = [
            EvolutionStrategyEmitter(
                archive,
                x0=x0,
                sigma0=0.5,
                ranker="2imp",
                selection_rule="filter",
                restart_rule="no_improvement",
                batch_size=36,
                seed=s,
            )
            for s in seeds.spawn(15)
        ]
    return archive, Scheduler(archive, emitters)


def run(algorithm, seed):
    archive, sched = scheduler(algorithm, seed)
    for _ in range(ITERATIONS):
        solutions = sched.ask()
        objectives, measures = sphere(solutions)
        sched.tell(objectives, measures)
    s = archive.stats
    return {"qd_score": float(s.qd_score), "coverage": float(s.coverage), "obj_max": float(s.obj_max)}


out = {
    "ribs": ribs.__version__,
    "dimension": DIM,
    "grid": [100, 100],
    "iterations": ITERATIONS,
    "evaluations": ITERATIONS * 540,
    "algorithms": {},
}
for algorithm in ["map_elites", "cma_me_imp"]:
    runs = [run(algorithm, seed) for seed in SEEDS]
    scores = sorted(r["qd_score"] for r in runs)
    out["algorithms"][algorithm] = {
        "qd_score": [r["qd_score"] for r in runs],
        "coverage": [r["coverage"] for r in runs],
        "obj_max": [r["obj_max"] for r in runs],
        "median_qd_score": (scores[4] + scores[5]) / 2,
    }
print(json.dumps(out, indent=1))
