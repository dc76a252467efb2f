"""basalt-run's field series (fields.csv: the [[output.fields]] savers, docs/io-ranks.md) as numpy arrays.

The file: a header ``step,time,<one column per saver>``, then one row per saved step; an empty cell is a saver
not due on that row; a value may be ``nan``, ``inf`` or ``-inf``. Read with the rules of basalt-view's
reader and its messages (``fields.csv: line 7: column "kinetic_energy": "1.2.3" is not a number``).
"""

import math
import os

import numpy as np

from ._errors import FormatError


def _number(text):
    """A cell as basalt-run writes it (shortest round-trip decimal, nan, inf, -inf); None when it is not one.
    Python's float() would also take "1_000" and surrounding spaces; those are not fields.csv's."""
    if not text or "_" in text or text != text.strip():
        return None
    try:
        return float(text)
    except ValueError:
        return None


def read_fields(path, as_pandas=False):
    """Reads a field series: a fields.csv, or a run's output folder holding one.

    Returns a numpy record array, one record per row: "step" (int64), "time" (float64) and one float64 column
    per saver, by its name (f["kinetic_energy"] or f.kinetic_energy); an empty cell (the saver was not due at
    that step) is nan. With as_pandas=True, a pandas DataFrame of the same columns (ImportError when pandas is
    not installed: Debian's python3-pandas). A malformed file raises basalt.FormatError naming the file and
    the line. A file with a header and no rows yet (a run that just started) gives zero records."""
    path = os.fspath(path)
    if os.path.isdir(path):
        path = os.path.join(path, "fields.csv")
    if as_pandas:
        try:
            import pandas
        except ImportError as e:
            raise ImportError("read_fields(as_pandas=True) needs pandas, which is not installed (Debian: "
                              "apt-get install python3-pandas); without as_pandas it returns a numpy record "
                              "array") from e
    if not os.path.isfile(path):
        raise FormatError.at(path, "", "no such file")
    names = None
    steps, rows = [], []
    with open(path, newline="") as f:
        for number, line in enumerate(f, start=1):
            line = line.rstrip("\n").rstrip("\r")
            if not line.strip(" \t"):
                continue  # blank lines
            where = f"line {number}"
            cells = [c.strip(" \t") for c in line.split(",")]
            if names is None:
                if len(cells) < 2 or cells[0] != "step" or cells[1] != "time":
                    raise FormatError.at(path, where, f'header must be "step,time,<field>...", found "{line}"')
                if any(not c for c in cells):
                    raise FormatError.at(path, where, "empty column name in header")
                if len(set(cells)) != len(cells):
                    dup = next(c for c in cells if cells.count(c) > 1)
                    raise FormatError.at(path, where, f'column "{dup}" named twice in header')
                names = cells
                continue
            if len(cells) != len(names):
                raise FormatError.at(path, where,
                                     f"{len(cells)} values, expected {len(names)} ({','.join(names)})")
            values = []
            for i, c in enumerate(cells):
                if not c and i >= 2:  # a saver not due on this row
                    values.append(math.nan)
                    continue
                v = _number(c)
                # step: a whole number; time: not nan (as basalt-view's reader)
                if v is None or (i == 0 and not (math.isfinite(v) and v == int(v))) or (i == 1 and math.isnan(v)):
                    raise FormatError.at(path, where, f'column "{names[i]}": "{c}" is not a number')
                values.append(v)
            steps.append(int(values[0]))
            rows.append(tuple(values[1:]))
    if names is None:
        raise FormatError.at(path, "line 1", 'empty file: expected a header "step,time,..."')
    dtype = [("step", np.int64)] + [(n, np.float64) for n in names[1:]]
    out = np.empty(len(rows), dtype=dtype)
    if rows:
        out["step"] = steps
        table = np.array(rows, dtype=np.float64).reshape(len(rows), len(names) - 1)
        for k, n in enumerate(names[1:]):
            out[n] = table[:, k]
    out = out.view(np.recarray)
    if as_pandas:
        return pandas.DataFrame({n: out[n] for n in names})
    return out
