#!/usr/bin/env python3
"""animats.evaluate from Python against `animats evolve`'s own parallel
evaluation (issue 41: "the same efficiency as the CLI"): a population of
the walker's genomes evaluated on 1 and 2 threads, best of `ROUNDS` timed
calls each, alternated; prints evaluations per second and the speed-up.
Run with the package installed (pip install ./crates/py):

    python3 bench/python_scaling.py [SCENE] [POPULATION]
"""
import sys
import time

import numpy as np

import animats

scene_path = sys.argv[1] if len(sys.argv) > 1 else "scenes/walker.toml"
population = int(sys.argv[2]) if len(sys.argv) > 2 else 64
ROUNDS = 5

scene = animats.load(scene_path)
bounds = np.asarray(scene.bounds())
rng = np.random.default_rng(1)
genomes = rng.uniform(bounds[:, 0], bounds[:, 1], size=(population, len(bounds)))

evaluators = {t: animats.Evaluator(scene, threads=t) for t in (1, 2)}
calls = {
    "evaluate": lambda t: animats.evaluate(scene, genomes, threads=t),
    "Evaluator": lambda t: evaluators[t].evaluate(genomes),
}
for name, call in calls.items():
    results = {1: None, 2: None}
    best = {1: float("inf"), 2: float("inf")}
    for _ in range(ROUNDS):
        for t in (1, 2):
            start = time.perf_counter()
            fitness = call(t)
            best[t] = min(best[t], time.perf_counter() - start)
            if results[t] is not None:
                assert np.array_equal(results[t], fitness)
            results[t] = fitness
    assert np.array_equal(results[1], results[2]), "threads changed the fitness"
    print(
        f"{name:10s} {scene_path}, {population} genomes: "
        f"1 thread {population / best[1]:.1f}/s, 2 threads {population / best[2]:.1f}/s, "
        f"{best[1] / best[2]:.2f}x (best of {ROUNDS})"
    )
