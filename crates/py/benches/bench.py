"""Benchmarks of the Python package (docs/PERFORMANCE.md, "Python"):

1. `animats.evaluate` on the 600 roobot genomes of `animats evolve
   --generations 100 --lanes 6 --seed 1`, against that command's own rate;
2. `env.step` of animats/Roobot-v0 against MuJoCo's Gymnasium Hopper-v5
   (if `gymnasium[mujoco]` is installed), with each one's cost below Python;
3. the native vector environment at N = 1, 64, 1024;
4. Ray on this machine (2 actors) against `animats.evaluate` on the same
   600 genomes (if Ray is installed).

Medians of --repeats runs, all in one process, one run. Usage:
    python crates/py/benches/bench.py [--animats target/release/animats] [--json out.jsonl]
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import re
import statistics
import subprocess
import time

import numpy as np

import animats

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..", ".."))
rows = []


def report(name, value, unit, **extra):
    rows.append(dict(name=name, value=value, unit=unit, **extra))
    more = "  ".join(f"{k} {v}" for k, v in extra.items())
    print(f"{name:<48} {value:>12.4g} {unit:<14} {more}", flush=True)


def median_time(f, repeats):
    times = []
    for _ in range(repeats):
        t = time.perf_counter()
        f()
        times.append(time.perf_counter() - t)
    return statistics.median(times), times


def the_600_genomes():
    """Every candidate `animats evolve --generations 100 --lanes 6 --seed 1` asks."""
    run = animats.Evolution("roobot", lanes=6, generations=100, seed=1)
    asked = []
    while not run.done:
        g, _ = run.ask()
        asked.append(g)
        run.tell(run.evaluate(g))
    return np.concatenate(asked)


def bench_evaluate(exe, repeats, genomes):
    rates = []
    for _ in range(repeats):
        out = subprocess.run(
            [exe, "evolve", "--generations", "100", "--lanes", "6", "--seed", "1",
             "--out", "/tmp/animats-bench-evolve"],
            capture_output=True, text=True, check=True,
        )
        m = re.search(r"600 evaluations in [0-9.]+ s \(([0-9.]+)/s", out.stdout + out.stderr)
        rates.append(float(m.group(1)))
        subprocess.run(["rm", "-rf", "/tmp/animats-bench-evolve"])
    cli = statistics.median(rates)
    t, _ = median_time(lambda: animats.evaluate("roobot", genomes), repeats)
    py = len(genomes) / t
    report("animats evolve (CLI), roobot", cli, "evaluations/s", runs=rates)
    report("animats.evaluate, the same 600 genomes", py, "evaluations/s",
           ratio=round(py / cli, 3), goal=">= 0.9")
    return py


def steps_per_second(env, action, n):
    env.reset(seed=0)
    t = time.perf_counter()
    for _ in range(n):
        _, _, term, trunc, _ = env.step(action)
        if term or trunc:
            env.reset()
    return (time.perf_counter() - t) / n


def bench_env(repeats):
    import gymnasium
    import animats.gym  # noqa: F401

    n = 20000
    roobot = gymnasium.make("animats/Roobot-v0")
    hold = np.array([0.5, 0.5, 0.5])
    # A policy that stays up a while: the evolved gait's levels would need
    # the FSM; a constant action falls and resets (reset cost included).
    t, _ = median_time(lambda: None, 1)
    per = statistics.median(steps_per_second(roobot, hold, n) for _ in range(repeats))
    dt = roobot.unwrapped.dt
    report("Roobot-v0 env.step", per * 1e6, "us/step", sim_per_wall=round(dt / per, 1))
    raw = animats.Env("roobot")
    a = np.ascontiguousarray(hold)

    def raw_steps():
        raw.reset(0)
        for _ in range(n):
            _, _, te, tr = raw.step(a)
            if te or tr:
                raw.reset(0)

    t, _ = median_time(raw_steps, repeats)
    report("  animats.Env.step (no Gymnasium wrappers)", t / n * 1e6, "us/step")
    try:
        hopper = gymnasium.make("Hopper-v5")
    except Exception as e:  # mujoco not installed
        print(f"Hopper-v5 not measured: {e}")
        return
    zero = np.zeros(hopper.action_space.shape)
    per_h = statistics.median(steps_per_second(hopper, zero, n) for _ in range(repeats))
    report("Hopper-v5 env.step (MuJoCo)", per_h * 1e6, "us/step",
           sim_per_wall=round(hopper.unwrapped.dt / per_h, 1))
    import mujoco

    m, d = hopper.unwrapped.model, hopper.unwrapped.data
    fs = hopper.unwrapped.frame_skip

    def mj():
        for _ in range(n):
            mujoco.mj_step(m, d, nstep=fs)

    t, _ = median_time(mj, repeats)
    report("  mujoco.mj_step x frame_skip (no Python env)", t / n * 1e6, "us/step")


def bench_vec(repeats):
    for n in (1, 64, 1024):
        v = animats.VecEnv("roobot", n)
        v.reset(0)
        a = np.full((n, 3), 0.5)
        steps = max(20, 20000 // n)

        def go():
            for _ in range(steps):
                v.step(a)

        t, _ = median_time(go, repeats)
        report(f"VecEnv roobot N={n}", n * steps / t, "env steps/s", calls_per_s=round(steps / t))


def bench_ray(repeats, genomes, here):
    try:
        import ray
    except ImportError:
        print("Ray not measured: not installed")
        return
    from animats import distributed

    ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False)
    pool = distributed.Pool("roobot", actors=2)
    pool.evaluate(genomes[:4])  # warm
    pool.stats.wall = pool.stats.compute = 0.0
    t, _ = median_time(lambda: pool.evaluate(genomes), repeats)
    rate = len(genomes) / t
    report("Ray, 2 actors, the same 600 genomes", rate, "evaluations/s",
           ratio=round(rate / here, 3), goal=">= 0.7",
           busiest_actor_computing=f"{pool.stats.compute / pool.stats.wall:.0%} of the wall time")
    pool.shutdown()
    ray.shutdown()


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--animats", default=os.path.join(ROOT, "target", "release", "animats"))
    p.add_argument("--repeats", type=int, default=5)
    p.add_argument("--json")
    a = p.parse_args()
    cpu = next((l.split(":", 1)[1].strip() for l in open("/proc/cpuinfo") if l.startswith("model name")), "?")
    print(f"{time.strftime('%Y-%m-%d')}  {cpu}  {os.cpu_count()} cores  Python {platform.python_version()}")
    genomes = the_600_genomes()
    here = bench_evaluate(a.animats, a.repeats, genomes)
    bench_env(a.repeats)
    bench_vec(a.repeats)
    bench_ray(a.repeats, genomes, here)
    if a.json:
        with open(a.json, "w") as f:
            for r in rows:
                f.write(json.dumps(dict(r, date=time.strftime("%Y-%m-%d"), cpu=cpu)) + "\n")


if __name__ == "__main__":
    main()
