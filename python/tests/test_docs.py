"""The examples of docs/python.md run as written."""

import contextlib
import io
import re

import camchain


def blocks(repository):
    text = (repository / "docs" / "python.md").read_text()
    return re.findall(r"```python\n(.*?)```", text, flags=re.S)


def run(code):
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        exec(compile(code, "docs/python.md", "exec"), {})
    return out.getvalue()


def test_the_first_run_runs(repository):
    first = next(b for b in blocks(repository) if 'camchain.Model("paper_concave")' in b)
    printed = run(first)
    assert printed.startswith("paper_concave — generated code")


def test_the_jump_speed_study_finds_the_designers_jump_speed(repository):
    study = next(b for b in blocks(repository) if "jump speed" in b)
    printed = run(study)
    found = float(re.search(r"jump speed ≈ ([0-9.]+) rad/s", printed).group(1))
    # `camchain cam cycloidal_roller` predicts 64.5668531162 rad/s from N = A + Bω + Cω²
    # (checked against bisection on simulations in the Rust suite); the doc's linear
    # interpolation on a 2 rad/s grid lands within 0.05 rad/s of it.
    assert abs(found - 64.5668531162) < 0.05
    assert "lift_off" in printed and "impact" in printed
