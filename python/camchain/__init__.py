"""camchain: cam mechanisms and multibody chains in contact with cams, simulated fast and
exactly.

    >>> import camchain
    >>> m = camchain.Model("paper_concave")          # generated code, compiled in
    >>> r = m.simulate(t_end=1.0)
    >>> r["q1"][-1], r.summary["energy_drift"]

`camchain.models()` lists the built-in models; `camchain.Model.from_file("my.ron")` runs a
model file on the numeric recursive reference with no compilation. See docs/python.md.
"""

from ._camchain import Model, compile, models, __version__
from ._errors import CamchainError, ModelError, SimulationError
from ._result import Result, Sweep

__all__ = [
    "Model",
    "Result",
    "Sweep",
    "compile",
    "models",
    "CamchainError",
    "ModelError",
    "SimulationError",
    "__version__",
]
