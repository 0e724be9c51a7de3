"""The Python API against the command line: the same scenes, the same
evaluations (to the bit), the same evolution logs."""

import json
import os
import re
import threading
import time
import warnings

import numpy as np
import pytest

import animats


# Two 10 g particles joined by 1e6 N/m, under explicit Euler at 10 ms.
STIFF = (
    "[world]\ndt = 0.01\nintegrator = \"euler\"\n"
    "[[particle]]\nname = \"a\"\nmass = 0.01\nposition = [0.0, 1.0, 0.0]\nradius = 0.01\n"
    "[[particle]]\nname = \"b\"\nmass = 0.01\nposition = [0.2, 1.0, 0.0]\nradius = 0.01\n"
    "[[spring]]\na = \"a\"\nb = \"b\"\nstiffness = 1e6\nrest_length = 0.1\n"
)


def test_a_bad_scene_raises_scene_error_naming_file_line_entry_and_field(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text(
        "[world]\ndt = 0.01\n[[particle]]\nname = \"a\"\nmass = -1.0\nposition = [0.0, 1.0, 0.0]\nradius = 0.1\n"
    )
    with pytest.raises(animats.SceneError) as e:
        animats.load(bad)
    msg = str(e.value)
    assert "bad.toml:5" in msg and "particle[0].mass" in msg, msg  # the line of `mass`
    assert isinstance(e.value, ValueError)
    with pytest.raises(animats.SceneError, match="cannot read"):
        animats.load(tmp_path / "missing.toml")


def test_a_world_steps_and_falls_freely(tmp_path):
    # One ball in vacuum: after n symplectic steps y = y0 - g h² n(n+1)/2.
    s = tmp_path / "ball.toml"
    s.write_text(
        "[world]\ndt = 0.001\nintegrator = \"symplectic\"\ngravity = [0.0, -9.8, 0.0]\n"
        "[[particle]]\nname = \"ball\"\nmass = 1.0\nposition = [0.0, 10.0, 0.0]\nradius = 0.1\n"
    )
    w = animats.load(s).world()
    assert w.names == ["ball"]
    w.step(1000)
    assert w.time == pytest.approx(1.0, abs=1e-12)
    p, v = w.positions(), w.velocities()
    assert p.shape == (1, 3) and p.dtype == np.float64
    h, n = 0.001, 1000
    assert p[0, 1] == pytest.approx(10.0 - 9.8 * h * h * n * (n + 1) / 2, abs=1e-9)
    assert v[0, 1] == pytest.approx(-9.8, abs=1e-9)


def test_snapshot_and_restore_continue_bit_for_bit(root):
    w = animats.load(root / "scenes" / "pogo.toml").world()
    w.step(300)
    snap = w.snapshot()
    w.step(500)
    a = w.positions()
    va = w.velocities()
    w.restore(snap)
    assert w.time == snap.time
    # The pogo's FSM's own state is in the snapshot: it steps on alike.
    w.step(500)
    assert np.array_equal(w.positions(), a) and np.array_equal(w.velocities(), va)
    w.restore(snap)
    w2 = animats.load(root / "scenes" / "pogo.toml").world()
    w2.step(300)
    assert np.array_equal(w2.positions(), w.positions())
    # Into a world of another scene: refused, and that world unchanged.
    walker = animats.load(root / "scenes" / "walker.toml").world()
    before = walker.positions()
    with pytest.raises(ValueError, match="another world|snapshot holds"):
        walker.restore(snap)
    assert np.array_equal(walker.positions(), before)


def test_a_pile_restored_goes_on_bit_for_bit_with_its_sleeping_rocks(root):
    # scenes/pile.toml's rocks fall asleep from about 2 s (sleep_speed): the
    # snapshot holds which sleep and where, so the restored pile goes on as
    # the original did, to the bit, and as one built anew from the file.
    w = animats.load(root / "scenes" / "pile.toml").world()
    w.step(4000)
    snap = w.snapshot()
    w.step(1500)
    a, va = w.positions(), w.velocities()
    w.restore(snap)
    w.step(1500)
    assert np.array_equal(w.positions(), a) and np.array_equal(w.velocities(), va)
    w2 = animats.load(root / "scenes" / "pile.toml").world()
    w2.restore(snap)
    w2.step(1500)
    assert np.array_equal(w2.positions(), a) and np.array_equal(w2.velocities(), va)


def test_actuators_and_sensors_in_scene_order(root):
    scene = animats.load(root / "scenes" / "pogo.toml")
    assert scene.actuators == ["leg_muscle"]
    assert scene.sensors == ["foot_touch", "leg_length"]
    w = scene.world()
    s = w.sensors()
    assert s.shape == (2,) and np.all((0 <= s) & (s <= 1))
    w.set_actuators([0.9])
    assert w.actuators()[0] == pytest.approx(0.9)
    with pytest.raises(ValueError, match="1 actuators"):
        w.set_actuators([0.1, 0.2])
    with pytest.raises(ValueError, match="not finite"):
        w.set_actuators([float("nan")])


def test_evaluate_equals_animats_evaluate_to_the_bit(cli, root, crawler):
    for path in [crawler, root / "scenes" / "walker_evolved.toml"]:
        want = json.loads(cli("evaluate", path, "--json"))
        scene = animats.load(path)
        got = animats.evaluate(scene, scene.start())
        assert got.shape == (1,)
        assert got[0] == want["fitness"], path
    for params in ["initial", "evolved"]:
        want = json.loads(cli("evaluate", "roobot", "--params", params, "--json"))
        genome = animats.ROOBOT_INITIAL if params == "initial" else _evolved(root)
        assert animats.evaluate("roobot", genome)[0] == want["fitness"]


def _evolved(root):
    import tomllib

    return np.array(tomllib.loads((root / "params" / "evolved.toml").read_text())["params"])


def test_evaluate_is_the_same_bits_on_any_thread_count(crawler):
    rng = np.random.default_rng(1)
    scene = animats.load(crawler)
    b = scene.bounds()
    g = b[:, 0] + (b[:, 1] - b[:, 0]) * rng.random((24, len(b)))
    one = animats.evaluate(scene, g, threads=1)
    two = animats.evaluate(scene, g, threads=2)
    assert np.array_equal(one, two)
    assert len(set(one.tolist())) > 20, "different genomes, different fitness"
    ev = animats.Evaluator(scene, threads=2)
    assert np.array_equal(ev.evaluate(g), one)
    with pytest.raises(ValueError, match="columns"):
        animats.evaluate(scene, g[:, :3])
    with pytest.raises(ValueError, match="not finite"):
        animats.evaluate(scene, np.full((1, len(b)), np.nan))


def _csv_rows(text):
    lines = text.strip().splitlines()
    return lines[0], lines[1:]


@pytest.mark.parametrize("optimiser", ["hill-climber", "ga", "cma-es"])
def test_an_evolution_writes_the_command_lines_log_and_best(cli, crawler, tmp_path, optimiser):
    args = ["--optimiser", optimiser, "--generations", "6", "--lanes", "2", "--seed", "4"]
    cli("evolve", crawler, *args, "--out", tmp_path / "cli")
    run = animats.Evolution(str(crawler), lanes=2, generations=6, seed=4, optimiser=optimiser)
    run.run()
    assert run.log_csv() == (tmp_path / "cli" / "log.csv").read_text()
    assert run.best_toml() == (tmp_path / "cli" / "best.toml").read_text()
    run.save(tmp_path / "py")
    assert (tmp_path / "py" / "log.csv").read_bytes() == (tmp_path / "cli" / "log.csv").read_bytes()


def test_a_python_loop_over_the_optimiser_gives_the_command_lines_log(cli, crawler, tmp_path):
    # Lane 0 of `animats evolve` is one optimiser and one evaluate per generation.
    cli("evolve", crawler, "--optimiser", "cma-es", "--generations", "8", "--lanes", "1",
        "--seed", "9", "--out", tmp_path)
    header, rows = _csv_rows((tmp_path / "log.csv").read_text())
    assert header.startswith("lane,generation,evaluations,fitness,best_fitness")
    scene = animats.load(crawler)
    opt = animats.Optimiser("cma-es", seed=9, problem=scene)
    best = -np.inf
    for gen in range(1, 9):
        pop = opt.ask()
        f = animats.evaluate(scene, pop)
        opt.tell(f)
        top = int(np.argmax(f))
        best = max(best, f[top])
        lane, g, evals, fitness, best_fitness = rows[gen - 1].split(",")[:5]
        assert (int(g), int(evals)) == (gen, gen * len(pop))
        assert float(fitness) == f[top] and float(best_fitness) == best
    assert opt.generation == 8
    with pytest.raises(ValueError, match="ask"):
        opt.tell(f)


def test_the_roobots_evolution_is_the_thesis_run(cli, tmp_path):
    cli("evolve", "--generations", "30", "--lanes", "3", "--seed", "3", "--out", tmp_path)
    run = animats.Evolution("roobot", lanes=3, generations=30, seed=3)
    run.run(threads=1)
    assert run.log_csv() == (tmp_path / "log.csv").read_text()
    assert run.best_toml() == (tmp_path / "best.toml").read_text()


def test_ctrl_c_stops_a_run_at_whole_generations_and_it_goes_on_to_the_same_bits(ctrl_c):
    straight = animats.Evolution("roobot", lanes=3, generations=300, seed=5)
    straight.run(threads=2)
    run = animats.Evolution("roobot", lanes=3, generations=300, seed=5)
    # Ctrl-C 0.3 s into a run of about 2 s on one thread.
    with ctrl_c(0.3), pytest.raises(KeyboardInterrupt):
        run.run(threads=1)
    assert 0 < run.generation < 300 and not run.done
    run.run(threads=2)
    assert run.log_csv() == straight.log_csv()
    assert run.best_toml() == straight.best_toml()


def test_another_thread_sees_a_run_s_progress_and_waits_for_its_log():
    straight = animats.Evolution("roobot", lanes=3, generations=300, seed=5)
    straight.run(threads=1)
    run = animats.Evolution("roobot", lanes=3, generations=300, seed=5)
    worker = threading.Thread(target=run.run, kwargs={"threads": 1})
    worker.start()
    seen, during = [], None
    while worker.is_alive():
        seen.append((run.generation, run.evaluations))
        if len(seen) == 3:
            # Any call but the progress waits for the run: this log is the
            # whole run's (it was "Already mutably borrowed").
            during = run.log_csv()
            # (The thread itself ends a moment after the run lets go: under
            # load it was still alive here.)
            worker.join(timeout=60)
            assert not worker.is_alive()
        time.sleep(0.02)
    worker.join()
    assert during is not None, f"the run ended within {len(seen)} looks"
    # Seen part way (about 2 s on one thread), never going back.
    assert any(0 < g < 300 for g, _ in seen), seen
    assert seen == sorted(seen), seen
    assert during == run.log_csv() == straight.log_csv()
    assert (run.generation, run.evaluations, run.best_fitness, run.done) == (
        300,
        straight.evaluations,
        straight.best_fitness,
        True,
    )


def test_ctrl_c_stops_an_evaluation_of_many_genomes(root, ctrl_c):
    scene = animats.load(root / "scenes" / "walker.toml")
    few = np.tile(scene.start(), (3, 1))
    want = animats.evaluate(scene, few, threads=1)
    # About 20 s of evaluations on one thread; Ctrl-C 0.3 s in.
    many = np.tile(scene.start(), (3000, 1))
    began = time.monotonic()
    with ctrl_c(0.3), pytest.raises(KeyboardInterrupt):
        animats.evaluate(scene, many, threads=1)
    assert time.monotonic() - began < 3.0
    # Nothing of it lingers: the next call is as any other.
    assert np.array_equal(animats.evaluate(scene, few, threads=1), want)


def test_ctrl_c_stops_one_long_evaluation_within_it(root, tmp_path, ctrl_c, cli):
    # One walker for 80,000 simulated seconds (about two minutes of steps):
    # Ctrl-C 0.3 s in ends the evaluations under way, not only those not yet
    # begun, from `evaluate` (one genome on the global pool, two there, one
    # on a pool of its own, fewer genomes than its threads) and
    # `evaluate_scenes`.
    text = (root / "scenes" / "walker.toml").read_text()
    assert "[evolve]\ncontroller = \"gait\"\nduration = 10.0\n" in text
    long = text.replace(
        "[evolve]\ncontroller = \"gait\"\nduration = 10.0\n",
        "[evolve]\ncontroller = \"gait\"\nduration = 80000.0\n",
    ).replace('fail_on_touch = ["hip_f", "hip_b"]\n', "")
    assert "fail_on_touch" not in long
    path = tmp_path / "long_walker.toml"
    path.write_text(long)
    scene = animats.load(path)
    one = scene.start()[None, :]
    for call in (
        lambda: animats.evaluate(scene, one),  # on the calling thread
        lambda: animats.evaluate(scene, np.tile(one, (2, 1))),  # the global pool
        lambda: animats.evaluate(scene, one, threads=1),  # on a pool of its own
        lambda: animats.evaluate(scene, np.tile(one, (3, 1)), threads=4),
        lambda: animats.evaluate_scenes([long]),
    ):
        began = time.monotonic()
        with ctrl_c(0.3), pytest.raises(KeyboardInterrupt):
            call()
        assert time.monotonic() - began < 3.0
    # Nothing lingers: a whole evaluation afterwards is the command line's.
    walker = root / "scenes" / "walker.toml"
    short = animats.load(walker)
    one = animats.evaluate(short, short.start()[None, :], threads=1)
    assert one[0] == json.loads(cli("evaluate", walker, "--json"))["fitness"]


def test_a_saved_run_resumes_to_the_same_bits_here_and_on_the_command_line(cli, crawler, tmp_path):
    args = dict(lanes=2, seed=5, optimiser="cma-es")
    flags = ["--optimiser", "cma-es", "--lanes", 2, "--seed", 5]
    straight = animats.Evolution(str(crawler), generations=6, **args)
    straight.run()
    cli("evolve", crawler, *flags, "--generations", 6, "--out", tmp_path / "cli6")
    files = ("log.csv", "best.toml")
    # Saved in Python after 3 generations, resumed in Python.
    part = animats.Evolution(str(crawler), generations=6, **args)
    part.run(generations=3)
    part.save(tmp_path / "py")
    again = animats.Evolution.resume(tmp_path / "py")
    assert (again.generation, again.done, again.evaluations) == (3, False, part.evaluations)
    assert again.config == part.config
    again.run()
    assert again.log_csv() == straight.log_csv()
    again.save(tmp_path / "py")
    for f in files:
        assert (tmp_path / "py" / f).read_bytes() == (tmp_path / "cli6" / f).read_bytes(), f
    # Saved by `run` itself, after every generation: the same run.
    saving = animats.Evolution(str(crawler), generations=6, **args)
    saving.run(checkpoint=tmp_path / "saving", checkpoint_every=0.0)
    assert saving.log_csv() == straight.log_csv()
    assert animats.Evolution.resume(tmp_path / "saving").done
    with pytest.raises(ValueError, match="checkpoint_every"):
        saving.run(checkpoint=tmp_path / "saving", checkpoint_every=float("nan"))
    # Python's checkpoint continued by the command line.
    part.save(tmp_path / "py3")
    cli("evolve", "--resume", tmp_path / "py3", "--generations", 6)
    for f in files:
        assert (tmp_path / "py3" / f).read_bytes() == (tmp_path / "cli6" / f).read_bytes(), f
    # The command line's checkpoint continued in Python, its total raised.
    cli("evolve", crawler, *flags, "--generations", 3, "--out", tmp_path / "cli3")
    there = animats.Evolution.resume(tmp_path / "cli3", generations=6)
    assert there.generation == 3
    there.run()
    assert there.log_csv() == straight.log_csv()
    # What is refused: fewer generations than done, no checkpoint, a
    # damaged one, and a save between an ask and its tell.
    with pytest.raises(ValueError, match="fewer than the 6 already done"):
        animats.Evolution.resume(tmp_path / "py", generations=5)
    with pytest.raises(FileNotFoundError, match="no checkpoint here"):
        animats.Evolution.resume(tmp_path / "nowhere")
    damaged = tmp_path / "damaged"
    damaged.mkdir()
    text = (tmp_path / "py3" / "checkpoint.json").read_text()
    (damaged / "checkpoint.json").write_text(text.replace('"seed":5', '"seed":6', 1))
    assert (damaged / "checkpoint.json").read_text() != text
    with pytest.raises(ValueError, match="corrupt"):
        animats.Evolution.resume(damaged)
    asked = animats.Evolution.resume(tmp_path / "cli3", generations=6)
    asked.ask()
    with pytest.raises(ValueError, match="tell the outcomes"):
        asked.save(tmp_path / "asked")
    assert not (tmp_path / "asked" / "checkpoint.json").exists()


def test_python_m_animats_evolve_stops_on_ctrl_c_and_resumes(cli, crawler, tmp_path):
    import signal
    import subprocess
    import sys

    args = ["--optimiser", "ga", "--lanes", "3", "--seed", "8"]
    cmd = [sys.executable, "-m", "animats.evolve", str(crawler), *args, "--generations",
           "100000000", "--no-check", "--out", str(tmp_path / "py")]
    # SIGINT as a terminal's Ctrl-C sends it. (A process started in the
    # background, as CI may be, hands SIGINT on ignored, and Python then
    # keeps it so: the child gets it back.)
    p = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                         preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    try:
        time.sleep(3.0)
        p.send_signal(signal.SIGINT)
        out, err = p.communicate(timeout=60)
    finally:
        p.kill()
    assert p.returncode == 130, (out, err)
    m = re.search(r"interrupted at generation (\d+); continue with "
                  r"`python -m animats.evolve --resume (.+)`", err)
    assert m and m.group(2) == str(tmp_path / "py"), err
    saved = animats.Evolution.resume(tmp_path / "py")
    assert int(m.group(1)) == saved.generation > 0
    total = saved.generation + 20
    r = subprocess.run([sys.executable, "-m", "animats.evolve", "--resume", str(tmp_path / "py"),
                        "--generations", str(total), "--no-check"], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    cli("evolve", crawler, *args, "--generations", total, "--no-check", "--out", tmp_path / "cli")
    for f in ("log.csv", "best.toml"):
        assert (tmp_path / "py" / f).read_bytes() == (tmp_path / "cli" / f).read_bytes(), f
    # A scene with --resume, or another seed, is refused.
    for extra in ([str(crawler)], ["--seed", "9"]):
        r = subprocess.run([sys.executable, "-m", "animats.evolve", *extra, "--resume",
                            str(tmp_path / "py")], capture_output=True, text=True)
        assert r.returncode != 0 and "keeps its" in r.stderr, r.stderr


def test_ask_and_tell_elsewhere_equal_run_here(crawler):
    here = animats.Evolution(str(crawler), lanes=2, generations=5, seed=2, optimiser="ga")
    here.run()
    there = animats.Evolution(str(crawler), lanes=2, generations=5, seed=2, optimiser="ga")
    ev = animats.Evaluator(str(crawler), threads=1)
    while not there.done:
        genomes, lanes = there.ask()
        assert sorted(set(lanes)) == [0, 1]
        with pytest.raises(ValueError, match="tell"):
            there.ask()
        there.tell(ev.outcomes(genomes))
    assert there.log_csv() == here.log_csv()


def test_a_blow_up_raises_runtime_error_naming_the_particle(tmp_path):
    # A spring far too stiff for explicit Euler at this step diverges.
    s = tmp_path / "stiff.toml"
    s.write_text(STIFF)
    with pytest.warns(RuntimeWarning, match="expect a blow-up"):
        w = animats.load(s).world()
    with pytest.raises(RuntimeError) as e:
        w.step(100_000)
    assert "diverged" in str(e.value) and "particle #0" in str(e.value), str(e.value)
    assert 0 < w.time < 1000, "it stopped at the blow-up, not after 100,000 steps"


def test_python_m_animats_evolve_writes_the_command_lines_files(cli, crawler, tmp_path):
    import subprocess
    import sys

    args = ["--optimiser", "ga", "--generations", "4", "--lanes", "2", "--seed", "6"]
    out = cli("evolve", crawler, *args, "--out", tmp_path / "cli")
    r = subprocess.run([sys.executable, "-m", "animats.evolve", str(crawler), *args,
                        "--out", str(tmp_path / "py")], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    for f in ("log.csv", "best.toml", "checked.toml"):
        assert (tmp_path / "py" / f).read_bytes() == (tmp_path / "cli" / f).read_bytes()
    # The end's checks of the winner, printed as the command line prints them.
    checks = [l for l in out.splitlines() if l.startswith("  check:")]
    assert len(checks) == 2, out
    assert [l for l in r.stdout.splitlines() if l.startswith("  check:")] == checks
    assert "checked.toml" in r.stdout.splitlines()[-1]
    # --no-check: none, and the one an earlier run wrote is removed.
    r = subprocess.run([sys.executable, "-m", "animats.evolve", str(crawler), *args, "--no-check",
                        "--out", str(tmp_path / "py")], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    assert "check:" not in r.stdout and not (tmp_path / "py" / "checked.toml").exists()
    bad = subprocess.run([sys.executable, "-m", "animats.evolve", str(tmp_path / "none.toml")],
                         capture_output=True, text=True)
    assert bad.returncode == 1 and "none.toml" in bad.stderr
    # --device: the CPU's files again, or (no GPU here) what is missing.
    r = subprocess.run([sys.executable, "-m", "animats.evolve", str(crawler), *args, "--device", "cuda",
                        "--out", str(tmp_path / "gpu")], capture_output=True, text=True)
    if r.returncode == 0:
        for f in ("log.csv", "best.toml"):
            assert (tmp_path / "gpu" / f).read_bytes() == (tmp_path / "cli" / f).read_bytes()
    else:
        assert r.returncode == 1 and 'device="cuda"' in r.stderr, r.stderr
        assert not (tmp_path / "gpu" / "log.csv").exists()


def test_a_cpu_without_the_build_s_instructions_is_refused_at_import():
    """The build's CPU check runs when the module is loaded, before any of
    its code: a CPU said to lack AVX2 (the tests' hook) stops the import
    with exit status 2 and a message naming it."""
    import subprocess
    import sys

    env = dict(os.environ, ANIMATS_TEST_CPU_LACKS="avx2")
    r = subprocess.run([sys.executable, "-c", "import animats; print('imported')"],
                       env=env, capture_output=True, text=True, timeout=60)
    if "avx2" in animats._animats.CPU_FEATURES.split(","):
        assert r.returncode == 2, r
        assert r.stdout == ""
        assert "(avx2)" in r.stderr and "target-cpu=native" in r.stderr, r.stderr
    else:
        # A baseline build (RUSTFLAGS="-C target-cpu=x86-64") needs nothing.
        assert r.returncode == 0 and "imported" in r.stdout, r


def test_a_step_past_the_stability_limit_is_a_runtime_warning(root, tmp_path):
    # Two 10 g particles joined by 1e6 N/m: the pair's mode is
    # ω = √(2k/m) = 14,142 rad/s; explicit Euler is given symplectic
    # Euler's ω h ≤ 2, so 1.414e-4 s, and 0.01 s is 70.7 times that.
    s = tmp_path / "stiff.toml"
    s.write_text(STIFF)
    with pytest.warns(RuntimeWarning) as caught:
        scene = animats.load(s)
    assert len(caught) == 1 and len(scene.warnings) == 1
    w = scene.warnings[0]
    assert str(caught[0].message) == f"{s}: {w}"
    assert w.startswith("dt = 0.01 s is 70.7 times the step at which euler") and "stable below 1.414e-4 s" in w, w
    # The same text through `parse`, named as given.
    with pytest.warns(RuntimeWarning, match="^mine.toml: dt = 0.01 s"):
        animats.parse(s.read_text(), "mine.toml")
    # A [morphology] scene at 10 ms: 800 N/m between two 20 g particles,
    # ω = 282.8 rad/s, symplectic Euler stable below 7.071e-3 s.
    swim = (root / "scenes" / "bodies_swim.toml").read_text()
    coarse_text, changed = re.subn(r"\ndt = [^\n]*\n", "\ndt = 0.01\n", swim, count=1)
    assert changed == 1
    with pytest.warns(RuntimeWarning, match="expect some bodies to blow up"):
        coarse = animats.parse(coarse_text, "coarse.toml")
    assert any("stable below 7.071e-3 s" in x for x in coarse.warnings), coarse.warnings
    # A scene given by its path to `evaluate` and `Evolution` warns as
    # `load` does (and as `animats evaluate` prints it).
    walker = (root / "scenes" / "walker.toml").read_text()
    coarse_text, changed = re.subn(r"\ndt = [^\n]*\n", "\ndt = 0.05\n", walker, count=1)
    assert changed == 1
    coarse_path = tmp_path / "coarse_walker.toml"
    coarse_path.write_text(coarse_text)
    genome = animats.load(root / "scenes" / "walker.toml").start()
    with pytest.warns(RuntimeWarning, match=f"^{re.escape(str(coarse_path))}: dt = 0.05 s .*expect a blow-up"):
        animats.evaluate(str(coarse_path), genome)
    with pytest.warns(RuntimeWarning, match="expect a blow-up"):
        animats.Evolution(str(coarse_path), generations=1, lanes=1, seed=1)
    # A batch of texts: one warning a message, naming the scenes that gave
    # it (the first five, then how many more), none for a sound one.
    with pytest.warns(RuntimeWarning) as caught:
        animats.evaluate_scenes([walker] + [coarse_text] * 7, threads=2)
    assert len(caught) == 1, [str(c.message) for c in caught]
    assert re.match(r"^<scenes 1, 2, 3, 4, 5 and 2 more>: dt = 0\.05 s .*expect a blow-up", str(caught[0].message)), str(caught[0].message)
    with pytest.warns(RuntimeWarning, match=r"^<scene 1>: dt = 0\.05 s"):
        animats.evaluate_scenes([walker, coarse_text])
    with pytest.warns(RuntimeWarning, match=r"^<scenes 0 and 2>: dt = 0\.05 s"):
        animats.evaluate_scenes([coarse_text, walker, coarse_text])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        animats.evaluate_scenes([walker])
    # The shipped scenes load without a word.
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        for name in ("bodies_swim.toml", "bodies_walk.toml", "walker.toml"):
            assert animats.load(root / "scenes" / name).warnings == []


def test_ctrl_c_stops_the_making_of_a_large_vector_environment(root, ctrl_c):
    # 200,000 walkers take about 40 s to make on one core (0.2 ms each);
    # Ctrl-C 0.3 s in stops the making.
    walker = str(root / "scenes" / "walker.toml")
    began = time.monotonic()
    with ctrl_c(0.3), pytest.raises(KeyboardInterrupt):
        animats.VecEnv(walker, 200_000, act_hz=50.0)
    assert time.monotonic() - began < 3.0
    # Nothing of it lingers: the next one is made and steps as any other.
    v = animats.VecEnv(walker, 3, act_hz=50.0)
    one = animats.Env(walker, act_hz=50.0)
    one.reset(2)
    a = np.full((3, len(v.action_names)), 0.7)
    o, *_ = v.step(a)
    assert np.array_equal(o[2], one.step(a[2])[0])


def test_ctrl_c_stops_a_long_step_of_a_vector_environment_which_must_then_be_reset(root, ctrl_c):
    # 512 walkers each holding its action for the whole 10 s episode:
    # about 2.5 s a step on two cores; Ctrl-C 0.15 s in stops it.
    walker = str(root / "scenes" / "walker.toml")
    v = animats.VecEnv(walker, 512, frame_skip=20_000)
    v.reset(5)
    a = np.full((512, len(v.action_names)), 0.7)
    began = time.monotonic()
    with ctrl_c(0.15), pytest.raises(KeyboardInterrupt):
        v.step(a)
    assert time.monotonic() - began < 1.5
    # Some copies stepped, others not: stepping on is refused until a reset.
    with pytest.raises(ValueError, match="call reset"):
        v.step(a)
    # Reset, it is a fresh one's equal: the same observations, and after a
    # (whole) step the same as a single environment's.
    o = v.reset(5)
    fresh = animats.VecEnv(walker, 512, frame_skip=20_000)
    assert np.array_equal(o, fresh.reset(5))
    o, r, terminated, truncated = v.step(a)
    one = animats.Env(walker, frame_skip=20_000)
    one.reset(5 + 511)
    o1, r1, *_ = one.step(a[511])
    assert np.array_equal(o[511], o1) and r[511] == r1
    assert truncated.all() or terminated.any()


def test_an_optimiser_of_too_many_genes_is_refused():
    # (dim=2**40 hung, making 8 TB of zeros.)
    with pytest.raises(ValueError, match="more than any optimiser takes"):
        animats.Optimiser("cma-es", dim=2**40)
    with pytest.raises(ValueError, match="more than cma-es takes"):
        animats.Optimiser("cma-es", dim=10_001)
    assert animats.Optimiser("ga", dim=10_001).ask().shape == (32, 10_001)
