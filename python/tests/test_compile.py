"""camchain.compile: a model file as generated code, built with cargo, cached, loaded; it
must run as the built-in model compiled from the same file and as the numeric reference."""

import shutil

import numpy as np
import pytest

import camchain


@pytest.fixture(scope="module")
def cache(tmp_path_factory):
    # One cache for the module: the first compile builds the runtime, the others reuse it.
    return tmp_path_factory.mktemp("compile-cache")


@pytest.fixture(scope="module")
def paper(repository, cache, tmp_path_factory):
    model_dir = tmp_path_factory.mktemp("models")
    path = model_dir / "paper_concave.ron"
    shutil.copy(repository / "models" / "paper_concave.ron", path)
    model = camchain.compile(path, cache_dir=cache, quiet=True)
    return model, path


def test_a_compiled_model_runs_as_the_built_in_one(paper):
    compiled, path = paper
    assert not compiled.numeric and compiled.source == str(path)
    ours = compiled.simulate(t_end=2.0)
    builtin = camchain.Model("paper_concave").simulate(t_end=2.0)
    numeric = camchain.Model.from_file(path).simulate(t_end=2.0)
    assert ours.columns == builtin.columns
    for name in ours.columns:
        scale = max(1.0, float(np.max(np.abs(builtin[name]))))
        # The same generated code, built by another cargo invocation: equal to round-off.
        assert np.max(np.abs(ours[name] - builtin[name])) <= 1e-12 * scale, name
        # The numeric reference evaluates the same equations by another route; on this
        # model the integrator takes the same steps on both, and the runs differ by
        # round-off (1.0e-14 of the scale measured over 2 s, 5.5e-14 over 10 s).
        assert np.max(np.abs(ours[name] - numeric[name])) <= 1e-12 * scale, name


def test_its_terms_are_the_numeric_references(paper):
    compiled, path = paper
    numeric = camchain.Model.from_file(path)
    rng = np.random.default_rng(7)
    for _ in range(10):
        q, qd = rng.uniform(-1, 1, 4), rng.uniform(-2, 2, 4)
        for a, b in zip(compiled.equations(q, qd, 0.3), numeric.equations(q, qd, 0.3)):
            assert np.max(np.abs(a - b)) <= 1e-12 * max(1.0, float(np.max(np.abs(b))))
        for f in ("constraint", "jacobian"):
            a, b = getattr(compiled, f)(q), getattr(numeric, f)(q)
            assert np.max(np.abs(a - b)) <= 1e-12 * max(1.0, float(np.max(np.abs(b))))


def test_parameters_and_sweeps_run_on_the_library(paper, cli_csv):
    compiled, path = paper
    changed = compiled.simulate(t_end=0.5, params={"k3": 60.0})
    header, table = cli_csv("paper_concave", "--t-end", 0.5, "--param", "k3=60")
    for k, name in enumerate(header):
        scale = max(1.0, float(np.max(np.abs(table[:, k]))))
        assert np.max(np.abs(changed[name] - table[:, k])) <= 1e-12 * scale, name
    with pytest.raises(camchain.ModelError) as caught:
        compiled.with_params({"k3": -1.0})
    assert caught.value.field.startswith("parameters") and caught.value.line > 0
    sweep = compiled.sweep({"k3": [30.0, 60.0]}, t_end=0.2)
    assert list(sweep["status"]) == ["ok", "ok"]
    builtin = camchain.Model("paper_concave").sweep({"k3": [30.0, 60.0]}, t_end=0.2)
    for name in ("max_normal_force", "min_normal_force", "energy_drift"):
        assert np.allclose(sweep[name], builtin[name], rtol=1e-12, atol=1e-15), name


def test_a_file_asking_for_the_articulated_route_runs_alike(paper, cache, tmp_path):
    # docs/method.md §14: the compiled library carries the articulated-body functions, and
    # the package's engine takes that route for it. Against the built-in model on the dense
    # route: the right-hand sides agree to round-off, the adaptive steps may then differ
    # marginally, so the runs differ at the file's integration tolerance (1e-10) times the
    # error's growth over 2 s: 1e-7 of each column's scale leaves margin (as the Rust suite's
    # tests/suite/formulations.rs).
    _, path = paper
    text = path.read_text()
    asked = text.replace("simulation: (t_end: 10.0,", "simulation: (formulation: Articulated, t_end: 10.0,", 1)
    assert asked != text
    other = tmp_path / "paper_concave.ron"
    other.write_text(asked)
    compiled = camchain.compile(other, cache_dir=cache, quiet=True)
    # The library was built from code with the sweeps (the built-in model has none).
    assert any("fn articulated_terms" in p.read_text() for p in cache.rglob("model.rs"))
    ours = compiled.simulate(t_end=2.0)
    builtin = camchain.Model("paper_concave").simulate(t_end=2.0)
    assert ours.columns == builtin.columns
    for name in ours.columns:
        scale = max(1.0, float(np.max(np.abs(builtin[name]))))
        assert np.max(np.abs(ours[name] - builtin[name])) <= 1e-7 * scale, name


def test_a_second_compile_of_the_same_text_is_a_cache_hit(paper, cache, tmp_path, monkeypatch):
    _, path = paper
    # A cache hit runs no cargo: with a cargo that does not exist it still loads (the time
    # it takes is in BENCHMARKS.md, "Python").
    monkeypatch.setenv("CARGO", str(tmp_path / "no-such-cargo"))
    again = camchain.compile(path, cache_dir=cache, quiet=True)
    assert again.simulate(t_end=0.1)["q1"].shape == (11,)


def test_a_changed_file_is_compiled_again_and_bad_files_are_located(paper, cache, tmp_path):
    _, path = paper
    text = path.read_text()
    other = tmp_path / "paper_concave.ron"
    # m1 is a constant parameter: folded into the code, which must be built again.
    changed_text = text.replace('(name: "m1", value: 1.0', '(name: "m1", value: 1.5', 1)
    assert changed_text != text
    other.write_text(changed_text)
    changed = camchain.compile(other, cache_dir=cache, quiet=True)
    numeric = camchain.Model.from_file(other)
    q = np.array([-1.6, 0.2, -0.05, 0.1])
    assert np.allclose(changed.equations(q, np.zeros(4))[0], numeric.equations(q, np.zeros(4))[0],
                       rtol=1e-12, atol=1e-14)
    bad = tmp_path / "bad.ron"
    bad.write_text(text.replace('(name: "m1", value: 1.0', '(name: "m1", value: -1.0', 1))
    with pytest.raises(camchain.ModelError) as caught:
        camchain.compile(bad, cache_dir=cache, quiet=True)
    # Line 21 of models/paper_concave.ron declares m1 with min: 0.
    assert caught.value.line == 21 and caught.value.field.startswith("parameters")


def test_without_cargo_the_error_says_what_to_install(paper, tmp_path, monkeypatch):
    _, path = paper
    other = tmp_path / "p.ron"
    other.write_text(path.read_text().replace('(name: "m1", value: 1.0', '(name: "m1", value: 1.25', 1))
    monkeypatch.setenv("CARGO", str(tmp_path / "no-such-cargo"))
    with pytest.raises(camchain.CamchainError, match="needs cargo"):
        camchain.compile(other, cache_dir=tmp_path / "cache", quiet=True)
