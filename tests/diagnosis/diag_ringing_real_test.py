#!/usr/bin/env python3
"""ftdiag on hanging-weight recordings: ringing, creep and held-out gain against independent references.

References ftdiag shares no code with:
- the independent generator (tests/support/real_class_generator.py, numpy only): its truth JSON
  gives the pendulum's frequency (excited at every load change with a random phase) and the creep
  time constants;
- the per-hold least-squares fits of tests/support/hold_analysis.py (numpy only) on every file:
  the line frequency per hold and the creep tau per hold.

Asserted on every generator seed (106: fifteen load changes in 30 min, one in most spectral
segments; 105, 117 and 123 were missed by a diagnosis that claimed two effects at most, or whose
creep search bent τ to a gain the user's static model had taken): the claims are the truth's
classes (resonance, creep, zero_drift where it shifted the zero), no other; the strongest line of the report's residual spectrum within 2 % of the per-hold fits'
median line, `resonance` claimed within 5 % of the true frequency, any creep
claimed has its tau inside the per-hold fits' range (widened by 50 %: a hold fits one exponential
to two) and every fraction below 2 %, the held-out RMS lowered by at least 30 % (issue 26's bar
for a real recording of the class), no claim "not resolved" and no
fit claimed at a search bound. Where `zero_drift` is claimed as "steps at load changes", its level
per stretch is compared with the generator's true zero (the sum of the zero shifts it applied up to
that stretch): both projected off [1, reference load] across the stretches (the user's static line
takes that part), on the channel with the largest true shifts the two correlate by r >= 0.85 and
differ by under half the truth's RMS, and on every channel r > 0.3 (a stretch's mean also holds the
creep, whose mean depends on the hold's length). On the vendored real recordings (tests/data/real/cie324_swing) the
same holds where the file allows it: no claim at a bound, held-out RMS not raised, creep (if
claimed) as above; the ringing is not asserted there (Ketter 133's holds of 7-65 s are too short
for its line to be a resolved per-change ringing; SEESL shows no line), which is printed. The time
each diagnosis takes is printed, not asserted (performance lives in bench/).

Usage: diag_ringing_real_test.py FTDIAG [--seeds S1,S2,...]
(--seeds: a subset of the generator seeds; the sanitizer stage runs two, the checks unchanged.)
"""

import os
import sys
import tempfile

import numpy as np

sys.dont_write_bytecode = True
HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
REAL = os.path.join(ROOT, "tests", "data", "real", "cie324_swing")
sys.path.insert(0, os.path.join(ROOT, "tests", "support"))
from ftdiag_runs import diagnose, generate  # noqa: E402
from hold_analysis import analyse  # noqa: E402


def per_hold_fits(path):
    """Every hold's and channel's fit of the independent per-hold analysis."""
    return [fit for hold in analyse(path)["holds"] for fit in hold.get("channels", {}).values()]


def per_hold_taus(fits):
    """Creep tau of every hold and channel the independent per-hold fits resolved."""
    return [fit["creep_tau_s"] for fit in fits
            if not fit["tau_at_bound"] and fit.get("creep_fraction") is not None]


def per_hold_line_hz(fits):
    """Median frequency of the ringing lines the per-hold fits found (None without any)."""
    lines = [fit["line_freq_hz"] for fit in fits if fit.get("line")]
    return float(np.median(lines)) if lines else None


def value(v):
    return v.get("value", v) if isinstance(v, dict) else v


def check_common(name, report, taus, failures):
    h = report["holdout"]
    if h["rms_after"] > h["rms_before"]:
        failures.append(f"{name}: held-out RMS raised {h['rms_before']:.4g} -> {h['rms_after']:.4g}")
    for eff in report["effects"]:
        if eff.get("not_resolved"):
            failures.append(f"{name}: {eff['name']} claimed but not resolved: {eff['not_resolved']}")
        if eff["name"] != "creep":
            continue
        params = eff["params"]
        tau_keys = [k for k in ("tau_s", "tau1_s", "tau2_s") if k in params]
        for k in tau_keys:
            tau = value(params[k])
            if not taus or not (min(taus) / 1.5 <= tau <= 1.5 * max(taus)):
                failures.append(f"{name}: creep {k} = {tau:.3g} s outside the per-hold fits' "
                                f"{min(taus, default=0):.3g}-{max(taus, default=0):.3g} s")
        for k in ("fraction", "fraction1", "fraction2"):
            for f in params.get(k, []) if isinstance(params.get(k), list) else []:
                if abs(value(f)) >= 0.02:
                    failures.append(f"{name}: creep {k} {value(f):.3g} is 2 % or more of the load")


