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
- ``animats/Scene-v0``: any scene with actuators, sensors and an
  ``[evolve]`` table, ``gymnasium.make("animats/Scene-v0", scene=path)``.
  Actions: every actuator's level (the scene's own controllers do not run);
  observations: every sensor's level; reward: the increase of the
  ``[evolve]`` fitness; the episode lasts its ``duration`` and terminates
  when an ``[evolve]`` end rule holds or the run blows up.

Both accept ``noise`` (m/s): each reset adds to every particle's velocity a
uniform random vector of up to ``noise`` per component, drawn from the
reset's seed (0 by default: every episode starts the same).

``gymnasium.make_vec(id, num_envs=N)`` gives :class:`AnimatsVectorEnv`, the
native vector environment that steps all N copies in one call in Rust (in
parallel for large N, the GIL released); ``vectorization_mode="sync"`` gives
Gymnasium's own ``SyncVectorEnv`` of N single environments instead.
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


class AnimatsEnv(gymnasium.Env):
    """One animats environment (see the module documentation)."""

    metadata = {"render_modes": []}

    def __init__(
        self,
        scene: Any = "roobot",
        noise: float = 0.0,
        seconds: Optional[float] = None,
        dt: Optional[float] = None,
        render_mode: Optional[str] = None,
    ) -> None:
        if render_mode is not None:
            raise ValueError(
                "animats environments do not render; use `animats view` or `animats render`"
            )
        self._env = _animats.Env(scene, noise, seconds, dt)
        n_obs = len(self._env.observation_names)
        n_act = len(self._env.action_names)
        self.observation_space = spaces.Box(0.0, 1.0, (n_obs,), dtype=np.float64)
        self.action_space = spaces.Box(0.0, 1.0, (n_act,), dtype=np.float64)
        self.observation_names = self._env.observation_names
        self.action_names = self._env.action_names
        self.dt = self._env.dt
        self.max_steps = self._env.max_steps
        self.render_mode = None

    def reset(
        self, *, seed: Optional[int] = None, options: Optional[dict] = None
    ) -> tuple[np.ndarray, dict]:
        super().reset(seed=seed)
        obs = self._env.reset(int(self.np_random.integers(0, _SEED_LIMIT)))
        return obs, {"time": 0.0}

    def step(
        self, action: Any
    ) -> tuple[np.ndarray, SupportsFloat, bool, bool, dict]:
        a = np.ascontiguousarray(action, dtype=np.float64).reshape(-1)
        obs, reward, terminated, truncated = self._env.step(a)
        return obs, reward, terminated, truncated, {"time": self._env.time}


class RoobotEnv(AnimatsEnv):
    """``animats/Roobot-v0``."""

    def __init__(
        self,
        noise: float = 0.0,
        seconds: Optional[float] = None,
        dt: Optional[float] = None,
        render_mode: Optional[str] = None,
    ) -> None:
        super().__init__("roobot", noise, seconds, dt, render_mode)


class SceneEnv(AnimatsEnv):
    """``animats/Scene-v0``: ``scene`` is a path or an ``animats.Scene``."""

    def __init__(
        self, scene: Any, noise: float = 0.0, render_mode: Optional[str] = None
    ) -> None:
        super().__init__(scene, noise, None, None, render_mode)


class AnimatsVectorEnv(VectorEnv):
    """``num_envs`` copies stepped in one call in Rust. A copy whose episode
    ended is reset at the next ``step`` (its action ignored, reward 0):
    Gymnasium's default "next step" autoreset."""

    metadata = {"render_modes": [], "autoreset_mode": AutoresetMode.NEXT_STEP}

    def __init__(
        self,
        num_envs: int = 1,
        scene: Any = "roobot",
        noise: float = 0.0,
        seconds: Optional[float] = None,
        dt: Optional[float] = None,
        render_mode: Optional[str] = None,
    ) -> None:
        if render_mode is not None:
            raise ValueError("animats environments do not render")
        self._env = _animats.VecEnv(scene, num_envs, 0, noise, seconds, dt)
        self.num_envs = num_envs
        n_obs = len(self._env.observation_names)
        n_act = len(self._env.action_names)
        self.single_observation_space = spaces.Box(0.0, 1.0, (n_obs,), dtype=np.float64)
        self.single_action_space = spaces.Box(0.0, 1.0, (n_act,), dtype=np.float64)
        self.observation_space = batch_space(self.single_observation_space, num_envs)
        self.action_space = batch_space(self.single_action_space, num_envs)
        self.observation_names = self._env.observation_names
        self.action_names = self._env.action_names
        self.dt = self._env.dt
        self.render_mode = None
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


def _roobot_vector(num_envs: int = 1, **kwargs: Any) -> AnimatsVectorEnv:
    return AnimatsVectorEnv(num_envs, "roobot", **kwargs)


def _scene_vector(num_envs: int = 1, *, scene: Any, **kwargs: Any) -> AnimatsVectorEnv:
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
