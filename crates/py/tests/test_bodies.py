"""Bodies that evolve, from Python (issue 39): `Evolution` and the Ray
runner on a [morphology] scene write the command line's log.csv and
best.toml bit for bit; `evaluate_scenes` scores complete scene texts (any
bodies) as `animats evaluate` scores the files."""

import json

import numpy as np
import pytest

import animats

SMALL = """
[world]
dt = 0.001
integrator = "symplectic"
[floor]
[morphology]
max_particles = 10
max_springs = 30
[evolve]
duration = 1.0
distance_weight = 1.0
time_weight = 0.0
"""


@pytest.fixture
def small(tmp_path):
    p = tmp_path / "small.toml"
    p.write_text(SMALL)
    return p


def test_an_evolution_of_bodies_writes_the_command_lines_files(cli, small, tmp_path):
    out = cli("evolve", small, "--population", 6, "--generations", 4, "--seed", 3, "--out", tmp_path / "cli")
    run = animats.Evolution(str(small), population=6, generations=4, seed=3)
    assert run.config["optimiser"] == "body-ga"
    run.run()
    run.save(tmp_path / "py")
    for f in ("log.csv", "best.toml"):
        assert (tmp_path / "py" / f).read_bytes() == (tmp_path / "cli" / f).read_bytes(), f
    # Asked and told by hand: genomes of different lengths come as a list.
    by_hand = animats.Evolution(str(small), population=6, generations=4, seed=3)
    while not by_hand.done:
        genomes, lanes = by_hand.ask()
        assert isinstance(genomes, list) and len(genomes) == 6 and lanes == [0] * 6
        by_hand.tell(by_hand.evaluate(genomes))
    assert by_hand.log_csv() == run.log_csv()
    # Evaluated elsewhere, as Ray's actors do: with the generation's screens
    # (which children a robust scene scores again at half the step) the
    # same log; scored in full, the same survivors and best.
    elsewhere = animats.Evolution(str(small), population=6, generations=4, seed=3)
    full = animats.Evolution(str(small), population=6, generations=4, seed=3)
    evaluator = animats.Evaluator(str(small), threads=1)
    while not elsewhere.done:
        genomes, _ = elsewhere.ask()
        screens = elsewhere.screens()
        assert len(screens) == 6
        assert {json.loads(s)["kind"] for s in screens} <= {"all", "above"}
        elsewhere.tell(evaluator.outcomes(genomes, screens=screens))
        genomes, _ = full.ask()
        full.tell(evaluator.outcomes(genomes))
    assert elsewhere.log_csv() == run.log_csv()
    assert full.best_toml() == run.best_toml()
    # The end's checks, as `animats evolve` ran them: the same lines and,
    # where a candidate kept 80 % in both, the same checked.toml.
    assert animats.Evolution(str(small), population=6, generations=4, seed=3).check() is None
    report = run.check(tmp_path / "py")
    lines = [l.strip() for l in out.splitlines() if l.startswith("  check:")]
    assert [l.replace(str(tmp_path / "py"), str(tmp_path / "cli")) for l in report["lines"]] == lines
    assert len(report["best"]) == 2 and {c["integrator"] for c in report["best"]} >= {"symplectic"}
    for c in report["best"]:
        assert c["dt"] == 0.00025 and c["share"] == c["fitness"] / run.best_fitness
    checked = tmp_path / "py" / "checked.toml"
    if report["checked"] is None:
        assert not checked.exists() and not (tmp_path / "cli" / "checked.toml").exists()
    else:
        assert checked.read_text() == report["checked"]["toml"]
        assert checked.read_bytes() == (tmp_path / "cli" / "checked.toml").read_bytes()
        assert min(report["checked"]["shares"]) >= 0.8
        e = animats.evaluate_scenes([checked.read_text()])
        assert e["fitness"][0] == report["checked"]["fitness"]
    with pytest.raises(ValueError, match="2 screens for 6 genomes"):
        evaluator.outcomes(genomes, screens=screens[:2])
    with pytest.raises(ValueError, match="not a screen"):
        evaluator.outcomes(genomes, screens=["{}"] * 6)


def test_evaluate_scenes_scores_texts_as_evaluate_scores_files(cli, small, tmp_path):
    cli("evolve", small, "--population", 6, "--generations", 2, "--seed", 3, "--out", tmp_path / "b")
    files = [animats_root() / "scenes" / "walker.toml", tmp_path / "b" / "best.toml",
             animats_root() / "scenes" / "jellyfish_swim.toml"]
    texts = [f.read_text() for f in files]
    out = animats.evaluate_scenes(texts, threads=2)
    assert set(out) == {"fitness", "distance", "time", "ended"}
    for k, f in enumerate(files):
        e = json.loads(cli("evaluate", f, "--json"))
        assert out["fitness"][k] == e["fitness"] and out["distance"][k] == e["distance"], f
        assert out["time"][k] == e["time"] and out["ended"][k] == e["ended"]
    with pytest.raises(animats.SceneError, match="<scene 1>"):
        animats.evaluate_scenes([texts[0], "[world]\ndt = -1.0\n"])
    with pytest.raises(animats.SceneError, match="no \\[evolve\\] table"):
        animats.evaluate_scenes(["[world]\n"])
    with pytest.raises(TypeError):
        animats.evaluate_scenes(texts[0])
    assert animats.evaluate_scenes([])["fitness"].shape == (0,)


