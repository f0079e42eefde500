#!/usr/bin/env python3
"""Independent per-hold analysis of a dead-weight recording (numpy only).

Written apart from the project's diagnosis so that its figures can check it. For a recording with
a stepwise reference force (holds of constant load) and bridge columns:

1. Converter glitches: samples that stand off both neighbours by more than 50 times the channel's
   first-difference noise while two samples either side are quiet (signal_tools.isolated_codes);
   replaced by the neighbours' mean for everything below, and counted unless they fall inside a
   load change (there a bounce sampled near its alias can look the same) with a code within the
   record's span (off the span by more than the span itself, a code is a glitch anywhere).
2. Load changes: where the reference changes. For each, the real load's progress from the old to
   the new level (5-95 %) on the channel with the largest step gives the application time, and
   the last excursion beyond 5 % of the step the settling time; the largest overshoot is reported.
3. Each hold, from the settled end of its load change + 1 s to 1 s before the next change, is
   fitted per channel by least squares with c + a exp(-(t-t0)/tau) + exp(-(t-t0)/T)(p cos + q sin)
   (2 pi f (t-t0)): f from the least-squares periodogram of the hold (10-s moving average removed),
   tau and T on logarithmic grids (a value on a grid end is "not resolved"), then f refined.
   Q = pi f T. Creep fraction = -a / step into the hold (positive: the output keeps moving the way
   the load moved). Ringing amplitude = sqrt(p^2 + q^2) / step at the start of the window.
4. Noise per channel from first differences inside the fitted windows: robust sigma of the raw
   differences / sqrt(2), and of the fit residual's differences / sqrt(2).

Usage: hold_analysis.py REC.csv [--force Fz] [--json OUT.json]
"""

import argparse
import json
import math
import os
import sys

import numpy as np

sys.dont_write_bytecode = True  # keep the source tree clean
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from recording_io import read_recording  # noqa: E402
from signal_tools import isolated_codes, ls_periodogram, moving_average, mvv_per_unit, robust_sigma  # noqa: E402

LINE_PROMINENCE = 20.0   # periodogram peak over its median that counts as a line
MIN_LINE_Q = 5.0         # and it must ring (decay time resolved, Q of at least this)
MIN_STEP_NOISE = 100.0   # creep and ringing fractions only where the step exceeds this x noise


def remove_glitches(x):
    sigma_d = robust_sigma(np.diff(x))
    idx = isolated_codes(x, 50.0 * max(sigma_d, 1.0))
    clean = x.copy()
    clean[idx] = 0.5 * (x[idx - 1] + x[idx + 1])
    return clean, idx


def transition(t, x, i_change, t_prev, t_next):
    """Application and settling of one load change, from the cleaned channel x."""
    tc = t[i_change]
    lo_b, hi_b = max(t_prev, tc - 8.0), tc - 3.0
    lo_a, hi_a = tc + 5.0, min(t_next, tc + 10.0)
    before = x[(t >= lo_b) & (t < hi_b)]
    after = x[(t >= lo_a) & (t < hi_a)]
    if len(before) < 3 or len(after) < 3:
        return None
    level_b, level_a = np.median(before), np.median(after)
    win = np.nonzero((t >= hi_b) & (t < lo_a))[0]
    p = (x[win] - level_b) / (level_a - level_b)
    leave = np.nonzero(p > 0.05)[0]
    reach = np.nonzero(p >= 0.95)[0]
    away = np.nonzero(np.abs(p - 1.0) > 0.05)[0]
    if not len(leave) or not len(reach):
        return None
    t_start = t[win[max(leave[0] - 1, 0)]]
    t_reach = t[win[reach[0]]]
    t_settled = t[win[min(away[-1] + 1, len(win) - 1)]] if len(away) else t_reach
    return {"t_ref_s": float(tc), "application_s": float(t_reach - t_start),
            "settled_after_ref_s": float(t_settled - tc), "start_before_ref_s": float(tc - t_start),
            "overshoot_fraction": float(max(p.max() - 1.0, 0.0))}


