"""A tour of animats from Python: run from the repository root after
`pip install "./crates/py[gym]"`."""

import numpy as np

import animats

# A scene file → a world you can step and read.
scene = animats.load("scenes/pogo.toml")
world = scene.world()
world.step(500)  # 500 steps of the scene's dt; its FSM hops the pogo stick
print(f"t = {world.time:.3f} s, positions\n{world.positions()}")
print("sensors", dict(zip(scene.sensors, world.sensors())))

# Batch evaluation: the roobot's fitness for 600 genomes, on every core.
rng = np.random.default_rng(0)
lo, hi = animats.ROOBOT_BOUNDS[:, 0], animats.ROOBOT_BOUNDS[:, 1]
genomes = animats.ROOBOT_INITIAL * (1 + 0.2 * (rng.random((600, 14)) - 0.5))
fitness = animats.evaluate("roobot", np.clip(genomes, lo, hi))
print(f"600 roobot evaluations: best {fitness.max():.1f}, median {np.median(fitness):.1f}")

# The optimisers of `animats evolve`, in a Python loop (CMA-ES on a scene).
walker = animats.load("scenes/walker.toml")
opt = animats.Optimiser("cma-es", seed=1, problem=walker)
for generation in range(10):
    pop = opt.ask()
    opt.tell(animats.evaluate(walker, pop))
genome, best = opt.best()
print(f"walker after 10 CMA-ES generations: fitness {best:.2f}")

# Gymnasium.
import gymnasium  # noqa: E402

import animats.gym  # noqa: E402,F401  (registers animats/Roobot-v0, animats/Scene-v0)

env = gymnasium.make("animats/Roobot-v0")
obs, _ = env.reset(seed=0)
total = 0.0
for _ in range(2500):
    obs, reward, terminated, truncated, _ = env.step(np.array([0.5, 0.5, 0.5]))
    total += reward
    if terminated or truncated:
        break
print(f"a roobot that holds still: return {total:.2f} (time up + 50 × distance)")

vec = gymnasium.make_vec("animats/Roobot-v0", num_envs=1024)  # stepped in Rust
obs, _ = vec.reset(seed=0)
obs, rewards, terminated, truncated, _ = vec.step(np.full((1024, 3), 0.5))
print(f"1024 roobots stepped in one call: observations {obs.shape}")
