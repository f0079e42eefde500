#!/usr/bin/env python3
"""The per-hold analysis recovers what the independent generator put in (its truth JSON).

This is what lets the figures hold_analysis.py reports on real recordings (docs/real-recordings.md)
be trusted: on data with a known ringing line, creep, glitches, noise and hand-applied load
changes, the same code finds them within the tolerances below.
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
from hold_analysis import analyse  # noqa: E402


class HoldAnalysisOnGenerator(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory()
        cls.cases = []
        for seed, rate in ((31, 10.0), (32, 25.0)):
            out = os.path.join(cls.tmp.name, f"g{seed}.csv")
            subprocess.run([sys.executable, os.path.join(HERE, "real_class_generator.py"), "--out", out,
                            "--seed", str(seed), "--duration-s", "900", "--rate-hz", str(rate),
                            "--channels", "2"], check=True, stdout=subprocess.DEVNULL)
            with open(os.path.splitext(out)[0] + ".json", encoding="utf-8") as f:
                truth = json.load(f)
            cls.cases.append((seed, truth, analyse(out)))

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def fits(self, result, name):
        return [h["channels"][name] for h in result["holds"] if name in h.get("channels", {})]

    def test_glitches_counted_are_the_true_ones(self):
        for seed, truth, result in self.cases:
            found = {(round(v, 3), name) for name, times in result["glitches"].items() for v in times}
            expected = {(round(g["t_s"], 3), f"b{g['channel']}") for g in truth["glitches"]}
            self.assertEqual(found, expected, f"seed {seed}")

    def test_ringing_frequency_and_q(self):
        for seed, truth, result in self.cases:
            ring = truth["ringing"]
            for name in result["channels"]:
                lines = [f for f in self.fits(result, name) if f["line"]]
                self.assertGreaterEqual(len(lines), 2, f"seed {seed} {name}")
                for f in lines:
                    self.assertLess(abs(f["line_freq_hz"] / ring["freq_hz"] - 1.0), 0.005, f"seed {seed} {name}")
                q = np.median([f["q"] for f in lines])
                self.assertLess(abs(q / ring["q"] - 1.0), 0.25, f"seed {seed} {name}: Q {q:.0f} vs {ring['q']:.0f}")

    def test_creep_time_constant_and_fraction(self):
        for seed, truth, result in self.cases:
            taus = truth["creep"]["tau_s"]
            for k, name in enumerate(result["channels"]):
                good = [f for f in self.fits(result, name)
                        if not f["tau_at_bound"] and f.get("creep_fraction") is not None]
                self.assertGreaterEqual(len(good), 2, f"seed {seed} {name}")
                tau = np.median([f["creep_tau_s"] for f in good])
                self.assertGreater(tau, 0.7 * taus[0], f"seed {seed} {name}")
                self.assertLess(tau, 1.3 * taus[-1], f"seed {seed} {name}")
                frac = np.median([f["creep_fraction"] for f in good])
                self.assertLess(abs(frac / truth["creep"]["fraction_total"][k] - 1.0), 0.5, f"seed {seed} {name}")

    def test_noise_in_the_quietest_hold(self):
        for seed, truth, result in self.cases:
            for k, name in enumerate(result["channels"]):
                quiet = min(f["noise_resid"] for f in self.fits(result, name))
                self.assertLess(abs(quiet / truth["noise_counts_rms"][k] - 1.0), 0.15, f"seed {seed} {name}")

    def test_application_times(self):
        for seed, truth, result in self.cases:
            sample = 1.0 / truth["rate_hz_actual"]
            self.assertEqual(len(result["transitions"]), len(truth["transitions"]))
            for est, tr in zip(result["transitions"], truth["transitions"]):
                self.assertIsNotNone(est)
                self.assertLessEqual(est["application_s"], tr["application_s"] + 2.0 * sample)
                self.assertGreaterEqual(est["application_s"], 0.5 * tr["application_s"] - 2.0 * sample)


if __name__ == "__main__":
    unittest.main()
