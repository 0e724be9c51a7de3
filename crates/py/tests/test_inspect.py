"""Inspecting creatures from Python: a genome's world and scene text,
masses, springs and contacts, setting the state, genes held to their
bounds, and the version."""

import re
import subprocess
import sys
import time

import numpy as np
import pytest

import animats


def test_the_version_is_the_crates(root):
    # The workspace's [workspace.package] version, which every crate takes.
    cargo = (root / "Cargo.toml").read_text()
    package = cargo[cargo.index("[workspace.package]"):]
    assert re.search(r'^version = "([^"]+)"', package, re.M).group(1) == animats.__version__


def test_a_genome_becomes_a_world_and_a_scene_text(root):
    scene = animats.load(root / "scenes" / "walker.toml")
    lo, hi = scene.bounds().T
    g = lo + 0.37 * (hi - lo)
    text = scene.best_toml(g)
    back = animats.parse(text, "best.toml")
    assert np.array_equal(back.start(), g)
    # The world of the genome is the world of its text, step for step.
    a, b = scene.world(g), back.world()
    a.step(500)
    b.step(500)
    assert np.array_equal(a.positions(), b.positions())
    # ... and not the scene's own brain's.
    c = scene.world()
    c.step(500)
    assert not np.array_equal(a.positions(), c.positions())
    # Its evaluation is animats.evaluate's of the genome, to the bit.
    assert animats.evaluate(back, back.start())[0] == animats.evaluate(scene, g)[0]


def test_masses_springs_and_contacts_of_the_walker(root):
    w = animats.load(root / "scenes" / "walker.toml").world()
    m = w.masses()
    assert m.shape == (len(w.names),)
    hips = [w.names.index("hip_f"), w.names.index("hip_b")]
    assert np.all(m[hips] == 0.3)
    s = w.springs()
    # Built at rest: every spring's length is its rest length (muscles at
    # the middle of their range within 0.1 % of it).
    assert np.allclose(s["length"], s["rest_length"], rtol=2e-3)
    assert s["a"].dtype == np.int64 and s["a"].max() < len(w.names)
    assert np.all(s["stiffness"] > 0)
    # The feet (radius 0.02 m at y = 0.02 m) stand on the floor, the hips not.
    on = w.contacts()
    feet = [i for i, n in enumerate(w.names) if n.startswith("foot")]
    assert on.dtype == np.bool_ and on[feet].all() and not on[hips].any()


def test_contacts_are_measured_from_the_terrain_and_the_tolerance_checked(tmp_path):
    # A 1 cm ball resting on a 20° slope, 0.5 m along it (its surface 18 cm
    # above y = 0), and one 1 cm clear of the slope.
    def ball(name, x, gap):
        y = x * np.tan(np.radians(20)) + (0.01 + gap) / np.cos(np.radians(20))
        return f"[[particle]]\nname = \"{name}\"\nmass = 0.1\nposition = [{x}, {y}, 0.0]\nradius = 0.01\n"

    s = tmp_path / "slope.toml"
    s.write_text(
        "[world]\ndt = 0.001\n[terrain]\nkind = \"slope\"\nangle = 20.0\n"
        + ball("resting", 0.5, 0.0)
        + ball("above", 1.0, 0.01)
    )
    w = animats.load(s).world()
    assert w.contacts().tolist() == [True, False]
    assert w.contacts(tolerance=0.011).tolist() == [True, True]
    for bad in (float("nan"), -1e-3, float("inf")):
        with pytest.raises(ValueError, match="tolerance"):
            w.contacts(tolerance=bad)