def zero_shift_agreement(truth, report):
    """Per channel (r, rms error, truth rms) of the claimed zero steps against the true zero."""
    steps = [e for e in report["effects"]
             if e["name"] == "zero_drift" and e.get("model") == "steps at load changes"]
    if not steps:
        return None
    levels = np.array(steps[0]["params"]["levels_mvv"]).T  # stretch x channel
    starts = np.array(steps[0]["params"]["level_from_s"])
    mids = np.append(0.5 * (starts[:-1] + starts[1:]), starts[-1] + 1.0)
    zero = np.zeros_like(levels)
    load = np.zeros(len(mids))
    for tr in truth["transitions"]:
        if tr.get("zero_shift_counts"):
            zero[mids > tr["settled_s"]] += np.array(tr["zero_shift_counts"]) * truth["mvv_per_count"]
        load[mids > tr["t_ref_s"]] = tr["load_after_n"]
    design = np.column_stack([np.ones(len(mids)), load])
    off = np.eye(len(mids)) - design @ np.linalg.pinv(design)
    want, got = off @ zero, off @ levels
    return [(float(np.corrcoef(want[:, c], got[:, c])[0, 1]),
             float(np.sqrt(np.mean((got[:, c] - want[:, c]) ** 2))),
             float(np.sqrt(np.mean(want[:, c] ** 2)))) for c in range(levels.shape[1])]


def check_zero_shifts(seed, truth, report, failures):
    agreement = zero_shift_agreement(truth, report)
    if agreement is None:
        print(f"generator seed {seed}: no zero steps claimed")
        return
    print(f"generator seed {seed}: zero steps vs truth (r, rms error, truth rms mV/V): "
          + "; ".join(f"({r:.2f}, {e:.2g}, {t:.2g})" for r, e, t in agreement))
    r, err, rms = max(agreement, key=lambda a: a[2])
    if r < 0.85 or err > 0.5 * rms:
        failures.append(f"seed {seed}: zero steps on the largest-shift channel r {r:.2f}, "
                        f"error {err:.2g} vs truth rms {rms:.2g}")
    if min(a[0] for a in agreement) <= 0.3:
        failures.append(f"seed {seed}: zero steps uncorrelated with the truth on a channel")


def check_generator(ftdiag, work, seed, failures):
    real, truth = generate(work, seed)
    report, elapsed = diagnose(ftdiag, real, work)
    f_true = truth["ringing"]["freq_hz"]
    ring = [e for e in report["effects"] if e["name"] == "resonance"]
    f_got = value(ring[0]["params"]["freq_hz"]) if ring else None
    h = report["holdout"]
    gain = 1.0 - h["rms_after"] / h["rms_before"]
    print(f"generator seed {seed}: verdict {report['verdict']}, ringing {f_got} Hz (truth "
          f"{f_true:.4f}), held-out {100 * gain:.1f} % lower, {elapsed:.1f} s")
    if f_got is None or abs(f_got / f_true - 1.0) > 0.05:
        failures.append(f"seed {seed}: resonance {f_got} not within 5 % of {f_true:.4f} Hz")
    if gain < 0.30:
        failures.append(f"seed {seed}: held-out RMS lowered by {100 * gain:.1f} %, not 30 %")
    fits = per_hold_fits(real)
    # The line the holds ring at must lead the engine's residual spectrum, whose lines seed the
    # ringing searches (the load changes' misfit, kept out of the fits, must not bury it there).
    line_hz = per_hold_line_hz(fits)
    peaks = report["mismatch"].get("spectral_peaks_hz", [])
    print(f"generator seed {seed}: per-hold line {line_hz} Hz, residual spectrum's lines {peaks[:3]}")
    if line_hz is not None and (not peaks or abs(peaks[0] / line_hz - 1.0) > 0.02):
        failures.append(f"seed {seed}: strongest residual line {peaks[:1]} Hz is not the holds' "
                        f"ringing at {line_hz:.4f} Hz")
    check_common(f"seed {seed}", report, per_hold_taus(fits), failures)
    check_zero_shifts(seed, truth, report, failures)
    # The same kind of statement as the truth: its ringing, creep and zero shifts, each under its
    # own name, and no physics the generator did not put in.
    claimed = {e["name"] for e in report["effects"]}
    want = {"resonance"} | ({"creep"} if truth.get("creep") else set()) | (
        {"zero_drift"} if any(tr.get("zero_shift_counts") for tr in truth["transitions"]) else set())
    if claimed != want:
        failures.append(f"seed {seed}: claims {sorted(claimed)}, the truth holds {sorted(want)}")


def check_real(ftdiag, work, file, failures):
    real = os.path.join(REAL, file)
    report, elapsed = diagnose(ftdiag, real, work)
    h = report["holdout"]
    ring = [e for e in report["effects"] if e["name"] == "resonance"]
    print(f"{file}: verdict {report['verdict']}, claims {[e['name'] for e in report['effects']]}, "
          f"ringing {'claimed' if ring else 'not claimed'}, held-out "
          f"{100 * (1 - h['rms_after'] / h['rms_before']):.1f} % lower, {elapsed:.1f} s")
    check_common(file, report, per_hold_taus(per_hold_fits(real)), failures)


def main():
    ftdiag = sys.argv[1]
    seeds = (101, 102, 103, 104, 105, 106, 110, 117, 123)
    if len(sys.argv) == 4 and sys.argv[2] == "--seeds":
        seeds = tuple(int(s) for s in sys.argv[3].split(","))
    elif len(sys.argv) != 2:
        sys.exit("usage: diag_ringing_real_test.py FTDIAG [--seeds S1,S2,...]")
    failures = []
    with tempfile.TemporaryDirectory() as work:
        for seed in seeds:
            check_generator(ftdiag, work, seed, failures)
        for file in ("ketter133_2024-02-14.csv", "seesl_2024-01-22.csv"):
            check_real(ftdiag, work, file, failures)
    for f in failures:
        print("FAIL:", f)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
