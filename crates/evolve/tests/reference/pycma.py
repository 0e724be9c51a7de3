"""pycma's evaluations to reach f <= 1e-8 on 10-D sphere, ellipsoid and
Rosenbrock, 10 seeds each, and on 120-D sphere and ellipsoid (condition
1e2), 3 seeds each: the reference for crates/evolve/tests/cma_es.rs.

    python3 -m venv venv && venv/bin/pip install cma numpy
    venv/bin/python crates/evolve/tests/reference/pycma.py > crates/evolve/tests/reference/pycma.json

Same protocol as the Rust test: x0 = 1 (sphere, ellipsoid) or 0
(Rosenbrock) in every coordinate, sigma0 = 0.5, pycma's defaults otherwise
(population 4 + floor(3 ln 10) = 10), at most 100,000 evaluations.
"""
import json
import warnings

warnings.filterwarnings("ignore")
import cma
import numpy as np

N = 10


def sphere(x):
    return float(np.sum(np.asarray(x) ** 2))


def ellipsoid(x):
    x = np.asarray(x)
    return float(sum(1e6 ** (i / (N - 1)) * x[i] ** 2 for i in range(N)))


def rosenbrock(x):
    x = np.asarray(x)
    return float(sum(100 * (x[i + 1] - x[i] ** 2) ** 2 + (1 - x[i]) ** 2 for i in range(N - 1)))


def run(f, x0, seed, n=N, maxfevals=100000):
    es = cma.CMAEvolutionStrategy(
        [x0] * n, 0.5, {"seed": seed, "verbose": -9, "ftarget": 1e-8, "maxfevals": maxfevals, "tolfun": 0, "tolx": 0, "tolfunhist": 0}
    )
    while not es.stop():
        xs = es.ask()
        es.tell(xs, [f(x) for x in xs])
        if es.result.fbest <= 1e-8:
            break
    return es.result.evaluations if es.result.fbest <= 1e-8 else None


out = {"pycma": cma.__version__, "dimension": N, "target": 1e-8, "sigma0": 0.5, "functions": {}}
for name, f, x0 in [("sphere", sphere, 1.0), ("ellipsoid", ellipsoid, 1.0), ("rosenbrock", rosenbrock, 0.0)]:
    evals = [run(f, x0, seed) for seed in range(1, 11)]
    done = sorted(e for e in evals if e is not None)
    out["functions"][name] = {"x0": x0, "evaluations": evals, "median": float(np.median(done)) if done else None}

# Above 64 genes CMA-ES decomposes its covariance by Householder and QL
# instead of Jacobi (crates/evolve/src/optimiser/eigen.rs): the sphere and
# an ellipsoid of condition 1e2 in 120 dimensions, 3 seeds each, the same
# protocol otherwise (at most 1,000,000 evaluations).
N_HIGH = 120


def ellipsoid_high(x):
    x = np.asarray(x)
    return float(np.sum(1e2 ** (np.arange(N_HIGH) / (N_HIGH - 1)) * x * x))


out["high"] = {"dimension": N_HIGH, "functions": {}}
for name, f in [("sphere", sphere), ("ellipsoid", ellipsoid_high)]:
    evals = [run(f, 1.0, seed, N_HIGH, 1000000) for seed in range(1, 4)]
    done = sorted(e for e in evals if e is not None)
    out["high"]["functions"][name] = {"x0": 1.0, "evaluations": evals, "median": float(np.median(done)) if done else None}
print(json.dumps(out, indent=1))
