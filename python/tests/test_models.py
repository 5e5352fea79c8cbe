"""The package as installed: what it lists, what a model declares, the arrays it returns."""

import pathlib

import numpy as np
import pytest

import camchain


def test_the_installed_package_is_tested_not_the_source_tree():
    # tests/wheel.rs runs pytest outside the source tree; the package must come from the
    # virtual environment's site-packages.
    assert "site-packages" in pathlib.Path(camchain.__file__).parts


def test_models_lists_the_command_lines_built_in_models(cli):
    listed = cli("list").stdout
    names = camchain.models()
    assert "paper_concave" in names and "cycloidal_roller" in names
    assert len(names) == len(set(names)) >= 20
    for name in names:
        assert name in listed, name


def test_a_model_declares_its_coordinates_contacts_parameters_and_loops():
    m = camchain.Model("paper_concave")
    assert [c["name"] for c in m.coordinates] == ["q1", "q2", "q3", "q4"]
    assert m.coordinates[0]["kind"] == "revolute" and m.coordinates[0]["unit"] == "rad"
    assert [c["name"] for c in m.contacts] == ["A"]
    assert m.contacts[0]["follower"] == "knife" and not m.contacts[0]["cam_moves"]
    assert m.loops == []
    assert not m.numeric and m.source == "paper_concave"
    four_bar = camchain.Model("four_bar")
    assert len(four_bar.loops) == 1 and four_bar.loops[0]["equations"]
    roller = camchain.Model("cycloidal_roller")
    params = {p["name"]: p for p in roller.parameters}
    assert params, "cycloidal_roller declares parameters"
    for p in params.values():
        assert p["value"] == p["default"]
        assert set(p) == {"name", "value", "default", "unit", "min", "max", "run_time", "description"}


def test_every_column_is_a_read_only_c_contiguous_float64_view():
    r = camchain.Model("paper_concave").simulate(t_end=0.2)
    assert r.columns[0] == "t" and len(r) == len(r.t) == 21
    for name in r.columns:
        column = r[name]
        assert column.dtype == np.float64
        assert column.flags["C_CONTIGUOUS"]
        assert not column.flags["WRITEABLE"]
        assert column.shape == (len(r),)
    table = r.to_numpy()
    assert table.shape == (len(r), len(r.columns))
    assert table.dtype == np.float64 and table.flags["C_CONTIGUOUS"]
    assert np.array_equal(table[:, r.columns.index("q2")], r["q2"])
    with pytest.raises(KeyError, match="no column 'q9'"):
        r["q9"]


def test_to_pandas_or_a_clear_import_error():
    r = camchain.Model("paper_concave").simulate(t_end=0.1)
    try:
        import pandas as pd
    except ImportError:
        # pandas is not a dependency: without it, the error says what to install.
        with pytest.raises(ImportError, match="pip install pandas"):
            r.to_pandas()
        return
    frame = r.to_pandas()
    assert isinstance(frame, pd.DataFrame) and list(frame.columns) == r.columns
    assert np.array_equal(frame["q1"].to_numpy(), r["q1"])
