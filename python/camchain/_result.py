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


class Sweep:
    """What `Model.sweep` computed: one row per run, the columns of `camchain sweep`'s CSV.

    - `s["omega"]`, `s["max_normal_force"]`: a column by name (`s.columns` lists them in the
      CSV's order): `run` (int64), the swept parameters and the metrics (float64, NaN where
      the CSV's cell is empty: no lift-off, a failed run), `status` (`ok` or `failed`) and
      `error` (the failed run's message, else empty) as arrays of strings;
    - `len(s)`: the runs completed (all of them, unless Ctrl-C stopped the sweep: then
      `s.planned` is larger and `run` tells which ones ran);
    - `s.to_numpy()`: the numeric columns, one row per run; `s.to_pandas()`: every column.
    """

    __slots__ = ("_data", "planned", "label")

    def __init__(self, columns, planned, label):
        data = {}
        for name, values in columns.items():
            array = np.asarray(values) if isinstance(values, list) else values
            if name in ("status", "error"):
                array = np.asarray(values, dtype=str)
            array.flags.writeable = False
            data[name] = array
        self._data = data
        self.planned = planned
        self.label = label

    @property
    def columns(self):
        """The column names, in the CSV's order."""
        return list(self._data)

    def __getitem__(self, name):
        try:
            return self._data[name]
        except KeyError:
            raise KeyError(
                f"no column {name!r}: the columns are {', '.join(self._data)}"
            ) from None

    def __contains__(self, name):
        return name in self._data

    def __len__(self):
        return len(self._data["run"])

    def to_numpy(self):
        """The numeric columns (all but `status` and `error`), one row per run: a new
        C-contiguous float64 (runs × columns) array."""
        numeric = [v for k, v in self._data.items() if k not in ("status", "error")]
        return np.ascontiguousarray(np.stack(numeric, axis=1).astype(np.float64))

    def to_pandas(self):
        """A `pandas.DataFrame` with every column (pandas must be installed)."""
        try:
            import pandas as pd
        except ImportError as e:
            raise ImportError("Sweep.to_pandas needs pandas: pip install pandas") from e
        return pd.DataFrame(dict(self._data))

    def __repr__(self):
        return f"<camchain.Sweep {self.label}: {len(self)} of {self.planned} runs, {len(self._data)} columns>"
