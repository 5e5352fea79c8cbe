"""Shared helpers of the Python suite: where the command line and the repository are (set by
tests/wheel.rs, which runs this suite against the installed wheel), and the command line's
CSV read back exactly."""

import os
import pathlib
import subprocess

import numpy as np
import pytest


def _path(variable):
    value = os.environ.get(variable)
    if not value:
        pytest.fail(f"{variable} is not set: run the suite through `cargo test -p camchain-python`")
    return pathlib.Path(value)


@pytest.fixture(scope="session")
def repository():
    return _path("CAMCHAIN_REPOSITORY")


@pytest.fixture(scope="session")
def cli():
    """Runs the command line; returns the completed process (output captured)."""
    exe = _path("CAMCHAIN_CLI")

    def run(*args, check=True):
        done = subprocess.run([str(exe), *map(str, args)], capture_output=True, text=True)
        if check and done.returncode != 0:
            raise AssertionError(f"camchain {' '.join(map(str, args))}: {done.stderr}")
        return done

    return run


def read_csv(path):
    """The command line's CSV: its header and its values, parsed exactly (the CLI writes
    shortest round-trip decimals)."""
    with open(path) as f:
        header = f.readline().strip().split(",")
        rows = [[float(x) for x in line.split(",")] for line in f if line.strip()]
    return header, np.array(rows, dtype=np.float64).reshape(len(rows), len(header))


@pytest.fixture
def cli_csv(cli, tmp_path):
    """`camchain simulate ARGS --csv FILE`, read back: (header, samples × columns)."""

    def run(*args):
        out = tmp_path / "run.csv"
        cli("simulate", *args, "--csv", out, "--quiet")
        return read_csv(out)

    return run


@pytest.fixture
def ctrl_c():
    """Python's own Ctrl-C handler for the test, the previous one restored after it. A process
    started in the background by a non-interactive shell (`cmd &`, nohup) inherits SIGINT
    ignored, and Python then installs no handler: SIGINT would do nothing at all."""
    import signal

    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    yield
    signal.signal(signal.SIGINT, previous)
