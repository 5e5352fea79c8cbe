"""Ctrl-C during a run stops it within a second with KeyboardInterrupt, keeping what it
computed; a failed run raises SimulationError with its partial result."""

import os
import signal
import threading
import time

import pytest

import camchain


def test_ctrl_c_stops_a_run_within_a_second_and_keeps_its_samples(ctrl_c):
    model = camchain.Model("paper_concave")
    timer = threading.Timer(0.5, lambda: os.kill(os.getpid(), signal.SIGINT))
    start = time.monotonic()
    timer.start()
    try:
        # Far longer than the test: 1e5 s of simulated time at tight tolerances.
        with pytest.raises(KeyboardInterrupt) as caught:
            model.simulate(t_end=1e5, dt_out=1.0, rtol=1e-12, atol=1e-14)
    finally:
        timer.cancel()
    elapsed = time.monotonic() - start
    assert elapsed < 0.5 + 1.0, elapsed
    partial = caught.value.result
    assert 0 < len(partial) and partial.t[-1] < 1e5
    assert partial["q1"].shape == partial.t.shape
