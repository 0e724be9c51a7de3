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
    p.add_argument("scene", nargs="?", help="a scene file with [evolve] (default: the roobot)")
    p.add_argument(
        "--optimiser",
        choices=["hill-climber", "ga", "cma-es", "body-ga", "map-elites", "cma-me"],
        help="default: the scene's [evolve] optimiser, else cma-es (body-ga for a [morphology] scene; the roobot: hill-climber)",
    )
    p.add_argument("--population", type=int)
    p.add_argument("--restarts", type=int, help="CMA-ES's restarts (default 0)")
    p.add_argument("--generations", type=int, help="generations per lane (default 100; a resumed run's new total)")
    p.add_argument("--lanes", type=int)
    p.add_argument("--seed", type=int, help="default 1")
    p.add_argument("--out", default="evolution", help="directory for log.csv, best.toml and checkpoint.json")
    p.add_argument(
        "--resume",
        metavar="DIR",
        help="continue the run saved in DIR (by this command, an interrupted one, or `animats evolve`)",
    )
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
    if a.resume is not None:
        if a.scene is not None:
            print(f"error: {a.resume}: a resumed run keeps its scene; give only --resume and "
                  "--generations", file=sys.stderr)
            return 2
        a.out = a.resume
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
            if a.resume is not None:
                from .distributed import _resumed

                given = {k: v for k, v in run_args.items() if k != "generations"}
                run = _resumed(a.resume, a.generations, given, device=a.device)
            else:
                run = _animats.Evolution(
                    "roobot" if a.scene is None else a.scene,
                    lanes=a.lanes,
                    generations=100 if a.generations is None else a.generations,
                    seed=1 if a.seed is None else a.seed,
                    optimiser=a.optimiser,
                    population=a.population,
                    restarts=0 if a.restarts is None else a.restarts,
                    device=a.device,
                )
            try:
                # Saved every 5 s as `animats evolve` saves, and on Ctrl-C.
                run.run(threads=a.threads, checkpoint=a.out)
            except KeyboardInterrupt:
                # The run stands at whole generations, saved: to go on.
                print(
                    f"interrupted at generation {run.generation}; continue with "
                    f"`python -m animats.evolve --resume {a.out}`",
                    file=sys.stderr,
                )
                return 130
            how = "here"
        else:
            from . import distributed

            try:
                run, stats = distributed.evolve(
                    a.scene,
                    **run_args,
                    resume=a.resume is not None,
                    actors=a.actors,
                    device=a.device,
                    address=None if a.ray == "local" else a.ray,
                    out=a.out,
                    progress=True,
                    check=False,  # below, after the clock, as here
                )
            except KeyboardInterrupt:
                # The last save stands (`checkpoint_every`, 5 s).
                if Path(a.out, "checkpoint.json").exists():
                    print(
                        f"interrupted; continue from the last save with "
                        f"`python -m animats.evolve --resume {a.out} --ray {a.ray}`",
                        file=sys.stderr,
                    )
                return 130
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
        f"wrote {a.out}/log.csv, best.toml{', checked.toml' if checked else ''}, checkpoint.json"
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
