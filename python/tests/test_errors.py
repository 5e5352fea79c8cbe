"""Bad model files, parameters and options raise located errors, never crash."""

import numpy as np
import pytest

import camchain


def test_an_unknown_built_in_names_the_built_in_models():
    with pytest.raises(camchain.ModelError, match="unknown model `paper_concav`.*paper_concave"):
        camchain.Model("paper_concav")


@pytest.mark.parametrize(
    # Positions read off the files (as reference/tests/suite/bad_models.rs reads them).
    "file, line, column, field, phrase",
    [
        ("body_named_ground.ron", 9, 19, "bodies[0].name", "reserved for the fixed base"),
        ("negative_mass.ron", 25, 19, "bodies[1].mass", "mass must be positive and finite"),
    ],
)
def test_a_bad_model_file_raises_a_located_model_error(repository, file, line, column, field, phrase):
    path = repository / "reference" / "tests" / "bad_models" / file
    with pytest.raises(camchain.ModelError) as caught:
        camchain.Model.from_file(path)
    e = caught.value
    assert isinstance(e, ValueError) and isinstance(e, camchain.CamchainError)
    assert (e.file, e.line, e.column, e.field) == (str(path), line, column, field)
    assert phrase in e.message
    assert str(e).startswith(f"{path}:{line}:{column}: {field}: ")


def test_a_syntax_error_is_located_where_the_text_is_wrong(tmp_path, repository):
    text = (repository / "models" / "paper_concave.ron").read_text()
    broken = text.replace("mass:", "mass=", 1)
    at = broken.index("mass=")
    line = broken.count("\n", 0, at) + 1
    path = tmp_path / "broken.ron"
    path.write_text(broken)
    with pytest.raises(camchain.ModelError) as caught:
        camchain.Model.from_file(path)
    assert caught.value.line == line and caught.value.file == str(path)


def test_files_that_are_not_models_are_refused(tmp_path):
    with pytest.raises(camchain.ModelError, match="cannot read"):
        camchain.Model.from_file(tmp_path / "missing.ron")
    with pytest.raises(camchain.ModelError, match="directory"):
        camchain.Model.from_file(tmp_path)
    empty = tmp_path / "empty.ron"
    empty.write_text("")
    with pytest.raises(camchain.ModelError):
        camchain.Model.from_file(empty)


def test_bad_parameters_raise_located_errors(repository):
    model = camchain.Model("cycloidal_roller")
    with pytest.raises(camchain.ModelError, match="nope"):
        model.simulate(t_end=0.1, params={"nope": 1.0})
    # `omega` is declared with min: 0.0 on line 23 of the file.
    with pytest.raises(camchain.ModelError) as caught:
        model.simulate(t_end=0.1, params={"omega": -1.0})
    assert caught.value.line == 23 and "omega" in str(caught.value)
    # A parameter the generated code folds: say so, and where the numeric path sets it.
    with pytest.raises(camchain.ModelError, match="numeric=True"):
        model.with_params({"rho": 0.013})
    numeric = camchain.Model("cycloidal_roller", numeric=True).with_params({"rho": 0.013})
    assert [p["value"] for p in numeric.parameters if p["name"] == "rho"] == [0.013]
    with pytest.raises(ValueError, match="params: omega: not a number"):
        model.simulate(params={"omega": "fast"})


@pytest.mark.parametrize(
    "options, message",
    [
        ({"rtol": -1.0}, "rtol"),
        ({"atol": 2.0}, "atol"),
        ({"t_end": 0.0}, "t_end"),
        ({"t_end": float("nan")}, "t_end"),
        ({"dt_out": -0.1}, "dt_out"),
        ({"t_end": 1e12, "dt_out": 1e-6}, "t_end/dt_out"),
        ({"method": "euler"}, "method: unknown integrator `euler`"),
        ({"restitution": 1.5}, "restitution"),
        ({"restitution": 0.5, "bilateral": True}, "restitution"),
        ({"initial": {"q9": 0.0}}, "initial: no coordinate `q9`"),
        ({"initial": {"q1": float("inf")}}, "initial: q1"),
    ],
)
def test_bad_options_raise_value_errors_naming_the_option(options, message):
    model = camchain.Model("paper_concave")
    with pytest.raises(ValueError, match=message.replace("(", r"\(")):
        model.simulate(**options)


def test_bad_vectors_are_refused_with_their_length():
    model = camchain.Model("paper_concave")
    with pytest.raises(ValueError, match="q: has 3 entries, the model 4"):
        model.constraint([0.0, 0.0, 0.0])
    with pytest.raises(ValueError, match="y: has 4 entries, the model 8"):
        model.rhs(0.0, np.zeros(4))
    with pytest.raises(ValueError, match="qd: expected a sequence of numbers"):
        model.bias(np.zeros(4), "fast")
    with pytest.raises(ValueError, match="y: entry 2 is NaN, not a finite number"):
        model.rhs(0.0, [0.0, 0.0, float("nan"), 0.0, 0.0, 0.0, 0.0, 0.0])
