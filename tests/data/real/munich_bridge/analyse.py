#!/usr/bin/env python3
"""Independent analysis of a converted Munich test-bridge load test (written apart from diagnosis/).

Runs the generic survey (tests/support/recording_survey.py), then the holds of the support load:
stretches of at least 20 s where the 2-s means of Fz move by less than 0.5 kN from one to the
next. Per hold: the mean load, the direction it was reached from (from below / above), the
strain b0 in um/m (mean, the slope within the hold and the 2-s means' spread) and the summed
support force's own slope, so that load-path dependence (the same load read differently after
loading and after unloading) and drift within holds can be told apart.

Usage: analyse.py CONVERTED.csv [--json OUT.json]
"""

import argparse
import json
import os
import sys

import numpy as np

sys.dont_write_bytecode = True  # keep the source tree clean
HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "..", "..", "support"))
from recording_io import read_recording  # noqa: E402
from recording_survey import print_report, runs, survey  # noqa: E402

UM_M_PER_MVV = 1.0 / 0.5e-3  # the converter's nominal quarter-bridge scale, inverted
BLOCK_S = 2.0


def holds(t, force_n, strain_um_m):
    rate = 1.0 / float(np.median(np.diff(t)))
    per = int(round(BLOCK_S * rate))
    n = len(t) // per
    fm = force_n[: n * per].reshape(n, per).mean(axis=1)
    steady = np.abs(np.diff(fm)) < 500.0
    out = []
    for i, j in runs(steady):
        if (j - i + 2) * BLOCK_S >= 20.0:
            rows = slice(i * per, (j + 2) * per)
            tt = t[rows]
            eps = strain_um_m[rows]
            f = force_n[rows]
            before = fm[i - 3] if i >= 3 else np.nan
            came = "start" if np.isnan(before) else ("below" if before < fm[i] else "above")
            block_means = eps[: (len(eps) // per) * per].reshape(-1, per).mean(axis=1)
            out.append({"t0_s": float(tt[0]), "t1_s": float(tt[-1]), "load_kn": float(np.mean(f)) / 1e3,
                        "from": came, "strain_um_m": float(np.mean(eps)),
                        "strain_slope_um_m_per_min": float(np.polyfit(tt / 60.0, eps, 1)[0]),
                        "strain_2s_spread_um_m": float(np.ptp(block_means)),
                        "load_slope_kn_per_min": float(np.polyfit(tt / 60.0, f, 1)[0]) / 1e3})
    return out


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("recording")
    parser.add_argument("--json")
    args = parser.parse_args()
    report = survey(args.recording, "Fz")
    print_report(report)
    rec = read_recording(args.recording)
    report["holds"] = holds(rec.col("t"), rec.col("Fz"), rec.col("b0") * UM_M_PER_MVV)
    print("  holds (strain in um/m, nominal scale):")
    for h in report["holds"]:
        print(f"    {h['t0_s']:6.1f}-{h['t1_s']:6.1f} s  {h['load_kn']:7.2f} kN from {h['from']:5s}"
              f"  strain {h['strain_um_m']:6.2f} (slope {h['strain_slope_um_m_per_min']:+.3f}/min, "
              f"2-s spread {h['strain_2s_spread_um_m']:.2f})  load slope "
              f"{h['load_slope_kn_per_min']:+.3f} kN/min")
    if args.json:
        with open(args.json, "w", encoding="utf-8") as f:
            json.dump(report, f, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
