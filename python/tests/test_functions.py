"""The generated functions one call each, against the numeric recursive reference (an
independent route: the reference evaluates the same model file's tree by its own recursion
at run time) and against the runtime's own runs."""

import numpy as np
import pytest

import camchain

rng = np.random.default_rng(2026)


@pytest.mark.parametrize("name", ["paper_concave", "eccentric_roller", "four_bar", "spatial_arm"])
def test_generated_terms_match_the_numeric_reference(name):
    generated, numeric = camchain.Model(name), camchain.Model(name, numeric=True)
    n = len(generated.coordinates)
    for _ in range(20):
        q, qd, t = rng.uniform(-1, 1, n), rng.uniform(-2, 2, n), float(rng.uniform(0, 1))
        for ours, theirs in zip(generated.equations(q, qd, t), numeric.equations(q, qd, t)):
            # Round-off of two evaluation orders, relative to the term's size.
            scale = max(1.0, float(np.max(np.abs(theirs))))
            assert np.max(np.abs(ours - theirs)) <= 1e-12 * scale
        for f in ("constraint", "jacobian"):
            a, b = getattr(generated, f)(q), getattr(numeric, f)(q)
            assert np.max(np.abs(a - b)) <= 1e-12 * max(1.0, float(np.max(np.abs(b))))
        a, b = generated.bias(q, qd), numeric.bias(q, qd)
        assert np.max(np.abs(a - b)) <= 1e-12 * max(1.0, float(np.max(np.abs(b))))


def test_shapes_and_the_jacobian_by_finite_differences():
    model = camchain.Model("paper_concave")
    q = np.array([-1.6, 0.3, -0.1, 0.2])
    M, F, Q = model.equations(q, np.zeros(4))
    assert M.shape == (4, 4) and F.shape == Q.shape == (4,)
    assert np.allclose(M, M.T, rtol=0, atol=1e-14)
    assert np.all(np.linalg.eigvalsh(M) > 0)
    J = model.jacobian(q)
    assert J.shape == (1, 4)
    step = 1e-6
    for i in range(4):
        e = np.zeros(4)
        e[i] = step
        central = (model.constraint(q + e) - model.constraint(q - e)) / (2 * step)
        # Central differences: truncation O(step²) and round-off O(1e-16/step) ≈ 1e-10.
        assert abs(central[0] - J[0, i]) <= 1e-8


def test_rhs_integrated_by_hand_follows_simulate():
    # rhs solves the multiplier form densely; simulate partitions the coordinates. A plain
    # RK4 over rhs from the assembled initial state must follow simulate's trajectory.
    model = camchain.Model("paper_concave")
    r = model.simulate(t_end=0.2, dt_out=0.01, rtol=1e-12, atol=1e-14)
    n = 4
    y = np.concatenate([[r[f"q{i}"][0] for i in range(1, 5)], [r[f"q{i}_dot"][0] for i in range(1, 5)]])
    h, t = 1e-4, 0.0
    for _ in range(2000):
        k1 = model.rhs(t, y)
        k2 = model.rhs(t + h / 2, y + h / 2 * k1)
        k3 = model.rhs(t + h / 2, y + h / 2 * k2)
        k4 = model.rhs(t + h, y + h * k3)
        y = y + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
        t += h
    expected = np.array([r[f"q{i}"][-1] for i in range(1, 5)])
    # RK4 at 1e-4 s over 0.2 s: global error ~1e-12 per unit of q⁗; the drift off h = 0 of an
    # unprojected integration is of the same order. 1e-8 leaves room for both.
    assert np.max(np.abs(y[:n] - expected)) < 1e-8
    assert abs(model.constraint(y[:n])[0]) < 1e-8


def test_initial_values_replace_the_guess():
    model = camchain.Model("paper_concave")
    default = model.simulate(t_end=0.1)
    # The assembled state given back as the initial one: the same run.
    start = {f"q{i}": default[f"q{i}"][0] for i in range(1, 5)}
    start.update({f"q{i}_dot": default[f"q{i}_dot"][0] for i in range(1, 5)})
    same = model.simulate(t_end=0.1, initial=start)
    assert np.max(np.abs(same["q4"] - default["q4"])) <= 1e-12
    moved = model.simulate(t_end=0.1, initial={"q1": default["q1"][0] + 0.05})
    assert abs(moved["q1"][0] - (default["q1"][0] + 0.05)) <= 1e-12
    assert abs(moved["A_h"][0]) <= 1e-10
