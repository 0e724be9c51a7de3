"""Evolution and evaluation spread over a Ray cluster (``pip install
./crates/py[ray]``).

Long-lived actors each hold a Rust :class:`animats.Evaluator`; each
generation's genomes are split among them, and their outcomes are told to
the optimisers in the order the genomes were asked, so the run is the same,
bit for bit, as ``animats evolve`` on one machine, however many actors and
whatever order they finish in. An actor that dies mid-generation costs time,
not results: Ray restarts it and its share is evaluated again.

On a cluster::

    ray start --head                          # on the first machine
    ray start --address=HEAD_IP:6379          # on each of the others
    python -m animats.evolve scenes/walker.toml --ray auto --actors 32 \\
        --optimiser cma-es --generations 500 --out walker-run

or from Python, ``animats.distributed.evolve("scenes/walker.toml",
address="auto", actors=32, optimiser="cma-es", generations=500)``.
"""

from __future__ import annotations

import os
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable, List, Optional

import numpy as np

from . import _animats

__all__ = ["Pool", "Stats", "evolve"]


#: The devices an actor may evaluate on (as ``animats.Evaluator``'s).
DEVICES = ("cpu", "cuda", "cuda-fast")


class _Worker:
    """A Ray actor's state: one evaluator, one thread (Ray gives each actor
    one CPU, and one GPU on a GPU device; the parallelism is across
    actors). An evaluator that cannot be made (no driver on this node) is
    kept as its message, for the pool to report."""

    def __init__(self, file: str, text: str, device: str = "cpu") -> None:
        scene = "roobot" if file == "roobot" and text == "" else _animats.parse(text, file)
        self.evaluator = None
        self.error: Optional[str] = None
        try:
            self.evaluator = _animats.Evaluator(scene, threads=1, device=device)
        except (RuntimeError, ValueError) as e:
            self.error = str(e)

    def ready(self) -> "tuple[int, Optional[str]]":
        """This actor's process id, and why it cannot evaluate (or None)."""
        return os.getpid(), self.error

    def outcomes(self, genomes: np.ndarray, screens: Optional[List[str]] = None) -> dict:
        if self.evaluator is None:
            raise RuntimeError(self.error)
        start = time.perf_counter()
        if isinstance(genomes, list):
            g = [np.ascontiguousarray(x, dtype=np.float64) for x in genomes]
        else:
            g = np.ascontiguousarray(genomes, dtype=np.float64)
        out = self.evaluator.outcomes(g, screens=screens)
        out["seconds"] = time.perf_counter() - start
        return out


@dataclass
class Stats:
    """What a distributed run did besides its results."""

    #: Generations dispatched.
    generations: int = 0
    #: Shares evaluated again after their actor died.
    retries: int = 0
    #: Seconds spent waiting for the actors.
    wall: float = 0.0
    #: Seconds the busiest actor of each call spent evaluating, summed: what
    #: is left of `wall` went to Ray (dispatch, transfer, scheduling).
    compute: float = 0.0
    #: Each actor's process id at the start.
    pids: List[int] = field(default_factory=list)
    #: The end's checks of the winner (``Evolution.check``'s report), when
    #: ``evolve`` wrote into a directory and checked; else ``None``.
    check: Optional[dict] = None


_LOST = None  # filled with Ray's exception types on first use


def _lost_errors() -> tuple:
    global _LOST
    if _LOST is None:
        from ray import exceptions as e

        names = ["RayActorError", "ActorDiedError", "ActorUnavailableError", "WorkerCrashedError"]
        _LOST = tuple(getattr(e, n) for n in names if hasattr(e, n))
    return _LOST


