"""The Python examples the README and the docs point users to run as
written: each is started as a user starts it (its own process, from the
repository root), and what it prints is checked against the API it tours."""

import importlib
import re
import subprocess
import sys

import numpy as np
import pytest

import animats

from conftest import ROOT


def run_example(name, *args, cwd=ROOT, timeout=300):
    r = subprocess.run(
        [sys.executable, str(ROOT / "examples" / "python" / name), *map(str, args)],
        capture_output=True,
        text=True,
        cwd=cwd,
        timeout=timeout,
    )
    assert r.returncode == 0, f"{name} failed:\n{r.stdout}\n{r.stderr}"
    return r.stdout


def number(pattern, text):
    m = re.search(pattern, text)
    assert m, f"no line matching {pattern!r} in:\n{text}"
    return float(m.group(1))


def test_the_quickstart_tour_runs_and_prints_what_the_api_gives():
    out = run_example("quickstart.py")
    # The pogo stick after 500 steps of its scene's dt.
    scene = animats.load(str(ROOT / "scenes" / "pogo.toml"))
    world = scene.world()
    world.step(500)
    assert number(r"t = ([\d.]+) s, positions", out) == pytest.approx(world.time, abs=5e-4)
    # The 600 roobot genomes: the same draw, the same fitness (the same
    # bits on any thread count).
    rng = np.random.default_rng(0)
    lo, hi = animats.ROOBOT_BOUNDS[:, 0], animats.ROOBOT_BOUNDS[:, 1]
    genomes = animats.ROOBOT_INITIAL * (1 + 0.2 * (rng.random((600, 14)) - 0.5))
    fitness = animats.evaluate("roobot", np.clip(genomes, lo, hi), threads=1)
    assert number(r"600 roobot evaluations: best ([-\d.]+)", out) == pytest.approx(
        fitness.max(), abs=0.05
    )
    assert number(r"median ([-\d.]+)", out) == pytest.approx(np.median(fitness), abs=0.05)
    # The optimiser loop, again here: the same seed, the same best.
    walker = animats.load(str(ROOT / "scenes" / "walker.toml"))
    opt = animats.Optimiser("cma-es", seed=1, problem=walker)
    for _ in range(10):
        pop = opt.ask()
        opt.tell(animats.evaluate(walker, pop))
    assert number(r"walker after 10 CMA-ES generations: fitness ([-\d.]+)", out) == pytest.approx(
        opt.best()[1], abs=0.005
    )
    # The Gymnasium episode, again here.
    gymnasium = pytest.importorskip("gymnasium")
    importlib.import_module("animats.gym")  # registers animats/Roobot-v0

    env = gymnasium.make("animats/Roobot-v0")
    env.reset(seed=0)
    total = 0.0
    for _ in range(2500):
        _, reward, terminated, truncated, _ = env.step(np.array([0.5, 0.5, 0.5]))
        total += reward
        if terminated or truncated:
            break
    assert number(r"a roobot that holds still: return ([-\d.]+)", out) == pytest.approx(
        total, abs=0.005
    )
    assert "1024 roobots stepped in one call: observations (1024, 4)" in out


def test_the_pyribs_example_fills_the_scenes_grid_with_hopping_gaits(tmp_path):
    pytest.importorskip("ribs")
    png = tmp_path / "map.png"
    out = run_example("pyribs_hopper.py", "--iterations", 3, "--out", png, cwd=tmp_path)
    coverage = number(r"iteration 3: coverage ([\d.]+)", out)
    # 108 evaluations into a 20 x 20 grid: some cells, never more than one
    # a solution.
    assert 0.0 < coverage <= 108 / 400
    assert re.search(r"\d+ of \d+ elites hop the whole 20 s", out), out
    try:
        import matplotlib  # noqa: F401
    except ImportError:
        assert "no heat map" in out
    else:
        assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_the_ray_example_writes_the_log_of_the_command_it_names(tmp_path):
    pytest.importorskip("ray")
    # Run from a folder of its own (it reads `scenes/walker.toml` and
    # writes `walker-ray/` where it starts), as from the repository root.
    (tmp_path / "scenes").symlink_to(ROOT / "scenes")
    out = run_example("ray_evolve.py", cwd=tmp_path)
    evaluations = number(r"(\d+) evaluations in [\d.]+ s on 2 actors \(0 shares retried\)", out)
    best = number(r"; best ([-\d.]+)", out)
    named = ("the same as: animats evolve scenes/walker.toml --optimiser cma-es "
             "--generations 50 --lanes 2 --seed 1 --out walker-cli")
    assert named in out, out
    # That run, here (whose log is the command line's: test_api.py).
    run = animats.Evolution(str(ROOT / "scenes" / "walker.toml"), optimiser="cma-es",
                            generations=50, lanes=2, seed=1)
    run.run()
    assert (tmp_path / "walker-ray" / "log.csv").read_text() == run.log_csv()
    assert evaluations == run.evaluations
    assert best == pytest.approx(run.best_fitness, abs=5e-4)
