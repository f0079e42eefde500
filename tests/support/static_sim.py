#!/usr/bin/env python3
"""Build the "simulation" a load-cell user has: a static linear model per cell.

For every bridge column b_k of a real recording, fit b_k = g_k * F + c_k by least squares against
the reference force column (default Fz), over all rows, then once more without the rows whose
residual exceeds 20 times the median absolute residual (isolated converter glitches would
otherwise pull the line). Writes a recording with the same metadata, t and wrench, whose b columns
are the model's predictions, and prints the fitted gains and offsets.

Usage: static_sim.py REAL.csv SIM.csv [--force Fz]
"""

import argparse
import os
import sys

import numpy as np

sys.dont_write_bytecode = True  # keep the source tree clean
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from recording_io import read_recording, write_recording  # noqa: E402


def fit_line(x, y):
    design = np.column_stack([x, np.ones_like(x)])
    coef = np.linalg.lstsq(design, y, rcond=None)[0]
    resid = y - design @ coef
    scale = np.median(np.abs(resid))
    keep = np.abs(resid) <= 20.0 * max(scale, 1e-12)
    coef = np.linalg.lstsq(design[keep], y[keep], rcond=None)[0]
    return coef, int((~keep).sum())


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("real")
    parser.add_argument("sim")
    parser.add_argument("--force", default="Fz", help="reference column the cells respond to")
    args = parser.parse_args()
    rec = read_recording(args.real)
    force = rec.col(args.force)
    columns = []
    for name in rec.names:
        values = rec.col(name)
        if name.startswith("b") and name[1:].isdigit():
            (gain, offset), dropped = fit_line(force, values)
            print(f"{name}: gain {gain:.6g} per unit of {args.force}, offset {offset:.6g}, "
                  f"{dropped} rows left out of the refit")
            columns.append((name, gain * force + offset, "{:.3f}"))
        elif name in ("t", "Fx", "Fy", "Fz", "Mx", "My", "Mz"):
            columns.append((name, values, "{:.6f}" if name == "t" else "{:.6g}"))
    meta = list(rec.meta.items()) + [("simulation", f"static linear model per cell in {args.force} "
                                      "(tests/support/static_sim.py)")]
    write_recording(args.sim, meta, columns)
    return 0


if __name__ == "__main__":
    sys.exit(main())
