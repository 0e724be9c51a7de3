"""A quality-diversity run's archive, read from its directory.

``animats evolve SCENE --optimiser map-elites --out DIR`` (or ``cma-me``)
writes ``DIR/archive.csv`` (one row per occupied cell: pyribs's columns
``index``, ``objective``, ``measures_0`` ... then ``threshold``, ``time``,
``distance``, ``ended`` and the genome ``solution_0`` ...), each elite as a
complete scene ``DIR/elites/<index>.toml``, and ``log.csv`` with the
archive's ``coverage``, ``qd_score`` and ``obj_max`` after each generation.

    >>> a = animats.Archive("hopmap")
    >>> a.objective.max(), a.measures.shape, a.stats["coverage"]
    >>> animats.load(a.scene_path(a.index[a.objective.argmax()]))
"""

from __future__ import annotations

import csv
import os
from typing import Dict, List, Union

import numpy as np


class Archive:
    """The elites of a run directory, in cell order."""

    def __init__(self, directory: Union[str, "os.PathLike[str]"]):
        self.directory = os.fspath(directory)
        path = os.path.join(self.directory, "archive.csv")
        if not os.path.exists(path):
            raise FileNotFoundError(
                f"{path}: no archive here; a run of `animats evolve SCENE --optimiser map-elites` writes one"
            )
        with open(path, newline="") as f:
            rows = list(csv.reader(f))
        if not rows or rows[0][:2] != ["index", "objective"]:
            raise ValueError(f"{path}: not an animats archive (its header is {rows[0][:2] if rows else 'missing'})")
        header = rows[0]
        k = sum(1 for c in header if c.startswith("measures_"))
        body = rows[1:]
        #: Each elite's cell (pyribs's integer index).
        self.index = np.array([int(r[0]) for r in body], dtype=np.int64)
        #: Each elite's objective (its fitness).
        self.objective = np.array([float(r[1]) for r in body], dtype=np.float64)
        #: ``(n, k)``: each elite's measures.
        self.measures = np.array([[float(x) for x in r[2 : 2 + k]] for r in body], dtype=np.float64).reshape(
            len(body), k
        )
        #: Each cell's threshold (its elite's objective unless CMA-MAE).
        self.threshold = np.array([float(r[2 + k]) for r in body], dtype=np.float64)
        #: Time each elite survived, s, and its distance, m.
        self.time = np.array([float(r[3 + k]) for r in body], dtype=np.float64)
        self.distance = np.array([float(r[4 + k]) for r in body], dtype=np.float64)
        #: Why each elite's evaluation ended.
        self.ended: List[str] = [r[5 + k] for r in body]
        #: Each elite's genome (bodies' genomes differ in length).
        self.solutions: List[np.ndarray] = [np.array([float(x) for x in r[6 + k :]], dtype=np.float64) for r in body]
        #: The archive's statistics after the last generation (from log.csv):
        #: ``elites``, ``coverage``, ``qd_score``, ``obj_max``.
        self.stats: Dict[str, float] = {}
        log = os.path.join(self.directory, "log.csv")
        if os.path.exists(log):
            with open(log, newline="") as f:
                lines = list(csv.DictReader(f))
            if lines and "coverage" in lines[-1]:
                self.stats = {key: float(lines[-1][key]) for key in ("elites", "coverage", "qd_score", "obj_max")}

    def __len__(self) -> int:
        return len(self.index)

    def scene_path(self, index: int) -> str:
        """The elite of cell ``index`` as a complete scene file:
        ``animats evaluate`` on it reproduces its objective and measures."""
        path = os.path.join(self.directory, "elites", f"{int(index)}.toml")
        if not os.path.exists(path):
            raise KeyError(f"cell {index} has no elite in {self.directory}")
        return path

    def scene_text(self, index: int) -> str:
        """The text of :meth:`scene_path`."""
        with open(self.scene_path(index)) as f:
            return f.read()

    def __repr__(self) -> str:
        return f"<animats.Archive {self.directory!r}: {len(self)} elites, {self.measures.shape[1]} measures>"
