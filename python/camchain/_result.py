"""The result of a run: its columns as float64 numpy arrays, its events and its summary."""

import numpy as np


class Result:
    """What `Model.simulate` computed.

    - `r.t`, `r["q1"]`, `r["A_normal_force"]`: one column of the command line's CSV by name
      (`r.columns` lists them, in the CSV's order), a read-only float64 C-contiguous array
      that shares the run's memory;
    - `r.to_numpy()`: every column, one row per sample (a copy, samples × columns);
    - `r.to_pandas()`: a `pandas.DataFrame` of the same (when pandas is installed);
    - `r.events`: lift-offs, impacts (with their speed, rebound and loss), sign changes of a
      bilateral contact's normal force, re-partitions, each a dict with its time `t` and
      `kind`, in the order the runtime met them (re-partitions, found between samples, after);
    - `r.summary`: the command line's summary, its `text` and its numbers.
    """

    __slots__ = ("_columns", "_index", "_data", "events", "summary", "label")

    def __init__(self, columns, data, events, summary, label):
        data.flags.writeable = False
        self._columns = tuple(columns)
        self._index = {name: k for k, name in enumerate(columns)}
        self._data = data
        self.events = events
        self.summary = summary
        self.label = label

    @property
    def columns(self):
        """The column names, in the CSV's order."""
        return list(self._columns)

    @property
    def t(self):
        """The output times (s)."""
        return self._data[0]

    def __getitem__(self, name):
        try:
            return self._data[self._index[name]]
        except KeyError:
            raise KeyError(
                f"no column {name!r}: the columns are {', '.join(self._columns)}"
            ) from None

    def __contains__(self, name):
        return name in self._index

    def __len__(self):
        return self._data.shape[1]

    def to_numpy(self):
        """Every column, one row per sample: a new C-contiguous (samples × columns) array."""
        return np.ascontiguousarray(self._data.T)

    def to_pandas(self):
        """A `pandas.DataFrame` with the CSV's columns (pandas must be installed)."""
        try:
            import pandas as pd
        except ImportError as e:
            raise ImportError("Result.to_pandas needs pandas: pip install pandas") from e
        return pd.DataFrame({name: self._data[k] for k, name in enumerate(self._columns)})

    def __repr__(self):
        span = f"t = {self.t[0]} to {self.t[-1]} s" if len(self) else "no samples"
        return f"<camchain.Result {self.label}: {len(self)} samples, {span}, {len(self._columns)} columns>"
