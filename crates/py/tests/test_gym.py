"""The Gymnasium environments: Gymnasium's own checker, seeds, vector
environments, and rewards that add up to the evaluation's fitness."""

import numpy as np
import pytest

gymnasium = pytest.importorskip("gymnasium")
from gymnasium.utils.env_checker import check_env  # noqa: E402

import animats  # noqa: E402
import animats.gym  # noqa: E402,F401  (registers the environments)


def test_roobot_passes_gymnasiums_checker():
    env = gymnasium.make("animats/Roobot-v0")
    check_env(env.unwrapped)
    assert env.observation_space.shape == (4,) and env.action_space.shape == (3,)
    assert env.unwrapped.action_names == ["roobot.leg", "roobot.hip", "roobot.ankle"]


def test_scene_passes_gymnasiums_checker(pogo_env):
    env = gymnasium.make("animats/Scene-v0", scene=str(pogo_env))
    check_env(env.unwrapped)
    assert env.unwrapped.action_names == ["leg_muscle"]
    assert env.observation_space.shape == (2,)


def test_a_scene_without_sensors_observes_its_state(root):
    walker = str(root / "scenes" / "walker.toml")
    env = gymnasium.make("animats/Scene-v0", scene=walker)
    assert env.unwrapped.observation_names[0] == "centre y"
    with pytest.raises(ValueError, match="sensor"):
        gymnasium.make("animats/Scene-v0", scene=walker, observation="sensors")


def test_an_episode_of_no_steps_or_too_many_is_refused(root):
    # (A step longer than the episode made one of no steps, each "ended"
    # at its first step.)
    walker = str(root / "scenes" / "walker.toml")
    for kw, expect in [
        (dict(dt=30.0), "shorter than half a step of 30 s"),
        (dict(dt=1e300), "shorter than half a step"),
        (dict(seconds=1e-300), "shorter than half a step of 0.0005 s"),
        (dict(dt=1e-300), "more than 1e12"),
        (dict(dt=float("nan")), "dt must be a positive number"),
        (dict(seconds=-1.0), "seconds must be a positive number"),
        # An action held longer than the episode (act_hz tiny once made
        # frame_skip 4294967295 quietly).
        (dict(seconds=1.0, act_hz=0.5), "act_hz 0.5 asks for an action every 2 s, longer than the episode \\(1 s\\)"),
        (dict(act_hz=1e-300), "longer than the episode"),
        (dict(seconds=1.0, frame_skip=2001), "frame_skip 2001 holds each action longer than the episode"),
    ]:
        with pytest.raises(ValueError, match=expect):
            animats.Env(walker, **kw)
        with pytest.raises(ValueError, match=expect):
            animats.VecEnv(walker, 2, **kw)
    e = animats.Env(walker, seconds=0.0005)
    assert e.max_steps == 1
    assert animats.Env(walker, seconds=1.0, frame_skip=2000).max_steps == 1
    assert animats.Env(walker, seconds=1.0, act_hz=1.0).max_steps == 1


@pytest.mark.parametrize("observation", ["sensors", "state", "both"])
@pytest.mark.parametrize("frame_skip", [1, 7, None])
@pytest.mark.parametrize("render_mode", [None, "rgb_array"])
def test_every_combination_passes_gymnasiums_checker(pogo_env, observation, frame_skip, render_mode):
    env = gymnasium.make(
        "animats/Scene-v0", scene=str(pogo_env), observation=observation,
        frame_skip=frame_skip, render_mode=render_mode,
    )
    check_env(env.unwrapped, skip_render_check=render_mode is None)
    inner = env.unwrapped
    n = len(inner.observation_names)
    if observation == "sensors":
        assert n == 2
    else:
        assert inner.observation_names[n - 1].startswith("contact ")
    # Without frame_skip the agent acts at about 50 Hz.
    physics = inner._env.dt / inner.frame_skip
    if frame_skip is None:
        assert abs(inner.dt - 0.02) <= physics / 2 + 1e-12
    else:
        assert inner.frame_skip == frame_skip


