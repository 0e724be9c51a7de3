"""Gymnasium environments of animats (``pip install ./crates/py[gym]``).

Importing this module registers:

- ``animats/Roobot-v0``: the thesis's hopping monopod, the scene
  ``scenes/hop_evolver.toml``. Actions: the levels of its actuators
  ``roobot.leg``, ``roobot.hip`` and ``roobot.ankle``, in [0, 1] (the hip
  motor acts only in flight, the ankle only in stance). Observations: its
  four sensors (foot height, leg angle, hip forward speed, time till
  touchdown), in [0, 1]. Reward: the increase over the step of the thesis's
  fitness, time upright + 50 × forward distance of the hip, so an episode's
  rewards add up to the fitness ``animats.evaluate`` gives the same run.
  8 ms per step, 20 s (2500 steps) per episode, terminated when the hip,
  head or tail touches the floor or the leg stretches to 1 m.
- ``animats/Scene-v0``: any scene with actuators and an ``[evolve]``
  table, ``gymnasium.make("animats/Scene-v0", scene=path)``. Actions: every
  actuator's level (the scene's own controllers do not run), each held for
  ``frame_skip`` physics steps (default: as many as make the agent act at
  about 50 Hz: 40 for a 0.5 ms step); observations: ``observation =
  "sensors"`` (every sensor's level, in [0, 1]; the default), ``"state"``
  (the centre of mass's height and velocity, every moving particle's
  position and velocity relative to it, every spring's length, and 1 or 0
  for each moving particle touching the floor; the default of a scene with
  no sensors) or ``"both"``; reward: the increase of the ``[evolve]``
  fitness (energy and target terms included); the episode lasts its
  ``duration`` and terminates when an ``[evolve]`` end rule holds or the run
  blows up.

Both accept ``noise`` (m/s): each reset adds to every particle's velocity a
uniform random vector of up to ``noise`` per component, drawn from the
reset's seed (0 by default: every episode starts the same);
``render_mode="rgb_array"``: ``render()`` returns the scene drawn by the
software renderer (``animats render``'s), ``(320, 480, 3)`` uint8; and
every ``info`` carries ``time`` (s), ``distance`` (m along the ``[evolve]``
axis), ``energy`` (J, the actuators' positive work) and ``ended``
(``None``, or ``"timeout"``, ``"touch NAME"``, ``"stretch A-B"``,
``"blow-up"``).

``gymnasium.make_vec(id, num_envs=N)`` gives :class:`AnimatsVectorEnv`, the
native vector environment that steps all N copies in one call in Rust (in
parallel for large N, the GIL released); ``vectorization_mode="sync"`` gives
Gymnasium's own ``SyncVectorEnv`` of N single environments instead. With
``render_mode="rgb_array"`` its ``render()`` returns every copy's picture,
as a tuple (Gymnasium's vector convention); ``render_copies`` draws chosen
copies only.
"""

from __future__ import annotations

from typing import Any, Optional, SupportsFloat

import gymnasium
import numpy as np
from gymnasium import spaces
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space

from . import _animats

__all__ = ["AnimatsEnv", "AnimatsVectorEnv", "RoobotEnv", "SceneEnv"]

_SEED_LIMIT = 2**63


def _box(bounds: list) -> spaces.Box:
    low = np.array([b[0] for b in bounds], dtype=np.float64)
    high = np.array([b[1] for b in bounds], dtype=np.float64)
    return spaces.Box(low, high, (len(bounds),), dtype=np.float64)


class AnimatsEnv(gymnasium.Env):
    """One animats environment (see the module documentation)."""

    metadata = {"render_modes": ["rgb_array"], "render_fps": 50}

    def __init__(
        self,
        scene: Any = "roobot",
        noise: float = 0.0,
        seconds: Optional[float] = None,
        dt: Optional[float] = None,
        render_mode: Optional[str] = None,
        frame_skip: Optional[int] = None,
        observation: Optional[str] = None,
        act_hz: Optional[float] = None,
    ) -> None:
        if render_mode not in (None, "rgb_array"):
            raise ValueError(
                f'render_mode must be None or "rgb_array", got {render_mode!r}'
            )
        self._env = _animats.Env(scene, noise, seconds, dt, frame_skip, act_hz, observation)
        n_act = len(self._env.action_names)
        self.observation_space = _box(self._env.observation_bounds)
        self.action_space = spaces.Box(0.0, 1.0, (n_act,), dtype=np.float64)
        self.observation_names = self._env.observation_names
        self.action_names = self._env.action_names
        self.dt = self._env.dt
        self.frame_skip = self._env.frame_skip
        self.max_steps = self._env.max_steps
        self.render_mode = render_mode
        self.metadata = {**self.metadata, "render_fps": max(1, round(1.0 / self.dt))}

    def _info(self) -> dict:
        e = self._env
        return {"time": e.time, "distance": e.distance, "energy": e.energy, "ended": e.ended}

    def reset(
        self, *, seed: Optional[int] = None, options: Optional[dict] = None
    ) -> tuple[np.ndarray, dict]:
        super().reset(seed=seed)
        obs = self._env.reset(int(self.np_random.integers(0, _SEED_LIMIT)))
        return obs, self._info()

    def step(
        self, action: Any
    ) -> tuple[np.ndarray, SupportsFloat, bool, bool, dict]:
        a = np.ascontiguousarray(action, dtype=np.float64).reshape(-1)
        obs, reward, terminated, truncated = self._env.step(a)
        return obs, reward, terminated, truncated, self._info()

    def render(self) -> Optional[np.ndarray]:
        """The scene now, ``(320, 480, 3)`` uint8 (``render_mode="rgb_array"``)."""
        if self.render_mode != "rgb_array":
            return None
        return self._env.render(480, 320)


