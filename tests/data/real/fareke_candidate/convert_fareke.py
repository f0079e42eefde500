#!/usr/bin/env python3
"""Convert the FARE-KE beam load-cell loading test (NOT vendored: no licence) for local analysis.

The recording `Calibration scripts/Comparison Beam load cells/loadingTest - connection 0 - UART
COM3.csv` of https://github.com/telenaco/FARE-KE (commit 675f97cbb66e3bddd849b2093c1fefce74e2e4cb)
has no licence, so it is not part of this repository; fetch it yourself and run
    convert_fareke.py LOADINGTEST.csv OUT.csv
Columns of the original: sample number, UNIX time (ms), micros, then three load cells
(CZL635, Degraw, TAL220) in raw codes. One unknown weight was hung and removed repeatedly; the
reference written here is Fz = 1 while it hangs, 0 otherwise (in units of that weight, not N),
from a hysteresis threshold on the glitch-free first cell, the step placed at the half-way crossing.
The converter is declared as a 24-bit signed code at gain 128 (an assumption: the repository does
not state the converter of this test).
"""

import os
import sys

import numpy as np

sys.dont_write_bytecode = True  # keep the source tree clean
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "..", "support"))
from recording_io import write_recording  # noqa: E402
from signal_tools import isolated_codes, robust_sigma  # noqa: E402


def main():
    if len(sys.argv) != 3:
        print(__doc__)
        return 2
    raw = np.genfromtxt(sys.argv[1], delimiter=",", skip_header=1)
    t = (raw[:, 1] - raw[0, 1]) / 1000.0
    codes = raw[:, 3:6]
    x = codes[:, 0].copy()
    idx = isolated_codes(x, 50.0 * robust_sigma(np.diff(x)))
    x[idx] = 0.5 * (x[idx - 1] + x[idx + 1])
    lo, hi = np.percentile(x, [5, 95])
    p = (x - hi) / (lo - hi)   # 0 unloaded, 1 loaded (the load lowers this cell's code)
    state = np.zeros(len(x), dtype=int)
    level, last = 0, 0
    for i, v in enumerate(p):
        target = 1 if v > 0.9 else 0 if v < 0.1 else level
        if target != level:
            seg = p[last:i + 1]
            cross = np.nonzero((seg > 0.5) != (seg[0] > 0.5))[0]
            start = last + (int(cross[0]) if len(cross) else i - last)
            state[start:] = target
            level = target
        if (v > 0.9) == bool(level) and (v < 0.1) != bool(level):
            last = i
    zeros = np.zeros(len(t))
    columns = [("t", t, "{:.3f}")] + [(n, state.astype(float) if n == "Fz" else zeros, "{:g}")
                                      for n in ("Fx", "Fy", "Fz", "Mx", "My", "Mz")]
    columns += [(f"b{k}", codes[:, k], "{:.0f}") for k in range(3)]
    meta = [("source", "https://github.com/telenaco/FARE-KE commit 675f97cbb66e3bddd849b2093c1fefce74e2e4cb "
             "(no licence: not redistributed)"),
            ("converter", "bits=24, coding=signed, gain=128, ratiometric=yes"),
            ("reference", "Fz = 1 while the weight hangs (unit: that weight), reconstructed from b0")]
    write_recording(sys.argv[2], meta, columns)
    changes = int(np.count_nonzero(np.diff(state)))
    print(f"wrote {sys.argv[2]}: {len(t)} rows, {t[-1]:.0f} s, {changes} load changes, {len(idx)} glitches on b0")
    return 0


if __name__ == "__main__":
    sys.exit(main())
