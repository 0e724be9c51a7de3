"""Evolution on a local Ray cluster: the same log.csv and best.toml, bit for
bit, as `animats evolve` on one machine, even when a worker is killed in the
middle of a generation."""

import os
import signal

import numpy as np
import pytest

ray = pytest.importorskip("ray")

import animats  # noqa: E402
from animats import distributed  # noqa: E402


@pytest.fixture(scope="module")
def cluster():
    # One GPU declared (Ray takes the count as given): GPU actors get
    # scheduled here, and find no driver unless this machine has one.
    ray.init(num_cpus=2, num_gpus=1, include_dashboard=False, log_to_driver=False)
    yield
    ray.shutdown()


def test_a_ray_evolution_writes_the_command_lines_log(cluster, cli, crawler, tmp_path):
    args = dict(generations=6, lanes=3, seed=4, optimiser="cma-es")
    cli("evolve", crawler, "--optimiser", "cma-es", "--generations", 6, "--lanes", 3,
        "--seed", 4, "--out", tmp_path / "cli")
    for actors in (1, 2):
        run, stats = distributed.evolve(str(crawler), actors=actors, out=tmp_path / f"ray{actors}", **args)
        assert stats.generations == 6 and stats.retries == 0
        for f in ("log.csv", "best.toml"):
            assert (tmp_path / f"ray{actors}" / f).read_bytes() == (tmp_path / "cli" / f).read_bytes(), (actors, f)
        # The end's checks, run where the driver runs: the command line's
        # checked.toml, and the report of `run.check`.
        f = "checked.toml"
        assert (tmp_path / "cli" / f).exists()
        assert (tmp_path / f"ray{actors}" / f).read_bytes() == (tmp_path / "cli" / f).read_bytes(), actors
        again = run.check()
        assert stats.check is not None and stats.check["checked"] is not None
        assert stats.check["best"] == again["best"] and stats.check["checked"] == again["checked"]
        assert stats.check["checked"]["toml"] == (tmp_path / f"ray{actors}" / f).read_text()
    # Without the checks (`--no-check`), an earlier checked.toml goes.
    run, stats = distributed.evolve(str(crawler), actors=1, out=tmp_path / "ray1", check=False, **args)
    assert stats.check is None
    assert not (tmp_path / "ray1" / "checked.toml").exists()
    assert (tmp_path / "ray1" / "log.csv").read_bytes() == (tmp_path / "cli" / "log.csv").read_bytes()


def test_a_worker_killed_mid_generation_costs_time_not_results(cluster, cli, tmp_path):
    # The roobot with CMA-ES, 24 genomes a generation: each actor's share
    # takes tens of milliseconds, and the kill lands while it runs.
    cli("evolve", "--optimiser", "cma-es", "--population", 24, "--generations", 5,
        "--lanes", 1, "--seed", 2, "--out", tmp_path / "cli")
    killed = []

    def kill(generation, pool):
        if generation == 3 and not killed:
            pid = pool.stats.pids[0]
            os.kill(pid, signal.SIGKILL)
            killed.append(pid)

    run, stats = distributed.evolve(
        "roobot", optimiser="cma-es", population=24, generations=5, lanes=1, seed=2,
        actors=2, out=tmp_path / "ray", on_generation=kill,
    )
    assert killed, "the worker was killed"
    assert stats.retries >= 1, "its share was evaluated again"
    for f in ("log.csv", "best.toml"):
        assert (tmp_path / "ray" / f).read_bytes() == (tmp_path / "cli" / f).read_bytes(), f