class RoobotEnv(AnimatsEnv):
    """``animats/Roobot-v0``."""

    def __init__(
        self,
        noise: float = 0.0,
        seconds: Optional[float] = None,
        dt: Optional[float] = None,
        render_mode: Optional[str] = None,
        frame_skip: Optional[int] = None,
        observation: Optional[str] = None,
    ) -> None:
        super().__init__("roobot", noise, seconds, dt, render_mode, frame_skip, observation)


class SceneEnv(AnimatsEnv):
    """``animats/Scene-v0``: ``scene`` is a path or an ``animats.Scene``;
    without ``frame_skip`` the agent acts at about 50 Hz."""

    def __init__(
        self,
        scene: Any,
        noise: float = 0.0,
        render_mode: Optional[str] = None,
        frame_skip: Optional[int] = None,
        observation: Optional[str] = None,
        seconds: Optional[float] = None,
        dt: Optional[float] = None,
    ) -> None:
        super().__init__(
            scene, noise, seconds, dt, render_mode, frame_skip, observation,
            act_hz=None if frame_skip is not None else 50.0,
        )


class AnimatsVectorEnv(VectorEnv):
    """``num_envs`` copies stepped in one call in Rust. A copy whose episode
    ended is reset at the next ``step`` (its action ignored, reward 0):
    Gymnasium's default "next step" autoreset."""

    metadata = {"render_modes": ["rgb_array"], "autoreset_mode": AutoresetMode.NEXT_STEP}

    def __init__(
        self,
        num_envs: int = 1,
        scene: Any = "roobot",
        noise: float = 0.0,
        seconds: Optional[float] = None,
        dt: Optional[float] = None,
        render_mode: Optional[str] = None,
        frame_skip: Optional[int] = None,
        observation: Optional[str] = None,
        act_hz: Optional[float] = None,
    ) -> None:
        if render_mode not in (None, "rgb_array"):
            raise ValueError(
                f'render_mode must be None or "rgb_array", got {render_mode!r}'
            )
        self._env = _animats.VecEnv(
            scene, num_envs, 0, noise, seconds, dt, frame_skip, act_hz, observation
        )
        self.num_envs = num_envs
        n_act = len(self._env.action_names)
        self.single_observation_space = _box(self._env.observation_bounds)
        self.single_action_space = spaces.Box(0.0, 1.0, (n_act,), dtype=np.float64)
        self.observation_space = batch_space(self.single_observation_space, num_envs)
        self.action_space = batch_space(self.single_action_space, num_envs)
        self.observation_names = self._env.observation_names
        self.action_names = self._env.action_names
        self.dt = self._env.dt
        self.render_mode = render_mode
        self.metadata = {**self.metadata, "render_fps": max(1, round(1.0 / self.dt))}
        self._np_random_seed = None

    def reset(
        self, *, seed: Optional[int] = None, options: Optional[dict] = None
    ) -> tuple[np.ndarray, dict]:
        if seed is not None:
            self._np_random, self._np_random_seed = gymnasium.utils.seeding.np_random(seed)
        first = int(self.np_random.integers(0, _SEED_LIMIT)) if seed is None else seed
        return self._env.reset(first), {}

    def step(
        self, actions: Any
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, dict]:
        a = np.ascontiguousarray(actions, dtype=np.float64).reshape(self.num_envs, -1)
        obs, rewards, terminated, truncated = self._env.step(a)
        return obs, rewards, terminated, truncated, {}

    def render(self) -> Optional[tuple[np.ndarray, ...]]:
        """Every copy now, ``(320, 480, 3)`` uint8 each, in a tuple
        (``render_mode="rgb_array"``; as a single environment draws it)."""
        if self.render_mode != "rgb_array":
            return None
        return tuple(self._env.render(480, 320))

    def render_copies(
        self, copies: Any, width: int = 480, height: int = 320
    ) -> np.ndarray:
        """The copies numbered in ``copies`` now, ``(len(copies), height,
        width, 3)`` uint8, drawn in parallel (whatever the ``render_mode``)."""
        return self._env.render(width, height, [int(k) for k in copies])


def _roobot_vector(num_envs: int = 1, **kwargs: Any) -> AnimatsVectorEnv:
    return AnimatsVectorEnv(num_envs, "roobot", **kwargs)


def _scene_vector(num_envs: int = 1, *, scene: Any, **kwargs: Any) -> AnimatsVectorEnv:
    # As Scene-v0: about 50 actions a second unless told.
    if kwargs.get("frame_skip") is None:
        kwargs.setdefault("act_hz", 50.0)
    return AnimatsVectorEnv(num_envs, scene, **kwargs)


def _register() -> None:
    registered = gymnasium.envs.registration.registry
    if "animats/Roobot-v0" not in registered:
        gymnasium.register(
            id="animats/Roobot-v0",
            entry_point="animats.gym:RoobotEnv",
            vector_entry_point="animats.gym:_roobot_vector",
        )
    if "animats/Scene-v0" not in registered:
        gymnasium.register(
            id="animats/Scene-v0",
            entry_point="animats.gym:SceneEnv",
            vector_entry_point="animats.gym:_scene_vector",
        )


_register()
