"""Model.sweep against the command line's `camchain sweep` CSV, value for value."""

import os
import signal
import threading
import time

import numpy as np
import pytest

import camchain


def read_sweep(path):
    """The sweep CSV: its `#` lines skipped, numbers parsed exactly, text cells as text."""
    with open(path) as f:
        lines = [l.rstrip("\n") for l in f if not l.startswith("#")]
    header = lines[0].split(",")
    rows = [l.split(",", len(header) - 1) for l in lines[1:]]
    return header, rows


def assert_same_rows(sweep, header, rows):
    assert sweep.columns == header
    assert len(sweep) == len(rows)
    for k, name in enumerate(header):
        cells = [r[k] for r in rows]
        if name in ("status", "error"):
            assert list(sweep[name]) == [c.strip('"') for c in cells], name
        elif name == "wall_time":
            assert np.all(sweep[name] > 0)
        else:
            expected = np.array([float(c) if c else np.nan for c in cells])
            # Both sides ran the same compiled code with the same values: exact.
            assert np.array_equal(sweep[name], expected, equal_nan=True), name


def test_a_product_sweep_equals_the_clis(cli, tmp_path):
    model = camchain.Model("cycloidal_roller")
    sweep = model.sweep({"omega": np.array([40.0, 50.0, 60.0]), "k": [400.0, 500.0]}, t_end=0.3, jobs=2)
    out = tmp_path / "sweep.csv"
    cli("sweep", "cycloidal_roller", "--param", "omega=40,50,60", "--param", "k=400,500",
        "--t-end", 0.3, "--csv", out, "--quiet", "--jobs", 2)
    header, rows = read_sweep(out)
    assert_same_rows(sweep, header, rows)
    assert list(sweep["run"]) == list(range(6))
    # The first parameter varies slowest, as in the CLI.
    assert list(sweep["omega"]) == [40.0, 40.0, 50.0, 50.0, 60.0, 60.0]
    assert sweep["run"].dtype == np.int64 and sweep["omega"].dtype == np.float64
    assert sweep.to_numpy().shape == (6, len(sweep.columns) - 2)


def test_a_latin_hypercube_is_the_clis_for_the_same_seed(cli, tmp_path):
    model = camchain.Model("cycloidal_roller")
    sweep = model.sweep({"omega": (40.0, 60.0), "c": (1.0, 3.0)}, samples=5, seed=7, t_end=0.2)
    out = tmp_path / "lhs.csv"
    cli("sweep", "cycloidal_roller", "--param", "omega=40:60", "--param", "c=1:3",
        "--samples", 5, "--seed", 7, "--t-end", 0.2, "--csv", out, "--quiet")
    header, rows = read_sweep(out)
    assert_same_rows(sweep, header, rows)
    # A Latin hypercube: one sample in each fifth of each interval.
    assert sorted(np.floor((sweep["omega"] - 40.0) / 4.0).astype(int)) == [0, 1, 2, 3, 4]


def test_metrics_select_columns_and_bad_sweeps_are_refused():
    model = camchain.Model("cycloidal_roller")
    sweep = model.sweep({"omega": [50.0]}, metrics=["max_normal_force"], t_end=0.1)
    assert sweep.columns == ["run", "omega", "status", "max_normal_force", "error"]
    with pytest.raises(ValueError, match="metrics: unknown metric `force`"):
        model.sweep({"omega": [50.0]}, metrics=["force"])
    with pytest.raises(ValueError, match="params: "):
        model.sweep({"nope": [1.0]})
    with pytest.raises(ValueError, match="params: omega"):
        model.sweep({"omega": [-1.0]})
    with pytest.raises(ValueError, match="params: omega: no values"):
        model.sweep({"omega": []})
    with pytest.raises(ValueError, match="jobs"):
        model.sweep({"omega": [50.0]}, jobs=0)


def test_values_set_by_with_params_are_swept_at_their_value():
    model = camchain.Model("cycloidal_roller").with_params({"k": 450.0})
    sweep = model.sweep({"omega": [50.0, 55.0]}, t_end=0.1)
    assert list(sweep["k"]) == [450.0, 450.0]


def test_ctrl_c_stops_a_sweep_within_a_second_and_keeps_its_rows(ctrl_c):
    model = camchain.Model("cycloidal_roller")
    timer = threading.Timer(0.5, lambda: os.kill(os.getpid(), signal.SIGINT))
    start = time.monotonic()
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt) as caught:
            model.sweep({"omega": np.linspace(40.0, 60.0, 2000)}, t_end=1.0, jobs=2)
    finally:
        timer.cancel()
    assert time.monotonic() - start < 0.5 + 1.0
    partial = caught.value.result
    assert partial.planned == 2000 and len(partial) < 2000
    assert all(s == "ok" for s in partial["status"])
