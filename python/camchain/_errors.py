"""The package's exceptions.

`CamchainError` (a `RuntimeError`) is the base of camchain's own errors. `ModelError` is a
problem in a model file or in a value given for one of its fields; it is also a
`ValueError`, and carries where it is: `file`, `line` and `column` (1-based, 0 when
unknown), `field` (`bodies[2].mass`) and `message`. `SimulationError` is a run that failed:
`time` (s, or None) where it stopped and `result`, what it computed until then.
"""

from ._camchain import CamchainError, SimulationError


class ModelError(CamchainError, ValueError):
    """A problem in a model file or a value for one of its fields, located like the
    build's errors: `str(e)` is `file:line:column: field: message`."""

    def __init__(self, text, file, line, column, field, message):
        super().__init__(text)
        self.file = file
        self.line = line
        self.column = column
        self.field = field
        self.message = message


__all__ = ["CamchainError", "ModelError", "SimulationError"]
