#!/usr/bin/env python3
"""Checks recording_survey.py against a record whose contents are known by construction.

A 100 Hz, 300-s record: Fz steps 0 -> 1000 N at 100 s, to 300 N at 200 s, to 0 at 250 s; b0 = 2e-6 mV/V per N,
white noise sigma 1e-4 mV/V, the 3rd harmonic of 60 Hz mains (180 Hz, folded to 20 Hz) of amplitude 1e-3 mV/V, a 7.3 Hz line of
5e-4, a drift of 1e-4 mV/V per minute, all rounded to a grid of 2e-5 mV/V; temp_C rising
monotonically; b1 = -1e-6 mV/V per N and the same noise only. Each figure the survey prints is compared with the construction.
"""

import os
import sys
import tempfile

import numpy as np

sys.dont_write_bytecode = True  # keep the source tree clean
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from recording_io import write_recording  # noqa: E402
from recording_survey import survey  # noqa: E402


def make(path, seed):
    rng = np.random.default_rng(seed)
    t = np.arange(0, 300.0, 0.01)
    fz = np.where((t >= 100) & (t < 200), 1000.0, np.where((t >= 200) & (t < 250), 300.0, 0.0))
    b0 = (2e-6 * fz + 1e-4 * rng.standard_normal(len(t)) + 1e-3 * np.sin(2 * np.pi * 180.0 * t + 0.3)
          + 5e-4 * np.sin(2 * np.pi * 7.3 * t) + 1e-4 * t / 60.0)
    b0 = np.round(b0 / 2e-5) * 2e-5
    b1 = np.round((-1e-6 * fz + 1e-4 * rng.standard_normal(len(t))) / 2e-5) * 2e-5
    zeros = np.zeros(len(t))
    temp = 20.0 + t / 300.0
    cols = [("t", t, "{:.2f}")] + [(n, fz if n == "Fz" else zeros, "{:g}")
                                  for n in ("Fx", "Fy", "Fz", "Mx", "My", "Mz")]
    cols += [("b0", b0, "{:.6g}"), ("b1", b1, "{:.6g}"), ("temp_C", temp, "{:.4f}")]
    write_recording(path, [("bridge_unit", "mV/V")], cols)


def check(cond, what, failures):
    print(("ok   " if cond else "FAIL ") + what)
    if not cond:
        failures.append(what)


def main():
    failures = []
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "rec.csv")
        make(path, 3)
        r = survey(path)
    b0 = r["channels"]["b0"]
    check(abs(r["rate_hz"] - 100.0) < 1e-6 and abs(r["duration_s"] - 299.99) < 1e-6, "rate and duration", failures)
    changes = r["reference"]["changes"]
    check(len(changes) == 3 and [int(c[0] > s - 3 and c[0] < s + 1) for c, s in zip(changes, (100, 200, 250))] == [1, 1, 1],
          f"three load changes near 100, 200 and 250 s: {[round(c[0], 1) for c in changes]}", failures)
    b1 = r["channels"]["b1"]
    # b1 is white noise of 1e-4 on a 2e-5 grid (rounding adds 2e-5/sqrt(12) in quadrature)
    expected = np.hypot(1e-4, 2e-5 / np.sqrt(12.0))
    check(abs(b1["noise_sigma"] / expected - 1) < 0.05 and not b1["lines"],
          f"noise {b1['noise_sigma']:.3g} vs {expected:.3g}, no line", failures)
    check(abs(b0["grid_step"] - 2e-5) < 1e-9 and b0["share_on_grid"] > 0.99, f"grid {b0['grid_step']:.3g}", failures)
    check(abs(b1["gain_per_ref"] + 1e-6) < 1e-8, f"gain of b1 {b1['gain_per_ref']:.4g}", failures)
    freqs = [ln["freq_hz"] for ln in b0["lines"]]
    near = lambda f: [ln for ln in b0["lines"] if abs(ln["freq_hz"] - f) < 0.1]  # noqa: E731
    check(len(near(20.0)) == 1 and abs(near(20.0)[0]["amplitude"] / 1e-3 - 1) < 0.15
          and any("180 Hz" in s for s in near(20.0)[0]["supply"]),
          f"folded 3x60 Hz line at 20 Hz named with its true frequency: {near(20.0)}", failures)
    check(len(near(7.3)) == 1 and abs(near(7.3)[0]["amplitude"] / 5e-4 - 1) < 0.15
          and not near(7.3)[0]["supply"], f"7.3 Hz line, no supply: lines {freqs}", failures)
    check(len(freqs) == 2, f"no other line: {freqs}", failures)
    check(r["temperature"]["rank_corr_with_time"] > 0.999, "temperature monotone in time", failures)
    print(f"{len(failures)} failure(s)")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
