"""``python -m animats.evolve [SCENE] [--ray ADDRESS] ...``: ``animats
evolve`` from Python, here or spread over a Ray cluster; the same log.csv,
best.toml and checked.toml, bit for bit, for the same arguments, and the
same checks of the winner at the end (``--no-check`` skips them)."""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

from . import _animats
from .distributed import DEVICES


def main(argv: "list[str] | None" = None) -> int:
    p = argparse.ArgumentParser(
        prog="python -m animats.evolve",
        description="Evolve the roobot or a scene's [evolve] controller, locally or on Ray.",
    )
    p.add_argument("scene", nargs="?", default="roobot", help="a scene file with [evolve] (default: the roobot)")
    p.add_argument(
        "--optimiser",
        choices=["hill-climber", "ga", "cma-es", "body-ga", "map-elites", "cma-me"],
        help="default: the scene's [evolve] optimiser, else cma-es (body-ga for a [morphology] scene; the roobot: hill-climber)",
    )
    p.add_argument("--population", type=int)
    p.add_argument("--restarts", type=int, default=0)
    p.add_argument("--generations", type=int, default=100)
    p.add_argument("--lanes", type=int)
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--out", default="evolution", help="directory for log.csv and best.toml")
    p.add_argument("--ray", metavar="ADDRESS", help="run on a Ray cluster: `auto`, HOST:PORT, or `local`")
    p.add_argument("--actors", type=int, default=2, help="Ray actors (with --ray)")
    p.add_argument("--threads", type=int, help="threads (without --ray)")
    p.add_argument(
        "--device",
        choices=DEVICES,
        default="cpu",
        help="where evaluations run: cpu (default), cuda or cuda-fast (here, or one GPU a Ray actor)",
    )
    p.add_argument(
        "--no-check",
        action="store_true",
        help="skip the end's checks of the winner at a quarter of the step (and checked.toml)",
    )
    a = p.parse_args(argv)
    start = time.perf_counter()
    # `animats evolve`'s arguments, the same here and on Ray.
    run_args = dict(
        lanes=a.lanes,
        generations=a.generations,
        seed=a.seed,
        optimiser=a.optimiser,
        population=a.population,
        restarts=a.restarts,
    )
    try:
        if a.ray is None:
            run = _animats.Evolution(a.scene, **run_args, device=a.device)
            run.run(threads=a.threads)
            run.save(a.out)
            how = "here"
        else:
            from . import distributed

            run, stats = distributed.evolve(
                a.scene,
                **run_args,
                actors=a.actors,
                device=a.device,
                address=None if a.ray == "local" else a.ray,
                out=a.out,
                progress=True,
                check=False,  # below, after the clock, as here
            )
            how = f"on Ray, {a.actors} actors, {stats.retries} shares retried"
        took = time.perf_counter() - start
        # The winner checked at a quarter of the step, as `animats evolve`
        # does at its end: checked.toml, or an earlier one removed.
        checked = False
        if a.no_check:
            Path(a.out, "checked.toml").unlink(missing_ok=True)
        else:
            report = run.check(a.out)
            if report is not None:
                for line in report["lines"]:
                    print(f"  {line}")
                checked = report["checked"] is not None
    except (ValueError, OSError, RuntimeError) as e:
        print(f"error: {e}", file=sys.stderr)
        return 1
    print(
        f"{run.generation} generations, {run.evaluations} evaluations {how} in "
        f"{took:.2f} s; best fitness {run.best_fitness}; "
        f"wrote {a.out}/log.csv, best.toml{', checked.toml' if checked else ''}"
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