def test_device_cuda_gives_the_cpu_s_bits_or_says_what_is_missing():
    walker = (animats_root() / "scenes" / "walker.toml").read_text()
    scene = animats.load(animats_root() / "scenes" / "walker.toml")
    with pytest.raises(ValueError, match='device="tpu"'):
        animats.evaluate_scenes([walker], device="tpu")
    try:  # fast mode (fused multiply-adds): a fitness, or what is missing
        fast = animats.evaluate_scenes([walker], device="cuda-fast")
        assert fast["fitness"].shape == (1,)
    except RuntimeError as e:
        assert "device=\"cuda-fast\"" in str(e), e
    try:
        gpu = animats.evaluate_scenes([walker], device="cuda")
    except RuntimeError as e:  # no GPU here (CI has none): what is missing
        assert "device=\"cuda\"" in str(e)
        assert any(w in str(e) for w in ("driver", "device", "NVRTC")), e
        with pytest.raises(RuntimeError, match="driver|device|NVRTC"):
            animats.evaluate(scene, scene.start(), device="cuda")
        with pytest.raises(RuntimeError, match="driver|device|NVRTC"):
            animats.Evaluator(scene, device="cuda")
        with pytest.raises(RuntimeError, match="driver|device|NVRTC"):
            animats.Evolution(scene, device="cuda")
        return
    cpu = animats.evaluate_scenes([walker])
    assert gpu["fitness"].tolist() == cpu["fitness"].tolist()
    g = scene.start()[None, :]
    assert animats.evaluate(scene, g, device="cuda").tolist() == animats.evaluate(scene, g).tolist()
    ev = animats.Evaluator(scene, device="cuda")
    assert ev.evaluate(g).tolist() == animats.evaluate(scene, g).tolist()
    runs = [animats.Evolution(scene, generations=2, seed=3, device=d) for d in ("cuda", "cpu")]
    for r in runs:
        r.run()
    assert runs[0].best_fitness == runs[1].best_fitness


def animats_root():
    import pathlib

    return pathlib.Path(__file__).resolve().parents[3]


def test_check_picks_the_command_lines_candidate_where_the_best_fails(cli, tmp_path):
    """A best tuned to the step's errors (a coarse step, not robust) fails
    the end's checks; `Evolution.check` then tries the archive's elites as
    `animats evolve` does and names and writes the same one."""
    shipped = (animats_root() / "scenes" / "bodies_walk.toml").read_text()
    lines = ["dt = 0.002" if l.startswith("dt = 0.0005") else l for l in shipped.splitlines()]
    text = "\n".join(lines) + "\n"
    text = text.replace('optimiser = "map-elites"\n', 'optimiser = "map-elites"\nrobust = false\n', 1)
    assert "\ndt = 0.002\n" in text and "robust = false" in text
    scene = tmp_path / "coarse.toml"
    scene.write_text(text)
    for seed in range(1, 7):
        cli_dir, py_dir = tmp_path / f"cli{seed}", tmp_path / f"py{seed}"
        out = cli("evolve", scene, "--generations", 15, "--seed", seed, "--out", cli_dir)
        run = animats.Evolution(str(scene), generations=15, seed=seed)
        run.run()
        report = run.check(py_dir)
        expected = [l.strip() for l in out.splitlines() if l.startswith("  check:")]
        assert [l.replace(str(py_dir), str(cli_dir)) for l in report["lines"]] == expected
        assert (py_dir / "checked.toml").exists() == (cli_dir / "checked.toml").exists()
        if report["checked"] is not None:
            assert (py_dir / "checked.toml").read_bytes() == (cli_dir / "checked.toml").read_bytes()
        if any(c["share"] < 0.8 for c in report["best"]):
            assert report["checked"] is None or report["checked"]["label"].startswith("elite ")
            # Without a directory nothing is written, and no line says so.
            alone = run.check()
            wrote = f": wrote {py_dir / 'checked.toml'}"
            assert alone["lines"] == [l.replace(wrote, "") for l in report["lines"]]
            assert all("wrote" not in l for l in alone["lines"])
            return
    pytest.fail("no seed of 1 to 6 gave a best that fails the checks")