class Pool:
    """``actors`` Ray actors evaluating one problem: ``scene`` is an
    ``animats.Scene``, a path or ``"roobot"``; or give ``problem_text`` as
    ``Evolution.problem_text()`` returns it. ``device``: where each actor
    evaluates, ``"cpu"`` (one core an actor) or ``"cuda"`` / ``"cuda-fast"``
    (one GPU and one core an actor, as ``animats.Evaluator(...,
    device=...)``). ``chunks``: shares per actor a generation (default 4 on
    CPUs, which evaluations of different lengths keep evenly busy; 1 on
    GPUs, which want each batch whole)."""

    def __init__(
        self,
        scene: Any = "roobot",
        actors: int = 2,
        *,
        problem_text: Optional[tuple] = None,
        max_retries: int = 5,
        chunks: Optional[int] = None,
        device: str = "cpu",
    ) -> None:
        import ray

        if actors < 1:
            raise ValueError(f"actors must be at least 1, got {actors}")
        if device not in DEVICES:
            raise ValueError(
                f'device={device!r}: "cpu" (the engine), "cuda" (an NVIDIA GPU: the same bits) '
                'or "cuda-fast" (the GPU with fused multiply-adds)'
            )
        gpu = device != "cpu"
        if problem_text is None:
            problem_text = _problem_text(scene)
        file, text = problem_text
        # Refuse a bad scene here, not in every actor.
        if not (file == "roobot" and text == ""):
            _animats.parse(text, file)
        cpus = ray.cluster_resources().get("CPU", 0)
        if actors > cpus:
            raise ValueError(
                f"{actors} actors need {actors} CPUs (one each) but the Ray cluster has {cpus:g}: "
                "they would wait forever; use fewer actors or add machines"
            )
        gpus = ray.cluster_resources().get("GPU", 0)
        if gpu and actors > gpus:
            raise ValueError(
                f"{actors} actors on device {device!r} need {actors} GPUs (one each) but the Ray "
                f"cluster has {gpus:g}: they would wait forever; use fewer actors or add GPU machines"
            )
        self.max_retries = max_retries
        self.chunks = max(1, chunks if chunks is not None else (1 if gpu else 4))
        self.stats = Stats()
        remote = ray.remote(num_cpus=1, num_gpus=1 if gpu else 0, max_restarts=-1)(_Worker)
        self.actors = [remote.remote(file, text, device) for _ in range(actors)]
        ready = ray.get([a.ready.remote() for a in self.actors])
        failed = [(k, error) for k, (_, error) in enumerate(ready) if error is not None]
        if failed:
            self.shutdown()
            k, error = failed[0]
            raise RuntimeError(f"{len(failed)} of {actors} actors cannot evaluate; actor {k}: {error}")
        self.stats.pids = [pid for pid, _ in ready]
        self._next = 0

    def outcomes(
        self,
        genomes: np.ndarray,
        on_dispatch: Optional[Callable[["Pool"], None]] = None,
        screens: Optional[List[str]] = None,
    ) -> dict:
        """Outcomes of each row of ``genomes`` (``Evaluator.outcomes``'s
        dict); ``screens``, one per row, as ``Evolution.screens()`` gives
        them. The rows are cut into ``chunks`` shares per actor, handed out
        as actors finish (evaluations differ in length: a fixed split would
        wait for the unluckiest actor), and merged in row order.
        ``on_dispatch`` is called once the first shares are sent (tests kill
        a worker there)."""
        import ray

        if isinstance(genomes, list):
            # Bodies: genomes of different lengths, sent as lists.
            g = [np.ascontiguousarray(x, dtype=np.float64) for x in genomes]
        else:
            g = np.ascontiguousarray(genomes, dtype=np.float64)
            if g.ndim != 2:
                raise ValueError(f"genomes must be a (P, D) array, got shape {g.shape}")
        start = time.perf_counter()
        n_shares = min(len(g), len(self.actors) * self.chunks)
        shares = [s for s in np.array_split(np.arange(len(g)), max(n_shares, 1)) if len(s)]
        results: list = [None] * len(shares)
        tries = [0] * len(shares)
        queue = list(range(len(shares)))
        pending = {}
        busy = [0.0] * len(self.actors)

        def send(actor: int) -> None:
            i = queue.pop(0)
            share = [g[k] for k in shares[i]] if isinstance(g, list) else g[shares[i]]
            screen = None if screens is None else [screens[k] for k in shares[i]]
            pending[self.actors[actor].outcomes.remote(share, screen)] = (i, actor)

        for a in range(len(self.actors)):
            if queue:
                send(a)
        if on_dispatch is not None:
            on_dispatch(self)
        while pending:
            done, _ = ray.wait(list(pending), num_returns=1)
            i, actor = pending.pop(done[0])
            try:
                results[i] = ray.get(done[0])
                busy[actor] += results[i]["seconds"]
            except _lost_errors() as e:
                tries[i] += 1
                self.stats.retries += 1
                if tries[i] > self.max_retries:
                    raise RuntimeError(
                        f"a share of {len(shares[i])} genomes failed {tries[i]} times: {e}"
                    ) from e
                # Again, first in line, on the next actor; Ray restarts the
                # dead one meanwhile.
                queue.insert(0, i)
                actor = (actor + 1) % len(self.actors)
            if queue:
                send(actor)
        self.stats.wall += time.perf_counter() - start
        self.stats.compute += max(busy)
        return _merge(results, len(g))

    def evaluate(self, genomes: np.ndarray) -> np.ndarray:
        """Fitness of each row of ``genomes``."""
        return self.outcomes(genomes)["fitness"]

    def shutdown(self) -> None:
        """Ends the actors."""
        import ray

        for a in self.actors:
            ray.kill(a)
        self.actors = []


def _merge(results: list, n: int) -> dict:
    if not results:
        return {"fitness": np.zeros(0), "time": np.zeros(0), "distance": np.zeros(0), "ended": []}
    out = {k: np.concatenate([r[k] for r in results]) for k in ("fitness", "time", "distance")}
    out["ended"] = [e for r in results for e in r["ended"]]
    assert len(out["ended"]) == n
    return out