def test_a_driver_that_dies_resumes_from_its_last_save_to_the_same_bits(cluster, cli, crawler, tmp_path):
    flags = ["--optimiser", "cma-es", "--lanes", 2, "--seed", 3]
    cli("evolve", crawler, *flags, "--generations", 7, "--out", tmp_path / "cli")
    args = dict(optimiser="cma-es", lanes=2, seed=3, actors=2)

    class Died(Exception):
        pass

    def die(generation, pool):
        if generation == 5:
            raise Died()

    # Saved after every generation (checkpoint_every=0): the driver dies
    # as generation 5's shares go out, and generation 4's save stands.
    with pytest.raises(Died):
        distributed.evolve(str(crawler), generations=7, out=tmp_path / "ray", on_generation=die,
                           checkpoint_every=0, **args)
    assert not (tmp_path / "ray" / "checked.toml").exists()
    assert animats.Evolution.resume(tmp_path / "ray").generation == 4
    # Choices the run was not made with are refused, as is a scene.
    with pytest.raises(ValueError, match="keeps its seed"):
        distributed.evolve(out=tmp_path / "ray", resume=True, seed=4)
    with pytest.raises(ValueError, match="keeps its scene"):
        distributed.evolve(str(crawler), out=tmp_path / "ray", resume=True)
    run, stats = distributed.evolve(out=tmp_path / "ray", resume=True, **args)
    assert stats.generations == 3 and run.generation == 7
    for f in ("log.csv", "best.toml", "checked.toml"):
        assert (tmp_path / "ray" / f).read_bytes() == (tmp_path / "cli" / f).read_bytes(), f


def test_more_actors_than_cpus_are_refused_not_left_waiting(cluster):
    with pytest.raises(ValueError, match="CPUs"):
        distributed.Pool("roobot", actors=3)


def _gpu_here() -> bool:
    try:
        animats.Evaluator("roobot", device="cuda")
        return True
    except RuntimeError:
        return False


def test_gpu_actors_need_a_gpu_each_and_a_known_device(cluster):
    with pytest.raises(ValueError, match="2 GPUs .* has 1"):
        distributed.Pool("roobot", actors=2, device="cuda")
    with pytest.raises(ValueError, match='device=.gpu.: "cpu"'):
        distributed.Pool("roobot", actors=1, device="gpu")


def test_a_gpu_actor_says_what_it_lacks_or_gives_the_cpu_s_bits(cluster, crawler):
    """On the GPU an actor evaluates as the engine does, to the bit; where
    its node has no usable GPU, making the pool says what is missing (it
    does not hang, and no evaluation is attempted)."""
    if not _gpu_here():
        with pytest.raises(RuntimeError, match="1 of 1 actors cannot evaluate; actor 0: device=.cuda.: .*(driver|device|NVRTC)"):
            distributed.Pool(str(crawler), actors=1, device="cuda")
        return
    scene = animats.load(crawler)
    b = scene.bounds()
    g = b[:, 0] + (b[:, 1] - b[:, 0]) * np.random.default_rng(5).random((12, len(b)))
    pool = distributed.Pool(scene, actors=1, device="cuda")
    try:
        assert pool.chunks == 1
        got = pool.evaluate(g)
    finally:
        pool.shutdown()
    assert got.tolist() == animats.evaluate(scene, g).tolist()


def test_a_pool_evaluates_as_evaluate_does(cluster, crawler):
    scene = animats.load(crawler)
    rng = np.random.default_rng(3)
    b = scene.bounds()
    g = b[:, 0] + (b[:, 1] - b[:, 0]) * rng.random((10, len(b)))
    pool = distributed.Pool(scene, actors=2)
    try:
        assert np.array_equal(pool.evaluate(g), animats.evaluate(scene, g))
    finally:
        pool.shutdown()


def test_a_ray_evolution_of_bodies_writes_the_command_lines_log(cluster, cli, tmp_path):
    from test_bodies import SMALL

    scene = tmp_path / "small.toml"
    scene.write_text(SMALL)
    cli("evolve", scene, "--population", 6, "--generations", 3, "--seed", 3, "--out", tmp_path / "cli")
    run, stats = distributed.evolve(str(scene), population=6, generations=3, seed=3, actors=2,
                                    out=tmp_path / "ray")
    assert stats.generations == 3
    for f in ("log.csv", "best.toml"):
        assert (tmp_path / "ray" / f).read_bytes() == (tmp_path / "cli" / f).read_bytes(), f