def test_ctrl_c_stops_a_long_step_between_steps(root, ctrl_c):
    scene = animats.load(root / "scenes" / "walker.toml")
    w = scene.world()
    # Ctrl-C 0.3 s into a call of about a minute (bounded, so that a
    # Ctrl-C not heard fails the test rather than hanging it).
    began = time.monotonic()
    with ctrl_c(0.3), pytest.raises(KeyboardInterrupt):
        w.step(2 * 10**7)
    assert time.monotonic() - began < 3.0
    steps = round(w.time / w.dt)
    assert 0 < steps < 2 * 10**7
    # It stands after its last whole step: the same bits as a world stepped
    # that far in one go.
    straight = scene.world()
    straight.step(steps)
    assert straight.time == w.time
    assert np.array_equal(straight.positions(), w.positions())
    assert np.array_equal(straight.velocities(), w.velocities())
    with pytest.raises(ValueError, match="too many"):
        w.step(10**12 + 1)


def test_a_world_read_while_another_thread_steps_it_waits_for_the_step(root):
    # Before, the reader waited for the world holding the GIL, which the
    # stepping thread needed back to let go of it: both hung for ever. In
    # a process of its own, so that a hang fails here instead of stopping
    # the tests.
    code = f"""
import threading, time, animats
w = animats.load({str(root / "scenes" / "walker.toml")!r}).world()
t = threading.Thread(target=lambda: w.step(400_000))
t.start()
time.sleep(0.05)
w.positions()
t.join()
print(round(w.time / w.dt))
"""
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    assert out.stdout.split() == ["400000"]


def test_positions_and_velocities_can_be_set(tmp_path):
    s = tmp_path / "ball.toml"
    s.write_text(
        "[world]\ndt = 0.001\nintegrator = \"symplectic\"\ngravity = [0.0, 0.0, 0.0]\n"
        "[[particle]]\nname = \"ball\"\nmass = 1.0\nposition = [0.0, 1.0, 0.0]\nradius = 0.1\n"
    )
    w = animats.load(s).world()
    w.set_positions(np.array([[1.0, 2.0, 3.0]]))
    w.set_velocities(np.array([[0.5, 0.0, -1.0]]))
    w.step(1000)
    # Uniform motion for 1 s.
    assert np.allclose(w.positions(), [[1.5, 2.0, 2.0]], atol=1e-12)
    with pytest.raises(ValueError, match=r"\(1, 3\)"):
        w.set_positions(np.zeros((2, 3)))
    with pytest.raises(ValueError, match="not finite"):
        w.set_velocities(np.array([[np.nan, 0.0, 0.0]]))


def test_genes_outside_their_bounds_are_refused_unless_clipped(root):
    scene = animats.load(root / "scenes" / "walker.toml")
    lo, hi = scene.bounds().T
    g = scene.start().copy()
    g[0] = hi[0] + 1.0
    with pytest.raises(ValueError, match="gene 0 .* outside its bounds"):
        animats.evaluate(scene, g)
    clipped = animats.evaluate(scene, g, clip=True)
    inside = g.copy()
    inside[0] = hi[0]
    assert clipped[0] == animats.evaluate(scene, inside)[0]
    with pytest.raises(ValueError, match="outside its bounds"):
        animats.Evaluator(scene).evaluate(g[None, :])
    # The roobot's genes are mutated by a fraction of their value: no bounds
    # hold them (Appendix B), so they are not refused.
    far = animats.ROOBOT_INITIAL * 3.0
    assert np.isfinite(animats.evaluate("roobot", far)[0])


def test_an_optimiser_writes_its_best_as_a_scene(root):
    path = root / "scenes" / "walker.toml"
    opt = animats.Optimiser("cma-es", problem=str(path), seed=2)
    assert opt.best_toml() is None, "nothing told yet"
    scene = animats.load(path)
    for _ in range(3):
        g = opt.ask()
        opt.tell(animats.evaluate(scene, g))
    best, fitness = opt.best()
    text = opt.best_toml()
    assert "animats.Optimiser" in text.splitlines()[0]
    back = animats.parse(text, "best.toml")
    assert np.array_equal(back.start(), best)
    # The written scene scores what the optimiser was told for its best.
    assert animats.evaluate(back, back.start())[0] == fitness
    with pytest.raises(ValueError, match="no problem"):
        animats.Optimiser("cma-es", dim=3).best_toml()