def test_info_carries_distance_energy_and_why_it_ended(pogo_env):
    env = gymnasium.make("animats/Scene-v0", scene=str(pogo_env))
    _, info = env.reset(seed=0)
    assert info["ended"] is None and info["energy"] == 0.0 and info["distance"] == 0.0
    energy = 0.0
    while True:
        k = round(info["time"] / env.unwrapped.dt)
        _, _, term, trunc, info = env.step(np.array([0.9 if k % 20 < 5 else 0.3]))
        assert info["energy"] >= energy  # positive work only adds up
        energy = info["energy"]
        if term or trunc:
            break
    assert info["ended"] == "timeout" and energy > 0.0 and info["distance"] != 0.0


def test_rgb_array_renders_the_scene_as_animats_render_does(pogo_env):
    env = gymnasium.make("animats/Scene-v0", scene=str(pogo_env), render_mode="rgb_array")
    env.reset(seed=0)
    first = env.render()
    assert first.shape == (320, 480, 3) and first.dtype == np.uint8
    assert first.std() > 10, "not a blank picture"
    for k in range(25):
        env.step(np.array([0.9 if k % 10 < 3 else 0.3]))
    later = env.render()
    assert np.any(first != later), "the picture follows the scene"
    plain = gymnasium.make("animats/Scene-v0", scene=str(pogo_env))
    plain.reset(seed=0)
    assert plain.render() is None


def _episode(env, policy, seed):
    obs, _ = env.reset(seed=seed)
    total, steps = 0.0, 0
    while True:
        obs, r, term, trunc, _ = env.step(policy(obs, steps))
        total += r
        steps += 1
        assert env.observation_space.contains(obs)
        if term or trunc:
            return total, steps, term


def test_rewards_add_up_to_the_evolve_fitness(pogo_env):
    # [evolve] of the pogo: fitness = 1 × time + 50 × rise of the centre of
    # mass (axis +y). Computed here from the particles' positions and the
    # file's masses, independently of the environment's own bookkeeping.
    import tomllib

    masses = np.array([p["mass"] for p in tomllib.loads(pogo_env.read_text())["particle"]])
    env = gymnasium.make("animats/Scene-v0", scene=str(pogo_env))
    inner = env.unwrapped._env

    def centre():
        return masses @ inner.positions()[:, 1] / masses.sum()

    env.reset(seed=0)
    y0 = centre()
    total, steps = 0.0, 0
    while True:
        # Hop by hand: thrust for 0.1 s in every 0.4 s.
        a = np.array([0.9 if (steps * env.unwrapped.dt) % 0.4 < 0.1 else 0.3])
        _, r, term, trunc, _ = env.step(a)
        total += r
        steps += 1
        if term or trunc:
            break
    assert trunc and not term and steps == env.unwrapped.max_steps == round(5.0 / env.unwrapped.dt)
    assert env.unwrapped.frame_skip > 1, "Scene-v0 acts at about 50 Hz, not every physics step"
    want = 1.0 * steps * env.unwrapped.dt + 50.0 * (centre() - y0)
    assert total == pytest.approx(want, abs=1e-9)
    assert abs(centre() - y0) > 1e-3, "the pogo moved"


def test_reset_with_a_seed_repeats_the_episode():
    env = gymnasium.make("animats/Roobot-v0", noise=0.05)
    policy = lambda o, k: np.array([0.3 + 0.4 * (k % 50 < 25), 0.5 + 0.3 * o[1] - 0.15, 0.5])
    a = _episode(env, policy, 5)
    b = _episode(env, policy, 5)
    c = _episode(env, policy, 6)
    assert a == b
    assert a != c


