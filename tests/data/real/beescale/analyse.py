#!/usr/bin/env python3
"""Independent analysis of the converted beescale log (written apart from diagnosis/).

Runs the generic survey (tests/support/recording_survey.py) on the rows it can trust, and adds:
- wrong readings: per scale, rows more than 1 kg from the record's median weight, grouped into
  episodes (consecutive such rows), with their times, lengths and values; temperature error codes
  (DS18B20 -127 C, and 0 C on both thermometers at once);
- simultaneous steps: both scales moving by more than 40 g between two rows;
- on the clean rows: the white noise (robust sigma of first differences / sqrt 2, in g), the value
  grid in g, the days logged on a coarser 10-g grid, the range of each day, and a least-squares fit weight = a + b*T_in + c*time (slope
  per K and per day, and each regressor's correlation with the weight), plus the correlation of
  T_in with time (time and temperature separable or not).

Usage: analyse.py CONVERTED.csv
"""

import os
import sys

import numpy as np

sys.dont_write_bytecode = True  # keep the source tree clean
HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "..", "..", "support"))
from recording_io import read_recording  # noqa: E402
from recording_survey import robust_sigma, runs, value_grid  # noqa: E402

G_PER_MVV = 1000.0 / 0.01  # the converter's nominal 0.01 mV/V per kg, inverted, in g


def episodes(mask, t_h):
    return [(float(t_h[i]), float(t_h[j]), j - i + 1) for i, j in runs(mask)]


def main():
    if len(sys.argv) != 2:
        print(__doc__)
        return 2
    rec = read_recording(sys.argv[1])
    t_h = rec.col("t") / 3600.0
    w = {name: rec.col(name) * G_PER_MVV for name in ("b0", "b1")}
    t_in, t_out = rec.col("temp_C"), rec.col("t_out_C")
    periods = np.diff(rec.col("t"))
    print(f"{len(t_h)} rows over {t_h[-1] / 24:.2f} days; period median {np.median(periods):.0f} s "
          f"(5-95 %: {np.percentile(periods, 5):.0f}-{np.percentile(periods, 95):.0f} s), "
          f"longest gap {np.max(periods) / 3600:.2f} h at {t_h[np.argmax(periods)]:.1f} h")
    bad = np.zeros(len(t_h), dtype=bool)
    for name, x in w.items():
        far = np.abs(x - np.median(x)) > 1000.0
        bad |= far
        print(f"  {name}: median {np.median(x):.0f} g; {far.sum()} rows > 1 kg off, episodes:")
        for a, b, n in episodes(far, t_h):
            vals = x[(t_h >= a) & (t_h <= b)]
            print(f"    {a:7.2f}-{b:7.2f} h, {n} rows, {np.min(vals):.0f}..{np.max(vals):.0f} g")
    temp_bad = (t_in <= -100) | ((t_in == 0) & (t_out == 0))
    print(f"  temperature error rows: {int(np.sum(t_in <= -100))} at -127 C, "
          f"{int(np.sum((t_in == 0) & (t_out == 0)))} with both at 0 C")
    bad |= temp_bad
    good = ~bad
    d0, d1 = np.diff(w["b0"]), np.diff(w["b1"])
    both = np.nonzero((np.abs(d0) > 40) & (np.abs(d1) > 40) & good[1:] & good[:-1])[0]
    print("  simultaneous steps > 40 g on both scales (h: g, g): "
          + ", ".join(f"{t_h[i + 1]:.2f}: {d0[i]:+.0f}, {d1[i]:+.0f}" for i in both))
    tt = t_h[good] / 24.0
    temp = t_in[good]
    print(f"  clean rows {good.sum()}; T_in {temp.min():.2f}..{temp.max():.2f} C, "
          f"T_out {t_out[good].min():.2f}..{t_out[good].max():.2f} C; corr(T_in, time) "
          f"{np.corrcoef(temp, tt)[0, 1]:+.3f}")
    for name, x in w.items():
        y = x[good]
        step, share = value_grid(y)
        noise = robust_sigma(np.diff(y)) / np.sqrt(2.0)
        design = np.column_stack([np.ones_like(tt), temp, tt])
        coef, *_ = np.linalg.lstsq(design, y, rcond=None)
        resid = y - design @ coef
        days = [np.ptp(y[(tt >= k) & (tt < k + 1)]) for k in range(int(tt.max()) + 1)
                if np.any((tt >= k) & (tt < k + 1))]
        tens = np.abs(y / 10.0 - np.round(y / 10.0)) < 1e-6
        coarse = [k for k in range(int(tt.max()) + 1)
                  if np.mean(tens[(tt >= k) & (tt < k + 1)] if np.any((tt >= k) & (tt < k + 1)) else 0) > 0.99]
        print(f"  {name}: days whose values all lie on a 10-g grid (from day 0): {coarse}")
        print(f"  {name}: noise {noise:.2f} g; grid {step:.3g} g ({100 * share:.0f} % on it); daily "
              f"range {np.min(days):.0f}-{np.max(days):.0f} g; fit {coef[1]:+.2f} g/K, "
              f"{coef[2]:+.2f} g/day, residual RMS {np.sqrt(np.mean(resid ** 2)):.1f} g; "
              f"corr with T_in {np.corrcoef(y, temp)[0, 1]:+.3f}, with time "
              f"{np.corrcoef(y, tt)[0, 1]:+.3f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