def _problem_text(scene: Any) -> tuple:
    if isinstance(scene, _animats.Scene):
        return (scene.file, scene.text)
    if isinstance(scene, str) and scene == "roobot" and not os.path.exists(scene):
        return ("roobot", "")
    s = _animats.load(scene)
    return (s.file, s.text)


def _resumed(
    out: Optional[str], generations: Optional[int], given: dict, device: str = "cpu"
) -> "_animats.Evolution":
    """The run saved in ``out``, refusing choices it was not made with."""
    if out is None:
        raise ValueError("resume=True continues the run saved in `out`: give `out`")
    run = _animats.Evolution.resume(out, generations=generations, device=device)
    config = run.config
    for key, value in given.items():
        if value is not None and value != config[key]:
            raise ValueError(
                f"{out}: a resumed run keeps its {key} ({config[key]}), got {value}; "
                "give only the generations"
            )
    return run


def evolve(
    scene: Any = None,
    *,
    generations: Optional[int] = None,
    lanes: Optional[int] = None,
    seed: Optional[int] = None,
    optimiser: Optional[str] = None,
    population: Optional[int] = None,
    restarts: Optional[int] = None,
    actors: int = 2,
    device: str = "cpu",
    address: Optional[str] = None,
    out: Optional[str] = None,
    on_generation: Optional[Callable[[int, Pool], None]] = None,
    progress: bool = False,
    check: bool = True,
    resume: bool = False,
    checkpoint_every: float = 5.0,
) -> "tuple[_animats.Evolution, Stats]":
    """An ``animats evolve`` run whose evaluations are spread over Ray
    actors; the same arguments and defaults (``scene``: the roobot,
    ``generations``: 100, ``seed``: 1, ``restarts``: 0), and the same ``log.csv``,
    ``best.toml`` and ``checked.toml`` (written into ``out`` if given: the
    winner checked at a quarter of the step where the driver runs, as
    ``animats evolve`` does at its end, the report in ``Stats.check``;
    ``check=False`` skips that, as ``--no-check``, and removes an earlier
    ``checked.toml``). With ``out``, the run is also saved there
    (``Evolution.save``: ``checkpoint.json`` beside the log) after the
    first generation that ends ``checkpoint_every`` seconds or more after
    the last save, and at the end; ``resume=True`` continues the run saved
    in ``out`` (a driver that died, or ``animats evolve --out``'s run) to
    the same bits as one never stopped: it keeps its scene and choices,
    and ``generations`` may raise its total. ``address``: the cluster
    (``"auto"`` on a machine that ran ``ray start``); without it, Ray starts
    a local one unless one is already initialised. ``device``: where the
    actors evaluate (``Pool``'s; on ``"cuda"`` the same bytes again).
    ``on_generation(g, pool)`` is called as generation ``g``'s shares are
    sent."""
    import ray

    if not checkpoint_every >= 0.0:
        raise ValueError(f"checkpoint_every must be at least 0 seconds, got {checkpoint_every}")
    given = dict(lanes=lanes, seed=seed, optimiser=optimiser, population=population,
                 restarts=restarts)
    if resume:
        if scene is not None:
            raise ValueError("a resumed run keeps its scene: give `out` and `resume=True` only")
        run = _resumed(out, generations, given)
    else:
        run = _animats.Evolution(
            "roobot" if scene is None else scene,
            lanes=lanes,
            generations=100 if generations is None else generations,
            seed=1 if seed is None else seed,
            optimiser=optimiser,
            population=population,
            restarts=0 if restarts is None else restarts,
        )
    if not ray.is_initialized():
        ray.init(address=address, log_to_driver=False)
    pool = Pool(problem_text=run.problem_text(), actors=actors, device=device)
    try:
        last = saved = time.monotonic()
        while not run.done:
            g = run.generation + 1
            genomes, _ = run.ask()
            hook = None if on_generation is None else (lambda p, g=g: on_generation(g, p))
            run.tell(pool.outcomes(genomes, on_dispatch=hook, screens=run.screens()))
            pool.stats.generations += 1
            if out is not None and not run.done and time.monotonic() - saved >= checkpoint_every:
                run.save(out)
                saved = time.monotonic()
            if progress and time.monotonic() - last > 5:
                last = time.monotonic()
                print(
                    f"generation {run.generation}/{run.config['generations']}, "
                    f"best {run.best_fitness}",
                    flush=True,
                )
        if out is not None:
            run.save(out)
    finally:
        pool.shutdown()
    if out is not None:
        if check:
            pool.stats.check = run.check(out)
        else:
            Path(out, "checked.toml").unlink(missing_ok=True)
    return run, pool.stats
