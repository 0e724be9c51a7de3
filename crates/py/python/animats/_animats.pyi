"""Type stubs of the compiled core (crates/py/src)."""

from os import PathLike
from typing import Any, Dict, List, Literal, Optional, Sequence, Tuple, Union, overload

import numpy as np
import numpy.typing as npt

F64 = npt.NDArray[np.float64]
SceneLike = Union["Scene", str, PathLike[str]]

__version__: str
#: The x86-64 extensions this build uses beyond the baseline, as rustc names
#: them ("sse4.2,popcnt,avx,avx2,fma,bmi1,bmi2" for the workspace's
#: x86-64-v3; "" for a baseline build): a CPU without them is refused at
#: import, before any of the module's code runs (README, "Building for
#: another CPU").
CPU_FEATURES: str
#: The compiled module's lists; ``animats.ROOBOT_INITIAL`` and
#: ``animats.ROOBOT_BOUNDS`` are float64 arrays of them.
ROOBOT_INITIAL: List[float]
ROOBOT_BOUNDS: List[List[float]]

class SceneError(ValueError):
    """A scene that cannot be read or built; names file, line, entry, field."""

def load(path: Union[str, PathLike[str]]) -> Scene: ...
def parse(text: str, file: str = "<string>") -> Scene: ...

class Scene:
    file: str
    text: str
    names: List[str]
    dt: float
    duration: float
    actuators: List[str]
    sensors: List[str]
    controllers: List[str]
    #: What `animats simulate` would warn of; `load` and `parse` issue each
    #: as a RuntimeWarning.
    warnings: List[str]
    evolvable: bool
    def world(self, genome: Optional[Sequence[float]] = None) -> World: ...
    def best_toml(self, genome: Sequence[float]) -> str: ...
    def start(self) -> F64: ...
    def bounds(self) -> F64: ...

class Snapshot:
    time: float

class World:
    time: float
    dt: float
    names: List[str]
    def step(self, n: int = 1) -> None: ...
    def positions(self) -> F64: ...
    def velocities(self) -> F64: ...
    def set_actuators(self, levels: Sequence[float]) -> None: ...
    def actuators(self) -> F64: ...
    def sensors(self) -> F64: ...
    def snapshot(self) -> Snapshot: ...
    def restore(self, snapshot: Snapshot) -> None: ...
    def energy(self) -> float: ...
    def masses(self) -> F64: ...
    def radii(self) -> F64: ...
    def springs(self) -> Dict[str, npt.NDArray[np.generic]]: ...
    def contacts(self, tolerance: float = 1e-6) -> npt.NDArray[np.bool_]: ...
    def set_positions(self, positions: F64) -> None: ...
    def set_velocities(self, velocities: F64) -> None: ...

Genomes = Union[F64, List[F64]]

@overload
def evaluate(scene: SceneLike, genomes: Genomes, threads: Optional[int] = None, measures: Literal[False] = False, clip: bool = False, device: Literal["cpu", "cuda", "cuda-fast"] = "cpu") -> F64: ...
@overload
def evaluate(scene: SceneLike, genomes: Genomes, threads: Optional[int], measures: Literal[True], clip: bool = False, device: Literal["cpu", "cuda", "cuda-fast"] = "cpu") -> Tuple[F64, F64]: ...

Outcomes = Dict[str, Union[F64, List[str]]]

def evaluate_scenes(texts: List[str], threads: Optional[int] = None, device: Literal["cpu", "cuda", "cuda-fast"] = "cpu") -> Outcomes: ...

class Evaluator:
    dim: int
    roobot: bool
    def __init__(
        self, scene: SceneLike, threads: Optional[int] = None, device: Literal["cpu", "cuda", "cuda-fast"] = "cpu"
    ) -> None: ...
    def evaluate(self, genomes: Genomes, clip: bool = False) -> F64: ...
    def outcomes(
        self, genomes: Genomes, clip: bool = False, screens: Optional[List[str]] = None
    ) -> Outcomes: ...

