"""animats: creatures from the physics up, driven from Python.

The Rust core, without a copy of its logic: scenes and worlds, parallel
evaluation, the optimisers and whole evolution runs, and environments.

    >>> import animats, numpy as np
    >>> scene = animats.load("scenes/walker.toml")   # or animats.parse(text)
    >>> world = scene.world(); world.step(100)
    >>> world.positions()                       # (N, 3) float64
    >>> world.masses(), world.springs(), world.contacts()
    >>> scene.world(genome)                     # the creature a genome makes
    >>> scene.best_toml(genome)                 # ... as a scene file's text
    >>> animats.evaluate(scene, scene.start())  # its own parameters' fitness
    >>> animats.evaluate("roobot", np.tile(animats.ROOBOT_INITIAL, (8, 1)))
    >>> animats.evaluate_scenes([open("scenes/walker.toml").read()])
    >>> f, m = animats.evaluate("scenes/hop_map.toml", g, measures=True)
    >>> animats.Archive("hopmap")               # a map-elites run's archive

``import animats.gym`` registers the Gymnasium environments
``animats/Roobot-v0`` and ``animats/Scene-v0``; ``animats.distributed``
spreads an evolution over a Ray cluster.
"""

from __future__ import annotations

from typing import Optional, Union
import os

import numpy as np
import numpy.typing as npt

from . import _animats
from .archive import Archive
from ._animats import (
    Env,
    Evaluator,
    Evolution,
    Optimiser,
    Scene,
    SceneError,
    Snapshot,
    VecEnv,
    World,
    load,
    parse,
)

#: The version of the compiled core (the Rust crates').
__version__: str = _animats.__version__

__all__ = [
    "Archive",
    "Env",
    "Evaluator",
    "Evolution",
    "Optimiser",
    "Scene",
    "SceneError",
    "Snapshot",
    "VecEnv",
    "World",
    "evaluate",
    "evaluate_scenes",
    "load",
    "parse",
    "ROOBOT_INITIAL",
    "ROOBOT_BOUNDS",
]

#: Appendix B's initial roobot parameters (the hill climber's start).
ROOBOT_INITIAL: npt.NDArray[np.float64] = np.array(_animats.ROOBOT_INITIAL, dtype=np.float64)
#: The roobot parameters' bounds, ``(14, 2)``.
ROOBOT_BOUNDS: npt.NDArray[np.float64] = np.array(_animats.ROOBOT_BOUNDS, dtype=np.float64)

SceneLike = Union[Scene, str, "os.PathLike[str]"]


def evaluate(
    scene: SceneLike,
    genomes,
    threads: Optional[int] = None,
    measures: bool = False,
    clip: bool = False,
    device: str = "cpu",
):
    """Fitness of each row of ``genomes`` under ``scene``'s ``[evolve]``
    evaluation (``"roobot"``: the thesis's hopping gait).

    ``genomes`` is a ``(P, D)`` array (a single ``(D,)`` genome gives one
    fitness in a ``(1,)`` array). The evaluations run in parallel on
    ``threads`` threads (default: every core) with the GIL released, and
    each is bit-identical to ``animats evaluate`` on the same parameters.
    With ``measures=True`` (a scene with an ``[archive]`` table), a tuple:
    the fitness and the ``(P, k)`` array of its measures, computed in the
    same evaluations (what a pyribs ``Scheduler.tell`` takes). A gene
    outside the scene's bounds (``scene.bounds()``) raises ``ValueError``
    naming it, unless ``clip=True`` clips genes into their bounds (the
    roobot's genes, mutated by a fraction of their value, have none).
    ``device="cuda"`` evaluates them as one batch on an NVIDIA GPU, with
    the same bits (``docs/GPU.md``); a ``RuntimeError`` says what is
    missing where no GPU can be used, or which entry of the scene the GPU
    does not evaluate.
    """
    if isinstance(genomes, list):
        # Bodies ([morphology] scenes): genomes differ in length.
        return _animats.evaluate(
            scene,
            [np.ascontiguousarray(g, dtype=np.float64) for g in genomes],
            threads,
            measures,
            clip,
            device,
        )
    g = np.ascontiguousarray(genomes, dtype=np.float64)
    if g.ndim == 1:
        g = g[None, :]
    if g.ndim != 2:
        raise ValueError(f"genomes must be a (P, D) array, got shape {g.shape}")
    return _animats.evaluate(scene, g, threads, measures, clip, device)


def evaluate_scenes(texts, threads: Optional[int] = None, device: str = "cpu") -> dict:
    """Each complete scene text in ``texts`` scored by its own ``[evolve]``
    table, in parallel on ``threads`` threads (default: every core) with the
    GIL released: a dict of arrays ``fitness``, ``distance``, ``time`` and
    the list ``ended`` (and ``measures``, ``(P, k)``, for scenes with an
    ``[archive]``), one entry per text, each bit-identical to
    ``animats evaluate`` on that text as a file. For encodings of your own
    (CPPNs, grammars, learned decoders): write the body your genome
    describes as ``[[particle]]``, ``[[spring]]``, ``[[actuator]]`` and a
    ``[[controller]]``, and let animats simulate it. A text that is not a
    valid scene raises ``SceneError`` naming it ``<scene K>``.
    ``device="cuda"``: evaluated as batches on an NVIDIA GPU, with the same
    bits (``docs/GPU.md``)."""
    if isinstance(texts, str):
        raise TypeError("texts must be a list of scene texts, not one string")
    return _animats.evaluate_scenes(list(texts), threads, device)
