"""pyribs drives animats: a MAP-Elites map of the thesis's hopping gaits.

pyribs (PyPI `ribs`) asks for solutions and is told objectives and
measures; animats evaluates them, in parallel with the GIL released,
computing the measures of scenes/hop_map.toml's [archive] table (the hip's
mean height and forward speed) during the same 20 s runs. The archive's
grid is the scene's own, so the map is the one `animats evolve
scenes/hop_map.toml --optimiser map-elites` fills.

    pip install "animats[qd]"          # ribs[visualize] (with matplotlib)
    python examples/python/pyribs_hopper.py --iterations 200 --out hopper_pyribs.png
"""

import argparse
import pathlib
import tomllib

import numpy as np
from ribs.archives import GridArchive
from ribs.emitters import GaussianEmitter
from ribs.schedulers import Scheduler

import animats

ROOT = pathlib.Path(__file__).resolve().parents[2]
SCENE = ROOT / "scenes" / "hop_map.toml"


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--iterations", type=int, default=200)
    ap.add_argument("--batch", type=int, default=36)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--out", default="hopper_pyribs.png")
    args = ap.parse_args()

    table = tomllib.loads(SCENE.read_text())["archive"]
    bounds = animats.ROOBOT_BOUNDS
    archive = GridArchive(
        solution_dim=len(animats.ROOBOT_INITIAL),
        dims=table["bins"],
        ranges=[tuple(r) for r in table["ranges"]],
        extra_fields={"time": ((), np.float64)},
        seed=args.seed,
    )
    evaluator = animats.Evaluator(str(SCENE))
    # As animats's own map-elites: Gaussian steps of a tenth of each gene's
    # range, clipped into the bounds.
    emitter = GaussianEmitter(
        archive,
        x0=animats.ROOBOT_INITIAL,
        sigma=0.1 * (bounds[:, 1] - bounds[:, 0]),
        bounds=[tuple(b) for b in bounds],
        batch_size=args.batch,
        seed=args.seed,
    )
    scheduler = Scheduler(archive, [emitter])
    for itr in range(1, args.iterations + 1):
        solutions = scheduler.ask()
        o = evaluator.outcomes(solutions)
        # pyribs has no `min_time`: runs that fell enter empty cells too
        # (`animats evolve` leaves them out); their time is kept beside them.
        scheduler.tell(o["fitness"], o["measures"], time=o["time"])
        if itr % 50 == 0 or itr == args.iterations:
            s = archive.stats
            print(f"iteration {itr}: coverage {s.coverage:.3f}, QD score {s.qd_score:.1f}, best {s.obj_max:.1f}")
    hop = archive.data("time") >= 20.0
    print(f"{hop.sum()} of {len(archive)} elites hop the whole 20 s")

    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        from ribs.visualize import grid_archive_heatmap
    except ImportError:
        print("matplotlib is not installed: no heat map (pip install 'ribs[visualize]')")
        return
    plt.figure(figsize=(8, 6))
    grid_archive_heatmap(archive)
    plt.xlabel(f"{table['measures'][0]['kind']} (m)")
    plt.ylabel(f"{table['measures'][1]['kind']} (m/s)")
    plt.title(f"pyribs MAP-Elites over animats's roobot: coverage {archive.stats.coverage:.1%}")
    plt.tight_layout()
    plt.savefig(args.out)
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
