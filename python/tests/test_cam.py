"""Model.cam: the cam designer's report as numbers, against the command line's and against
the motion law's closed forms."""

import math
import re

import numpy as np
import pytest

import camchain


@pytest.fixture(scope="module")
def report():
    return camchain.Model("cycloidal_roller").cam(speed=70.0, samples=720, turns=2)


def test_the_peaks_are_the_cycloidal_laws_closed_forms(report):
    # cycloidal_roller: a rise of h = 12 mm over β = 120° (models/cycloidal_roller.ron). The
    # cycloidal law's peaks at ω: v = 2hω/β, a = 2πhω²/β², j = 4π²hω³/β³ (Norton, Design of
    # Machinery, table 8-2).
    h, beta, w = 0.012, math.radians(120.0), 70.0
    peaks = report["peaks"]
    assert abs(peaks["velocity"]["max"]["value"] - 2 * h * w / beta) < 1e-12
    assert abs(peaks["acceleration"]["max"]["value"] - 2 * math.pi * h * w**2 / beta**2) < 1e-10
    assert abs(peaks["jerk"]["max"]["value"] - 4 * math.pi**2 * h * w**3 / beta**3) < 1e-6
    # The rise's velocity peaks mid-rise, at 60° after its start (the dwell ends at 60°).
    assert abs(math.degrees(peaks["velocity"]["max"]["cam_angle"]) - 120.0) < 1e-6


def test_the_sampled_design_is_design_csvs_columns(report, cli, tmp_path):
    design = report["design"]
    assert list(design) == [
        "cam_angle_deg", "s", "v", "a", "j", "pressure_angle_deg", "radius_of_curvature",
        "profile_x", "profile_y", "pitch_x", "pitch_y", "normal_force",
    ]
    assert all(v.dtype == np.float64 and v.shape == (721,) for v in design.values())
    cli("cam", "cycloidal_roller", "--speed", 70, "--samples", 720, "--turns", 2, "--out", tmp_path)
    path = tmp_path / "cycloidal_roller_cam" / "design.csv"
    header = path.read_text().splitlines()[0].split(",")
    table = np.loadtxt(path, delimiter=",", skiprows=1)
    assert header == list(design)
    for k, name in enumerate(header):
        # The same computation, printed in shortest round-trip form: exact.
        assert np.array_equal(design[name], table[:, k], equal_nan=True), name


def test_the_jump_speed_and_lift_offs_are_the_clis(report, cli, tmp_path):
    printed = cli("cam", "cycloidal_roller", "--speed", 70, "--samples", 720, "--turns", 2,
                  "--out", tmp_path).stdout
    jump = report["jump"]
    printed_jump = float(re.search(r"predicted jump speed ([0-9.]+) rad/s", printed).group(1))
    # The CLI prints twelve significant digits.
    assert abs(printed_jump - jump["speed"]) <= 1e-11 * jump["speed"]
    # README: 64.5668531162 rad/s at 3600 samples; the coarser grid here moves it little.
    assert abs(jump["speed"] - 64.5668531162) < 1e-3
    assert report["lift_offs"], "above the jump speed the follower leaves the cam"
    first = report["lift_offs"][0]
    assert f"lifts off at t = {first['t']:.9f} s" in printed
    assert report["text"].splitlines()[0] == printed.splitlines()[0]


def test_cam_options_are_checked():
    model = camchain.Model("cycloidal_roller")
    with pytest.raises(ValueError, match="samples"):
        model.cam(samples=0)
    with pytest.raises(ValueError, match="speed"):
        model.cam(speed=-1.0)
    with pytest.raises(ValueError, match="cam: studies the model file's parameter values"):
        model.with_params({"k": 400.0}).cam()
    with pytest.raises(ValueError, match="no cam designed from a motion law"):
        camchain.Model("paper_concave").cam()
