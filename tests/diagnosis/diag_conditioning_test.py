#!/usr/bin/env python3
"""ftdiag's data conditioning against references it does not share code with.

- The independent generator (tests/support/real_class_generator.py, numpy, no ftstack code):
  every converter glitch of its truth is reported (row time and channel, nothing else), every
  transition the report excludes contains the truth's logged step, and the quiet noise lies within
  25 % of the truth's noise.
- The vendored real recording tests/data/real/cie324_swing (Ketter 133): the 12 wrong codes the
  independent hold analysis found (b0 x4, b1 x4, b3 x2, b4 x2), each a bit error, i.e. an offset
  within 2 % of 2^23 or 2^24 counts (a physical fact of the converter, not a figure of ftdiag).

Usage: diag_conditioning_test.py FTDIAG
"""

import os
import sys
import tempfile

sys.dont_write_bytecode = True
HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.join(ROOT, "tests", "support"))
from ftdiag_runs import diagnose, generate  # noqa: E402


def glitch_finding(report):
    found = [f for f in report.get("findings", []) if f["name"] == "converter_glitch"]
    return found[0] if found else None


def check_generator(ftdiag, work, seed, rate_hz, failures):
    real, truth = generate(work, seed, "--duration-s", "1200", "--rate-hz", str(rate_hz),
                           "--channels", "3")
    report = diagnose(ftdiag, real, work)[0]
    dt = 1.0 / truth["rate_hz_actual"]
    want = sorted((g["channel"], g["t_s"]) for g in truth["glitches"])
    finding = glitch_finding(report)
    got = sorted((g["channel"], g["t_s"]) for g in finding["glitches"]) if finding else []
    if len(got) != len(want) or any(a[0] != b[0] or abs(a[1] - b[1]) > 0.5 * dt
                                    for a, b in zip(got, want)):
        failures.append(f"seed {seed}: glitches {got} != truth {want}")
    steps = [t["t_ref_s"] for t in truth["transitions"]]
    excluded = [t for t in report["conditioning"]["transitions"]["list"] if t["excluded"]]
    if len(excluded) < len(steps) // 2:
        failures.append(f"seed {seed}: {len(excluded)} of {len(steps)} transitions excluded")
    for t in excluded:
        lo, hi = t["excluded_s"]
        if not any(lo - dt <= s <= hi + dt for s in steps):
            failures.append(f"seed {seed}: excluded {lo}-{hi} s holds no logged step")
    for ch in report["conditioning"]["noise_quiet"]["channels"]:
        true_counts = truth["noise_counts_rms"][ch["channel"]]
        got_counts = ch.get("sigma_in_unit", 0.0)
        if abs(got_counts / true_counts - 1.0) > 0.25:
            failures.append(f"seed {seed} b{ch['channel']}: quiet noise {got_counts:.4g} counts, "
                            f"truth {true_counts:.4g}")
    print(f"seed {seed} @ {rate_hz} Hz: {len(got)} glitches (truth {len(want)}), "
          f"{len(excluded)}/{len(steps)} transitions excluded")


def check_cie324(ftdiag, work, failures):
    real = os.path.join(ROOT, "tests", "data", "real", "cie324_swing", "ketter133_2024-02-14.csv")
    report = diagnose(ftdiag, real, work)[0]
    finding = glitch_finding(report)
    glitches = finding["glitches"] if finding else []
    per_channel = {}
    for g in glitches:
        per_channel[g["channel"]] = per_channel.get(g["channel"], 0) + 1
    if per_channel != {0: 4, 1: 4, 3: 2, 4: 2}:
        failures.append(f"cie324: glitches per channel {per_channel}")
    counts_per_mvv = 2 ** 23 / 3.90625  # 24-bit signed, gain 128, ratiometric (the file's header)
    for g in glitches:
        counts = abs(g["offset_mvv"]) * counts_per_mvv
        if min(abs(counts / 2 ** 23 - 1.0), abs(counts / 2 ** 24 - 1.0)) > 0.02:
            failures.append(f"cie324: glitch at {g['t_s']} s is {counts:.0f} counts, no bit error")
    print(f"cie324: {len(glitches)} glitches {per_channel}")


def main():
    ftdiag = sys.argv[1]
    failures = []
    with tempfile.TemporaryDirectory() as work:
        check_generator(ftdiag, work, 102, 10, failures)
        check_generator(ftdiag, work, 104, 25, failures)
        check_cie324(ftdiag, work, failures)
    for f in failures:
        print("FAIL:", f)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
