#!/usr/bin/env python3
"""Checks the hanging-weight generator against its own truth, by analysis of the data alone.

Every check estimates a property from the written recording with a method that does not share
the generator's formulas (a least-squares periodogram, a neighbour test for isolated codes,
robust statistics of first differences, level crossings) and compares it with the truth JSON.
"""

import json
import os
import subprocess
import sys
import tempfile
import unittest

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.dont_write_bytecode = True  # keep the source tree clean
sys.path.insert(0, HERE)
from recording_io import read_recording  # noqa: E402
from signal_tools import isolated_codes, ls_periodogram, moving_average  # noqa: E402

GENERATOR = os.path.join(HERE, "real_class_generator.py")


def generate(workdir, name, *args):
    out = os.path.join(workdir, name + ".csv")
    subprocess.run([sys.executable, GENERATOR, "--out", out, *args], check=True,
                   stdout=subprocess.DEVNULL)
    with open(os.path.join(workdir, name + ".json"), encoding="utf-8") as f:
        truth = json.load(f)
    return read_recording(out), truth


class GeneratorTruth(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory()
        cls.runs = {seed: generate(cls.tmp.name, f"all_{seed}", "--seed", str(seed),
                                   "--duration-s", "900", "--rate-hz", str(rate), "--channels", "3")
                    for seed, rate in ((11, 10.0), (12, 10.0), (13, 40.0))}

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def test_recording_is_hx711_codes_at_the_stated_rate(self):
        for seed, (rec, truth) in self.runs.items():
            self.assertEqual(rec.meta["converter"], "bits=24, coding=signed, gain=128, ratiometric=yes")
            codes = rec.data[:, [rec.names.index(b) for b in rec.bridges()]]
            self.assertEqual(codes.shape[1], truth["channels"])
            self.assertTrue(np.all(codes == np.round(codes)), f"seed {seed}: non-integer codes")
            self.assertTrue(np.all((codes >= -2 ** 23) & (codes < 2 ** 23)))
            t = rec.col("t")
            rate = (len(t) - 1) / (t[-1] - t[0])   # time stamps are rounded to 1 ms
            self.assertAlmostEqual(rate, truth["rate_hz_actual"], delta=0.005 * truth["rate_hz_actual"])

    def test_glitches_are_exactly_where_the_truth_says(self):
        for seed, (rec, truth) in self.runs.items():
            found = set()
            for k, name in enumerate(rec.bridges()):
                for i in isolated_codes(rec.col(name), 1e5):
                    found.add((int(i), k))
            expected = {(g["index"], g["channel"]) for g in truth["glitches"]}
            self.assertGreater(len(expected), 0)
            self.assertEqual(found, expected, f"seed {seed}")
            for g in truth["glitches"]:
                self.assertAlmostEqual(rec.col("t")[g["index"]], g["t_s"], delta=1e-9)
                self.assertGreaterEqual(abs(g["delta_counts"]), 2 ** 17)

    def test_ringing_line_in_quiet_holds_is_at_the_truth_frequency(self):
        for seed, (rec, truth) in self.runs.items():
            f_true = truth["ringing"]["freq_hz"]
            rate = truth["rate_hz_actual"]
            t = rec.col("t")
            coarse = np.linspace(0.2, 0.45 * rate, 1200)
            prominent = []
            for hold in truth["holds"]:
                rows = np.nonzero((t > hold["start_s"] + 2.0)
                                  & (t < min(hold["end_s"], hold["start_s"] + 122.0)))[0]
                if len(rows) < 40 * rate:
                    continue
                for k, name in enumerate(rec.bridges()):
                    x = rec.col(name)[rows].copy()
                    for i in isolated_codes(x, 1e5):
                        x[i] = 0.5 * (x[i - 1] + x[i + 1])
                    x -= moving_average(x, int(round(10.0 * rate)))   # creep and zero out
                    power = ls_periodogram(t[rows], x, coarse)
                    peak = int(np.argmax(power))
                    if power[peak] > 30.0 * np.median(power):
                        step = coarse[1] - coarse[0]
                        fine = np.linspace(coarse[peak] - step, coarse[peak] + step, 201)
                        f_peak = fine[int(np.argmax(ls_periodogram(t[rows], x, fine)))]
                        prominent.append((f_peak, hold["start_s"], k))
            self.assertGreater(len(prominent), 0, f"seed {seed}: no ringing line stands out")
            for f_found, start, k in prominent:
                self.assertLess(abs(f_found - f_true) / f_true, 0.02,
                                f"seed {seed}: hold at {start:.0f} s, b{k}: {f_found:.4f} Hz vs {f_true:.4f}")

    def test_noise_from_first_differences_matches_the_truth(self):
        rec, truth = generate(self.tmp.name, "noise_only", "--seed", "21", "--duration-s", "300",
                              "--effects", "noise")
        for k, name in enumerate(rec.bridges()):
            d = np.diff(rec.col(name))
            sigma = 1.4826 * np.median(np.abs(d - np.median(d))) / np.sqrt(2.0)
            # Rows inside a load change are few; the robust estimate ignores them.
            self.assertLess(abs(sigma / truth["noise_counts_rms"][k] - 1.0), 0.1, name)

    def test_load_changes_fall_inside_the_stated_transition_windows(self):
        rec, truth = generate(self.tmp.name, "clean", "--seed", "22", "--duration-s", "900",
                              "--effects", "")
        t = rec.col("t")
        self.assertTrue(np.all(truth["noise_counts_rms"] == np.zeros(truth["channels"])))
        for k, name in enumerate(rec.bridges()):
            x = rec.col(name)
            for tr in truth["transitions"]:
                before = x[np.searchsorted(t, tr["application_start_s"]) - 1]
                after = x[min(np.searchsorted(t, tr["application_end_s"]) + 1, len(x) - 1)]
                step = tr["load_after_n"] - tr["load_before_n"]
                self.assertAlmostEqual((after - before) / step, truth["sensitivity_counts_per_n"][k],
                                       delta=2.0 / abs(step) + 1e-9)
                half = 0.5 * (before + after)
                crossing = t[np.nonzero(np.sign(x - half) != np.sign(before - half))[0]]
                crossing = crossing[crossing >= tr["application_start_s"] - 1.0]
                self.assertGreaterEqual(crossing[0], tr["application_start_s"])
                self.assertLessEqual(crossing[0], tr["application_end_s"])
                # The logged reference step lies inside the application window too.
                fz = rec.col("Fz")
                i_ref = np.nonzero(np.diff(fz) != 0)[0] + 1
                t_steps = t[i_ref]
                nearest = t_steps[np.argmin(np.abs(t_steps - tr["t_ref_s"]))]
                self.assertGreaterEqual(nearest, tr["application_start_s"] - 0.01)
                self.assertLessEqual(nearest, tr["application_end_s"] + 0.11)

    def test_unknown_effect_is_refused(self):
        out = os.path.join(self.tmp.name, "bad.csv")
        run = subprocess.run([sys.executable, GENERATOR, "--out", out, "--effects", "ringing,wobble"],
                             capture_output=True, text=True)
        self.assertNotEqual(run.returncode, 0)
        self.assertIn("wobble", run.stderr)
        self.assertFalse(os.path.exists(out))


if __name__ == "__main__":
    unittest.main()
