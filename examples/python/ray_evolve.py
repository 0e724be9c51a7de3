"""An evolution spread over Ray actors; the same log.csv, bit for bit, as
`animats evolve` with the same arguments. Locally: `python
examples/python/ray_evolve.py`; on a cluster, after `ray start --head` (and
`ray start --address=HEAD:6379` on the others), pass `auto`."""

import sys
import time

from animats import distributed

address = sys.argv[1] if len(sys.argv) > 1 else None
start = time.perf_counter()
run, stats = distributed.evolve(
    "scenes/walker.toml",
    optimiser="cma-es",
    generations=50,
    lanes=2,
    seed=1,
    actors=2,
    address=address,
    out="walker-ray",
)
print(
    f"{run.evaluations} evaluations in {time.perf_counter() - start:.1f} s on "
    f"{len(stats.pids)} actors ({stats.retries} shares retried); best {run.best_fitness:.3f}"
)
print("the same as: animats evolve scenes/walker.toml --optimiser cma-es "
      "--generations 50 --lanes 2 --seed 1 --out walker-cli")