class Optimiser:
    generation: int
    dim: int
    kind: str
    def __init__(
        self,
        kind: str,
        dim: Optional[int] = None,
        seed: int = 0,
        *,
        start: Optional[F64] = None,
        bounds: Optional[F64] = None,
        population: Optional[int] = None,
        lane: int = 0,
        sigma: Optional[float] = None,
        restarts: int = 0,
        problem: Optional[SceneLike] = None,
    ) -> None: ...
    def ask(self) -> F64: ...
    def tell(self, fitness: F64) -> None: ...
    def best(self) -> Optional[Tuple[F64, float]]: ...
    def best_toml(self) -> Optional[str]: ...

class Evolution:
    done: bool
    generation: int
    evaluations: int
    dim: int
    best_fitness: Optional[float]
    config: Dict[str, object]
    def __init__(
        self,
        scene: Optional[SceneLike] = None,
        *,
        lanes: Optional[int] = None,
        generations: int = 100,
        seed: int = 1,
        optimiser: Optional[str] = None,
        population: Optional[int] = None,
        restarts: int = 0,
        device: Literal["cpu", "cuda", "cuda-fast"] = "cpu",
    ) -> None: ...
    def ask(self) -> Tuple[Genomes, List[int]]: ...
    def tell(self, outcomes: Outcomes) -> None: ...
    def evaluate(self, genomes: Genomes, threads: Optional[int] = None) -> Outcomes: ...
    def screens(self) -> List[str]: ...
    def run(
        self,
        generations: Optional[int] = None,
        threads: Optional[int] = None,
        *,
        checkpoint: Optional[Union[str, PathLike[str]]] = None,
        checkpoint_every: float = 5.0,
    ) -> None: ...
    def problem_text(self) -> Tuple[str, str]: ...
    def log_csv(self) -> str: ...
    def best_toml(self) -> Optional[str]: ...
    def check(self, out: Optional[Union[str, PathLike[str]]] = None) -> Optional[Dict[str, Any]]: ...
    def save(self, directory: Union[str, PathLike[str]]) -> None: ...
    @staticmethod
    def resume(
        directory: Union[str, PathLike[str]],
        *,
        generations: Optional[int] = None,
        device: str = "cpu",
    ) -> "Evolution": ...

class Env:
    observation_names: List[str]
    observation_bounds: List[Tuple[float, float]]
    action_names: List[str]
    dt: float
    frame_skip: int
    max_steps: int
    time: float
    distance: float
    energy: float
    ended: Optional[str]
    def __init__(
        self,
        scene: SceneLike,
        noise: float = 0.0,
        seconds: Optional[float] = None,
        dt: Optional[float] = None,
        frame_skip: Optional[int] = None,
        act_hz: Optional[float] = None,
        observation: Optional[str] = None,
    ) -> None: ...
    def reset(self, seed: int = 0) -> F64: ...
    def observe(self) -> F64: ...
    def step(self, action: F64) -> Tuple[F64, float, bool, bool]: ...
    def positions(self) -> F64: ...
    def render(self, width: int = 480, height: int = 320) -> npt.NDArray[np.uint8]: ...

class VecEnv:
    num_envs: int
    observation_names: List[str]
    observation_bounds: List[Tuple[float, float]]
    action_names: List[str]
    dt: float
    max_steps: int
    def __init__(
        self,
        scene: SceneLike,
        n: int,
        seed: int = 0,
        noise: float = 0.0,
        seconds: Optional[float] = None,
        dt: Optional[float] = None,
        frame_skip: Optional[int] = None,
        act_hz: Optional[float] = None,
        observation: Optional[str] = None,
    ) -> None: ...
    def reset(self, seed: int = 0) -> F64: ...
    def step(
        self, actions: F64
    ) -> Tuple[F64, F64, npt.NDArray[np.bool_], npt.NDArray[np.bool_]]: ...
    def render(
        self, width: int = 480, height: int = 320, copies: Optional[List[int]] = None
    ) -> npt.NDArray[np.uint8]: ...
