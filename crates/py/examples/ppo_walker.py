"""PPO (stable-baselines3) learns to drive the soft walker's six muscles
from its state, through ``animats/Scene-v0``.

    pip install "./crates/py[rl]"
    python crates/py/examples/ppo_walker.py [--steps 40000] [--csv curve.csv]

The walker (``scenes/walker.toml``) acts at 50 Hz (40 physics steps of
0.5 ms per action) on 4 s episodes; its reward is the increase of its
``[evolve]`` fitness, 30 per second upright + 50 per metre forward. Every
``--every`` steps the deterministic policy is scored on one episode (the
same start each time); the curve is the distance it walks and its return.
"""

from __future__ import annotations

import argparse
import csv
import pathlib
import sys
import time

import gymnasium
import numpy as np

import animats.gym  # noqa: F401  (registers the environments)

ROOT = pathlib.Path(__file__).resolve().parents[3]


def make(seconds: float) -> gymnasium.Env:
    return gymnasium.make(
        "animats/Scene-v0",
        scene=str(ROOT / "scenes" / "walker.toml"),
        observation="state",
        seconds=seconds,
    )


def score(model, env: gymnasium.Env) -> tuple[float, float]:
    """The deterministic policy's return and distance (m) on one episode."""
    obs, info = env.reset(seed=0)
    total = 0.0
    while True:
        action, _ = model.predict(obs, deterministic=True)
        obs, r, term, trunc, info = env.step(action)
        total += r
        if term or trunc:
            return total, info["distance"]


def main(argv: list[str] | None = None) -> list[tuple[int, float, float, float]]:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--steps", type=int, default=40_000)
    p.add_argument("--every", type=int, default=4_096)
    p.add_argument("--seconds", type=float, default=4.0)
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--csv", type=pathlib.Path)
    args = p.parse_args(argv)

    import torch
    from stable_baselines3 import PPO

    torch.set_num_threads(1)
    env, judge = make(args.seconds), make(args.seconds)
    model = PPO("MlpPolicy", env, n_steps=1024, batch_size=64, seed=args.seed, verbose=0)
    start = time.perf_counter()
    curve = [(0, *score(model, judge), 0.0)]
    print("steps  return  distance_m  wall_s")
    print(f"{0:5d}  {curve[0][1]:6.1f}  {curve[0][2]:10.3f}  {0.0:6.1f}")
    done = 0
    while done < args.steps:
        model.learn(args.every, reset_num_timesteps=False)
        done += args.every
        ret, dist = score(model, judge)
        wall = time.perf_counter() - start
        curve.append((done, ret, dist, wall))
        print(f"{done:5d}  {ret:6.1f}  {dist:10.3f}  {wall:6.1f}", flush=True)
    if args.csv:
        with args.csv.open("w", newline="") as f:
            w = csv.writer(f)
            w.writerow(["steps", "return", "distance_m", "wall_s"])
            w.writerows(curve)
    return curve


if __name__ == "__main__":
    main(sys.argv[1:])
