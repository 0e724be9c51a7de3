"""Quality-diversity from Python (issue 40): measures beside the fitness,
the same bits as `animats evaluate --json`; an archive written by the
command line read back by `animats.Archive`, each elite reproduced."""

import json

import numpy as np
import pytest

import animats
from conftest import ROOT

HOP_MAP = ROOT / "scenes" / "hop_map.toml"


def test_measures_match_the_command_line(cli):
    genomes = np.tile(animats.ROOBOT_INITIAL, (3, 1))
    genomes[1, 0] *= 1.1
    fitness, measures = animats.evaluate(str(HOP_MAP), genomes, measures=True)
    assert measures.shape == (3, 2)
    one = json.loads(cli("evaluate", HOP_MAP, "--json"))
    assert fitness[0] == one["fitness"]
    assert list(measures[0]) == one["measures"]
    # evaluate_scenes: the same, from the text.
    out = animats.evaluate_scenes([HOP_MAP.read_text()])
    assert out["measures"].shape == (1, 2)
    assert list(out["measures"][0]) == one["measures"]
    # Without an [archive], measures=True is refused.
    with pytest.raises(ValueError, match=r"\[archive\]"):
        animats.evaluate(str(ROOT / "scenes" / "walker.toml"), animats.load(str(ROOT / "scenes" / "walker.toml")).start(), measures=True)


def test_an_archive_reads_back_and_its_elites_reproduce(cli, tmp_path):
    out = tmp_path / "map"
    cli("evolve", HOP_MAP, "--optimiser", "map-elites", "--generations", 3, "--population", 8, "--out", out)
    a = animats.Archive(out)
    assert len(a) > 0 and a.measures.shape == (len(a), 2)
    assert a.stats["elites"] == len(a)
    assert np.all(a.time == 20.0)
    best = int(np.argmax(a.objective))
    f, m = animats.evaluate(str(HOP_MAP), a.solutions[best], measures=True)
    assert f[0] == a.objective[best]
    assert np.array_equal(m[0], a.measures[best])
    scene = json.loads(cli("evaluate", a.scene_path(a.index[best]), "--json"))
    assert scene["fitness"] == a.objective[best]
    with pytest.raises(FileNotFoundError):
        animats.Archive(tmp_path)


def test_an_ask_tell_map_matches_the_command_line(cli, tmp_path):
    cli("evolve", HOP_MAP, "--optimiser", "cma-me", "--generations", 2, "--population", 6, "--out", tmp_path / "cli")
    run = animats.Evolution(str(HOP_MAP), optimiser="cma-me", population=6, generations=2)
    ev = animats.Evaluator(str(HOP_MAP))
    while not run.done:
        genomes, _ = run.ask()
        o = ev.outcomes(genomes)
        # Outcomes refused (an ending that is none, a measure too few)
        # leave the generation asked, to be told again rightly.
        bad = dict(o, ended=["sideways"] + list(o["ended"][1:]))
        with pytest.raises(ValueError, match=r"ended\[0\]: `sideways` is not an ending"):
            run.tell(bad)
        bad = dict(o, measures=np.asarray(o["measures"])[:, :1])
        with pytest.raises(ValueError, match="1 measures told, the archive has 2"):
            run.tell(bad)
        run.tell(o)
    run.save(tmp_path / "py")
    for f in ("log.csv", "archive.csv"):
        assert (tmp_path / "py" / f).read_text() == (tmp_path / "cli" / f).read_text(), f
    # Outcomes without their measures are refused by an archive.
    run = animats.Evolution(str(HOP_MAP), optimiser="map-elites", population=4, generations=1)
    genomes, _ = run.ask()
    o = ev.outcomes(genomes)
    del o["measures"]
    with pytest.raises(ValueError, match="measures"):
        run.tell(o)