def test_make_vec_sync_and_native_step_the_same_copies():
    n, steps = 8, 300
    sync = gymnasium.make_vec("animats/Roobot-v0", num_envs=n, vectorization_mode="sync", noise=0.02)
    native = gymnasium.make_vec("animats/Roobot-v0", num_envs=n, noise=0.02)
    assert isinstance(native, animats.gym.AnimatsVectorEnv)
    o1, _ = sync.reset(seed=10)
    o2, _ = native.reset(seed=10)
    rng = np.random.default_rng(0)
    # Gymnasium seeds copy k with seed + k: so do we. The noise is ours to
    # draw; the sync copies draw theirs from np_random, so compare shapes.
    assert o1.shape == o2.shape == (n, 4)
    done_native = 0
    for _ in range(steps):
        a = rng.random((n, 3))
        o2, r2, te2, tr2, _ = native.step(a)
        o1, r1, te1, tr1, _ = sync.step(a)
        assert o2.shape == (n, 4) and r2.shape == (n,)
        done_native += int(np.sum(te2 | tr2))
    assert done_native > 0, "random actions topple some roobots: autoreset exercised"


def test_the_native_vector_environment_is_n_single_environments():
    n = 5
    vec = animats.VecEnv("roobot", n, seed=3, noise=0.05)
    singles = [animats.Env("roobot", noise=0.05) for _ in range(n)]
    obs = vec.reset(3)
    for k, e in enumerate(singles):
        assert np.array_equal(e.reset(3 + k), obs[k])
    rng = np.random.default_rng(2)
    compared = 0
    for _ in range(100):
        a = 0.5 + 0.1 * (rng.random((n, 3)) - 0.5)
        o, r, te, tr = vec.step(a)
        ended = False
        for k, e in enumerate(singles):
            ok, rk, tek, trk = e.step(a[k])
            assert np.array_equal(ok, o[k]) and rk == r[k] and (tek, trk) == (te[k], tr[k])
            ended |= tek or trk
        compared += 1
        if ended:  # the next-step reset is exercised in the test above
            break
    assert compared >= 50


def test_the_vector_environment_draws_each_copy_as_a_single_one_does(pogo_env):
    n = 3
    vec = animats.VecEnv(str(pogo_env), n, seed=7, noise=0.2)
    singles = [animats.Env(str(pogo_env), noise=0.2) for _ in range(n)]
    for k, e in enumerate(singles):
        e.reset(7 + k)
    rng = np.random.default_rng(1)
    for _ in range(30):
        a = rng.random((n, 1))
        vec.step(a)
        for k, e in enumerate(singles):
            e.step(a[k])
    every = vec.render(240, 160)
    assert every.shape == (n, 160, 240, 3) and every.dtype == np.uint8
    for k, e in enumerate(singles):
        assert np.array_equal(every[k], e.render(240, 160)), f"copy {k}"
    # The noise set the copies apart: their pictures differ.
    assert np.any(every[0] != every[1])
    assert np.array_equal(vec.render(240, 160, [2, 0]), every[[2, 0]])
    with pytest.raises(ValueError, match="no copy 3"):
        vec.render(copies=[3])
    with pytest.raises(ValueError, match="no copy -1"):
        vec.render(copies=[-1])
    with pytest.raises(ValueError, match="between 16 and 4096"):
        vec.render(8, 8)


def test_make_vec_renders_every_copy_in_rgb_array_mode(pogo_env):
    env = gymnasium.make_vec(
        "animats/Scene-v0", num_envs=2, scene=str(pogo_env), render_mode="rgb_array"
    )
    assert isinstance(env, animats.gym.AnimatsVectorEnv)
    env.reset(seed=0)
    frames = env.render()
    assert isinstance(frames, tuple) and len(frames) == 2
    assert all(f.shape == (320, 480, 3) and f.dtype == np.uint8 for f in frames)
    assert frames[0].std() > 10, "not a blank picture"
    assert env.metadata["render_fps"] == round(1.0 / env.dt)
    assert env.render_copies([1], 64, 48).shape == (1, 48, 64, 3)
    plain = gymnasium.make_vec("animats/Scene-v0", num_envs=2, scene=str(pogo_env))
    assert plain.render() is None
    with pytest.raises(ValueError, match="render_mode"):
        gymnasium.make_vec("animats/Scene-v0", num_envs=2, scene=str(pogo_env), render_mode="human")
