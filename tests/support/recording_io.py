"""Read and write recordings in the ftstack recording format (docs/spec/recording-format.md).

A small, independent reader for the Python test tools: `# key: value` metadata lines before the
header, one header line, comma-separated numbers. It refuses what the format refuses (missing
columns, numbers that do not parse, NaN/inf, t not increasing) with file and line.
"""

import math

import numpy as np


class Recording:
    """Metadata (dict), column names (list) and the numbers (rows x columns, float)."""

    def __init__(self, meta, names, data):
        self.meta = meta
        self.names = names
        self.data = data

    def has(self, name):
        return name in self.names

    def col(self, name):
        return self.data[:, self.names.index(name)]

    def bridges(self):
        """Names of the b0, b1, ... columns in index order."""
        out = []
        while f"b{len(out)}" in self.names:
            out.append(f"b{len(out)}")
        return out


def read_recording(path):
    meta = {}
    names = None
    rows = []
    with open(path, encoding="utf-8") as f:
        for line_no, line in enumerate(f, start=1):
            line = line.rstrip("\r\n")
            if names is None and line.startswith("#"):
                key, sep, value = line[1:].partition(":")
                if sep:
                    meta[key.strip()] = value.strip()
                continue
            if names is None:
                names = [c.strip() for c in line.split(",")]
                if "t" not in names:
                    raise ValueError(f"{path}:{line_no}: header has no 't' column")
                continue
            if not line.strip():
                continue
            fields = line.split(",")
            if len(fields) != len(names):
                raise ValueError(f"{path}:{line_no}: {len(fields)} fields, header has {len(names)}")
            row = []
            for col_no, field in enumerate(fields, start=1):
                try:
                    v = float(field)
                except ValueError:
                    raise ValueError(f"{path}:{line_no}:{col_no}: '{field}' is not a number") from None
                if not math.isfinite(v):
                    raise ValueError(f"{path}:{line_no}:{col_no}: '{field}' is not finite")
                row.append(v)
            rows.append(row)
    if names is None:
        raise ValueError(f"{path}: no header line")
    data = np.array(rows, dtype=float).reshape(len(rows), len(names))
    t = data[:, names.index("t")]
    bad = np.nonzero(np.diff(t) <= 0)[0]
    if len(bad):
        raise ValueError(f"{path}: t does not increase at data row {int(bad[0]) + 2}")
    return Recording(meta, names, data)


def write_recording(path, meta, columns):
    """columns: list of (name, values, format) in file order; meta: list of (key, value)."""
    n = len(columns[0][1])
    with open(path, "w", encoding="utf-8") as f:
        for key, value in meta:
            f.write(f"# {key}: {value}\n")
        f.write(",".join(name for name, _, _ in columns) + "\n")
        formats = [fmt for _, _, fmt in columns]
        values = [v for _, v, _ in columns]
        for i in range(n):
            f.write(",".join(fmt.format(v[i]) for fmt, v in zip(formats, values)) + "\n")
