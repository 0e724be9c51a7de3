"""Shared fixtures: the repository's paths and the `animats` binary the
Python results are compared with."""

import _thread
import contextlib
import os
import pathlib
import shutil
import signal
import subprocess
import threading

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[3]


def animats_bin() -> str:
    env = os.environ.get("ANIMATS_BIN")
    if env:
        return env
    for build in ("release", "debug"):
        p = ROOT / "target" / build / "animats"
        if p.exists():
            return str(p)
    found = shutil.which("animats")
    if found:
        return found
    pytest.skip("no animats binary: build it (cargo build) or set ANIMATS_BIN")


@pytest.fixture(scope="session")
def cli():
    exe = animats_bin()

    def run(*args, cwd=None):
        r = subprocess.run([exe, *map(str, args)], capture_output=True, text=True, cwd=cwd)
        if r.returncode != 0:
            raise AssertionError(f"animats {' '.join(map(str, args))} failed:\n{r.stderr}")
        return r.stdout

    return run


@pytest.fixture(scope="session")
def root():
    return ROOT


@pytest.fixture(scope="session")
def crawler():
    """A 3-bead crawler no shipped scene holds (evolves in milliseconds)."""
    return ROOT / "crates" / "cli" / "tests" / "crawler.toml"


@pytest.fixture(scope="session")
def pogo_env(tmp_path_factory):
    """The pogo stick with an [evolve] table: sensors, an actuator, a reward."""
    text = (ROOT / "scenes" / "pogo.toml").read_text()
    text += '\n[evolve]\ncontroller = "hop"\nduration = 5.0\naxis = [0.0, 1.0, 0.0]\n'
    p = tmp_path_factory.mktemp("scenes") / "pogo_env.toml"
    p.write_text(text)
    return p


@pytest.fixture
def ctrl_c():
    """`with ctrl_c(seconds):` Ctrl-C, as Python sees it (SIGINT's handler
    raising KeyboardInterrupt in the main thread), `seconds` into the block.
    Python's own handler is put in place for it: a process started in the
    background, as CI may be, inherits SIGINT ignored, and then
    `interrupt_main` does nothing."""

    @contextlib.contextmanager
    def after(seconds):
        old = signal.signal(signal.SIGINT, signal.default_int_handler)
        timer = threading.Timer(seconds, _thread.interrupt_main)
        timer.start()
        try:
            yield
        finally:
            timer.cancel()
            signal.signal(signal.SIGINT, old)

    return after