def fit_hold(t, x, rate):
    """Least-squares creep + decaying line on one hold window; returns a dict of figures."""
    t0 = t[0]
    s = t - t0
    span = s[-1]
    width = max(3, min(int(round(10.0 * rate)), len(x) // 3))
    hp = x - moving_average(x, width)
    coarse = np.linspace(max(0.05, 3.0 / span), 0.45 * rate, 1200)
    power = ls_periodogram(t, hp, coarse)
    k = int(np.argmax(power))
    prominence = float(power[k] / np.median(power))
    step = coarse[1] - coarse[0]
    fine = np.linspace(coarse[k] - step, coarse[k] + step, 41)
    f = float(fine[int(np.argmax(ls_periodogram(t, hp, fine)))])
    taus = np.geomspace(max(1.0, 5.0 / rate), 3.0 * span, 40)
    decays = np.geomspace(2.0, 20.0 * span, 30)
    best = None

    def solve(tau, decay, freq):
        env = np.exp(-s / decay)
        arg = 2.0 * math.pi * freq * s
        design = np.column_stack([np.ones_like(s), np.exp(-s / tau), env * np.cos(arg), env * np.sin(arg)])
        coef, *_ = np.linalg.lstsq(design, x, rcond=None)
        resid = x - design @ coef
        return float(resid @ resid), coef, resid

    for tau in taus:
        for decay in decays:
            sse, coef, resid = solve(tau, decay, f)
            if best is None or sse < best[0]:
                best = (sse, tau, decay, f, coef, resid)
    _, tau, decay, f, coef, resid = best
    for freq in np.linspace(f - 0.5 * step, f + 0.5 * step, 21):
        sse, c2, r2 = solve(tau, decay, freq)
        if sse < best[0]:
            best = (sse, tau, decay, freq, c2, r2)
    _, tau, decay, f, coef, resid = best
    decay_at_bound = bool(decay in (decays[0], decays[-1]))
    q = math.pi * f * decay
    return {
        "window_s": [float(t[0]), float(t[-1])], "rows": int(len(x)),
        "line_freq_hz": f, "line_prominence": prominence,
        "line": bool(prominence >= LINE_PROMINENCE and not decay_at_bound and q >= MIN_LINE_Q),
        "decay_s": float(decay), "q": float(q), "decay_at_bound": decay_at_bound,
        "ring_amplitude": float(math.hypot(coef[2], coef[3])),
        "creep_tau_s": float(tau), "creep_a": float(coef[1]),
        "tau_at_bound": bool(tau in (taus[0], taus[-1])),
        "noise_raw": robust_sigma(np.diff(x)) / math.sqrt(2.0),
        "noise_resid": robust_sigma(np.diff(resid)) / math.sqrt(2.0),
        "level": float(np.median(x)),
    }


def analyse(path, force="Fz"):
    rec = read_recording(path)
    scale = mvv_per_unit(rec.meta)
    t = rec.col("t")
    ref = rec.col(force)
    rate = (len(t) - 1) / (t[-1] - t[0])
    names = rec.bridges()
    clean = {}
    glitches = {}
    for name in names:
        clean[name], idx = remove_glitches(rec.col(name))
        glitches[name] = [float(t[i]) for i in idx]
    changes = list(np.nonzero(np.diff(ref) != 0)[0] + 1)
    steps = {name: [] for name in names}
    edges = [0] + changes + [len(t)]
    # The channel that carries the largest load step tells the transitions.
    span = {n: abs(np.median(clean[n][changes[0]:edges[2]]) - np.median(clean[n][:changes[0]]))
            for n in names} if changes else {n: 0.0 for n in names}
    lead = max(names, key=lambda n: span[n])
    transitions = []
    for j, i in enumerate(changes):
        t_prev = t[edges[j]]
        t_next = t[edges[j + 2] - 1]
        tr = transition(t, clean[lead], i, t_prev, t_next)
        transitions.append(tr)
    # An isolated code inside a load change may be a bounce sampled near its alias: kept apart.
    windows = [(tr["t_ref_s"] - tr["start_before_ref_s"] - 0.5, tr["t_ref_s"] + tr["settled_after_ref_s"] + 0.5)
               for tr in transitions if tr]
    in_changes = {}
    for name in names:
        # A code off the whole record's span by more than that span is a glitch wherever it is.
        x = rec.col(name)
        lo, hi = np.percentile(clean[name], [0.5, 99.5])
        wild = {float(t[i]) for i in range(len(t)) if x[i] < lo - (hi - lo) or x[i] > hi + (hi - lo)}
        inside = [v for v in glitches[name] if any(a <= v <= b for a, b in windows) and v not in wild]
        glitches[name] = [v for v in glitches[name] if v not in inside]
        in_changes[name] = inside
    holds = []
    for j in range(len(edges) - 1):
        a, b = edges[j], edges[j + 1]
        start = t[a]
        if j > 0:
            tr = transitions[j - 1]
            settle = tr["settled_after_ref_s"] if tr else 5.0
            start = t[a] + max(settle, 0.0) + 1.0
        end = t[b - 1] - (1.0 if b < len(t) else 0.0)
        if j < len(changes) and transitions[j]:
            end = min(end, t[changes[j]] - transitions[j]["start_before_ref_s"] - 1.0)
        rows = np.nonzero((t >= start) & (t <= end))[0]
        hold = {"load": float(ref[a]), "start_s": float(start), "end_s": float(end), "channels": {}}
        if len(rows) < max(30, 3.0 * rate):
            hold["skipped"] = f"only {len(rows)} rows after settling"
            holds.append(hold)
            continue
        for name in names:
            fit = fit_hold(t[rows], clean[name][rows], rate)
            hold["channels"][name] = fit
        holds.append(hold)
    # Step into each hold per channel: difference of the fitted hold levels.
    for j in range(1, len(holds)):
        for name in names:
            cur = holds[j]["channels"].get(name)
            prev = holds[j - 1]["channels"].get(name)
            if cur and prev:
                step = cur["level"] - prev["level"]
                cur["step"] = step
                big = abs(step) > MIN_STEP_NOISE * max(cur["noise_resid"], 1e-12)
                cur["creep_fraction"] = -cur["creep_a"] / step if big else None
                cur["ring_fraction"] = cur["ring_amplitude"] / abs(step) if big else None
    return {"file": os.path.basename(path), "rate_hz": rate, "rows": len(t), "mvv_per_unit": scale,
            "channels": names, "glitches": glitches, "isolated_in_load_changes": in_changes,
            "transitions": transitions, "holds": holds}


def summary(result):
    lines = [f"{result['file']}: {result['rows']} rows at {result['rate_hz']:.3f} Hz"]
    for name, g in result["glitches"].items():
        if g:
            lines.append(f"  glitches {name}: {len(g)} at t = " + ", ".join(f"{v:.1f}" for v in g))
    inside = sum(len(v) for v in result["isolated_in_load_changes"].values())
    if inside:
        lines.append(f"  isolated codes inside load changes (a bounce near its alias?), not counted: {inside}")
    good = [tr for tr in result["transitions"] if tr]
    if good:
        app = [tr["application_s"] for tr in good]
        settle = [tr["settled_after_ref_s"] for tr in good]
        over = [tr["overshoot_fraction"] for tr in good]
        lines.append(f"  load changes: {len(result['transitions'])}, application (5-95 %) "
                     f"{min(app):.2f}-{max(app):.2f} s, settled within 5 % {min(settle):.2f}-{max(settle):.2f} s "
                     f"after the reference step, overshoot up to {100 * max(over):.1f} % of the step")
    scale = result["mvv_per_unit"]
    for name in result["channels"]:
        fits = [h["channels"][name] for h in result["holds"] if name in h.get("channels", {})]
        if not fits:
            continue
        lines_f = [f["line_freq_hz"] for f in fits if f["line"]]
        q = [f["q"] for f in fits if f["line"] and not f["decay_at_bound"]]
        ring = [f["ring_fraction"] for f in fits if f["line"] and f.get("ring_fraction")]
        tau = [f["creep_tau_s"] for f in fits if not f["tau_at_bound"] and f.get("creep_fraction") is not None]
        frac = [f["creep_fraction"] for f in fits if not f["tau_at_bound"] and f.get("creep_fraction") is not None]
        unresolved = sum(1 for f in fits if f["tau_at_bound"])
        raw = [f["noise_raw"] for f in fits]
        res = [f["noise_resid"] for f in fits]
        text = f"  {name}: {len(fits)} holds fitted; "
        text += (f"line in {len(lines_f)}: {min(lines_f):.4f}-{max(lines_f):.4f} Hz" if lines_f else "no line")
        if q:
            text += f", Q {min(q):.0f}-{max(q):.0f}"
        if ring:
            text += f", ringing {100 * min(ring):.3f}-{100 * max(ring):.3f} % of the step"
        if tau:
            text += (f"; creep tau {min(tau):.1f}-{max(tau):.1f} s, fraction "
                     f"{100 * min(frac):+.3f} to {100 * max(frac):+.3f} %")
        if unresolved:
            text += f" ({unresolved} holds: tau at a grid end, not resolved)"
        quiet = int(np.argmin(res))
        text += (f"; noise (first differences / sqrt 2): median over holds {np.median(raw):.1f} raw, "
                 f"quietest hold {res[quiet]:.1f} after the fit = {res[quiet] * scale:.2e} mV/V")
        lines.append(text)
    return "\n".join(lines)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("recording")
    parser.add_argument("--force", default="Fz")
    parser.add_argument("--json", help="write every per-hold figure here")
    args = parser.parse_args()
    result = analyse(args.recording, args.force)
    print(summary(result))
    if args.json:
        with open(args.json, "w", encoding="utf-8") as f:
            json.dump(result, f, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
