#!/usr/bin/env python3
"""What a recording holds, measured without the diagnosis: a survey for the real-recording corpus.

For a recording in the ftstack format (docs/spec/recording-format.md) prints, with numbers:
- rate (median period, its spread) and duration; the columns;
- the reference: its range and its load changes (a change = the 1-s running median moving by
  more than 5 % of the reference's range within 2 s; consecutive changes merge), holds between;
- per bridge and per extra numeric column: range, white noise (robust sigma of first differences
  / sqrt 2), the value grid (the smallest step between distinct values and the share of values
  that lie on multiples of it), drift (slope of a straight line through the record, per minute,
  and the spread of 60-s means), and the static gain against the reference (least squares);
- spectral lines per bridge: a Welch average of Hann-windowed periodograms (segments of 2^k
  samples, about 20 s), peaks at least 30x the median spectral level of their neighbourhood,
  with each line's amplitude; which of them sit within one bin of harmonics 1-5 of 50 Hz, 60 Hz
  or 16.7 Hz, or of
  where such a line folds at this rate;
- temperature: range, grid, and whether it is monotone in time (Spearman-like rank correlation).
Nothing here reads or calls diagnosis code. Usage: recording_survey.py REC.csv [--json OUT]
"""

import argparse
import json
import os
import sys

import numpy as np

sys.dont_write_bytecode = True  # keep the source tree clean
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from recording_io import read_recording  # noqa: E402

SUPPLY_HZ = (16.7, 50.0, 60.0)


def robust_sigma(x):
    return 1.4826 * float(np.median(np.abs(x - np.median(x))))


def value_grid(x):
    values = np.unique(x)
    if len(values) < 2:
        return 0.0, 1.0
    steps = np.diff(values)
    step = float(np.min(steps[steps > 0]))
    ratio = (x - values[0]) / step
    on_grid = float(np.mean(np.abs(ratio - np.round(ratio)) < 0.02))
    return step, on_grid


def running_median(x, width):
    if width < 2:
        return x.copy(), 1
    pad = width // 2
    padded = np.pad(x, pad, mode="edge")
    windows = np.lib.stride_tricks.sliding_window_view(padded, 2 * pad + 1)
    return np.median(windows[:: max(1, width // 8)], axis=1), max(1, width // 8)


def runs(mask):
    """(first, last) index of every run of consecutive True values."""
    edges = np.diff(np.concatenate(([0], np.asarray(mask, dtype=np.int8), [0])))
    return list(zip(np.nonzero(edges == 1)[0].tolist(), (np.nonzero(edges == -1)[0] - 1).tolist()))


def load_changes(t, f, rate_hz):
    span = float(np.ptp(f))
    if span <= 0:
        return []
    med, stride = running_median(f, max(3, int(round(rate_hz))))
    tm = t[::stride][: len(med)]
    lag = max(1, int(round(2.0 * rate_hz / stride)))
    moved = np.abs(med[lag:] - med[:-lag]) > 0.05 * span
    return [(float(tm[i]), float(tm[j + lag]), float(med[i]), float(med[j + lag]))
            for i, j in runs(moved)]


def welch(x, rate_hz):
    n = len(x)
    seg = 1 << int(np.clip(np.floor(np.log2(min(n, 20.0 * rate_hz))), 6, 20))
    seg = min(seg, n)
    window = np.hanning(seg)
    step = seg // 2
    acc = np.zeros(seg // 2 + 1)
    count = 0
    for start in range(0, n - seg + 1, step):
        piece = x[start:start + seg]
        piece = piece - np.polyval(np.polyfit(np.arange(seg), piece, 1), np.arange(seg))
        acc += np.abs(np.fft.rfft(piece * window)) ** 2
        count += 1
    freqs = np.fft.rfftfreq(seg, 1.0 / rate_hz)
    # amplitude of a sine from its Hann-windowed peak: 2|X| / sum(w)
    amp = 2.0 * np.sqrt(acc / max(count, 1)) / np.sum(window)
    return freqs, amp


def folded(f_hz, rate_hz):
    f = f_hz % rate_hz
    return min(f, rate_hz - f)


def supply_match(f_hz, rate_hz, resolution_hz):
    names = []
    for base in SUPPLY_HZ:
        for k in range(1, 6):
            true_f = k * base
            seen = folded(true_f, rate_hz)
            if abs(seen - f_hz) <= resolution_hz:
                where = "" if true_f < rate_hz / 2 else f" (folded from {true_f:g} Hz)"
                names.append(f"{k}x{base:g} Hz{where}")  # every alias: the rate may not decide
    return names


def spectral_lines(x, rate_hz, threshold=30.0, limit=8):
    freqs, amp = welch(x, rate_hz)
    power = amp ** 2
    res = freqs[1] - freqs[0]
    lines = []
    half = max(8, len(freqs) // 64)
    for i in range(2, len(freqs) - 1):
        if power[i] < power[i - 1] or power[i] < power[i + 1]:
            continue
        lo, hi = max(1, i - half), min(len(freqs), i + half)
        floor = float(np.median(power[lo:hi]))
        if floor > 0 and power[i] >= threshold * floor:
            lines.append({"freq_hz": float(freqs[i]), "amplitude": float(amp[i]),
                          "above_floor": float(power[i] / floor),
                          "supply": supply_match(float(freqs[i]), rate_hz, res)})
    lines.sort(key=lambda d: -d["amplitude"])
    return lines[:limit], float(res)


def column_stats(t, x, f, rate_hz):
    step, on_grid = value_grid(x)
    minutes = (t - t[0]) / 60.0
    slope = float(np.polyfit(minutes, x, 1)[0]) if len(x) > 2 else 0.0
    block = max(1, int(round(60.0 * rate_hz)))
    means = [float(np.mean(x[i:i + block])) for i in range(0, len(x) - block + 1, block)]
    out = {"min": float(np.min(x)), "max": float(np.max(x)),
           "noise_sigma": robust_sigma(np.diff(x)) / np.sqrt(2.0),
           "grid_step": step, "share_on_grid": on_grid, "drift_per_min": slope,
           "minute_means_spread": float(np.ptp(means)) if means else 0.0}
    if f is not None and np.ptp(f) > 0:
        gain, offset = np.polyfit(f, x, 1)
        resid = x - (gain * f + offset)
        out.update({"gain_per_ref": float(gain), "offset": float(offset),
                    "static_fit_rms": float(np.sqrt(np.mean(resid ** 2)))})
    return out


def survey(path, ref_name=None):
    rec = read_recording(path)
    t = rec.col("t")
    periods = np.diff(t)
    rate = 1.0 / float(np.median(periods))
    report = {"file": os.path.basename(path), "rows": int(len(t)), "rate_hz": rate,
              "period_spread_s": [float(np.min(periods)), float(np.max(periods))],
              "duration_s": float(t[-1] - t[0]), "columns": rec.names}
    if ref_name is None:
        ref_name = max(("Fx", "Fy", "Fz", "Mx", "My", "Mz"),
                       key=lambda n: float(np.ptp(rec.col(n))) if rec.has(n) else -1.0)
    f = rec.col(ref_name) if rec.has(ref_name) else None
    if f is not None:
        report["reference"] = {"name": ref_name, "min": float(np.min(f)), "max": float(np.max(f)),
                               "changes": load_changes(t, f, rate)}
    skip = {"t", "Fx", "Fy", "Fz", "Mx", "My", "Mz", "segment", "pose", "block"}
    report["channels"] = {}
    for name in rec.names:
        if name in skip:
            continue
        x = rec.col(name)
        stats = column_stats(t, x, f if name.startswith("b") else None, rate)
        if name.startswith("b"):
            stats["lines"], stats["line_resolution_hz"] = spectral_lines(x, rate)
        report["channels"][name] = stats
    if rec.has("temp_C"):
        temp = rec.col("temp_C")
        ranks_t = np.argsort(np.argsort(t))
        ranks_c = np.argsort(np.argsort(temp + 1e-12 * np.arange(len(temp))))
        report["temperature"] = {"min": float(np.min(temp)), "max": float(np.max(temp)),
                                 "rank_corr_with_time": float(np.corrcoef(ranks_t, ranks_c)[0, 1])}
    return report


def print_report(r):
    print(f"{r['file']}: {r['rows']} rows, {r['rate_hz']:.4g} Hz (periods "
          f"{r['period_spread_s'][0]:.4g}-{r['period_spread_s'][1]:.4g} s), {r['duration_s']:.1f} s")
    if "reference" in r:
        ref = r["reference"]
        print(f"  reference {ref['name']}: {ref['min']:.6g} .. {ref['max']:.6g}, "
              f"{len(ref['changes'])} load changes")
        for c in ref["changes"]:
            print(f"    {c[0]:8.2f}-{c[1]:8.2f} s: {c[2]:.6g} -> {c[3]:.6g}")
    for name, s in r["channels"].items():
        print(f"  {name}: {s['min']:.6g} .. {s['max']:.6g}; noise {s['noise_sigma']:.3g}; grid "
              f"{s['grid_step']:.3g} ({100 * s['share_on_grid']:.0f} % on it); drift "
              f"{s['drift_per_min']:.3g}/min, 60-s means spread {s['minute_means_spread']:.3g}")
        if "gain_per_ref" in s:
            print(f"    static gain {s['gain_per_ref']:.6g} per unit, fit RMS {s['static_fit_rms']:.3g}")
        for line in s.get("lines", []):
            print(f"    line {line['freq_hz']:.4g} Hz amp {line['amplitude']:.3g} "
                  f"({line['above_floor']:.0f}x floor) {', '.join(line['supply'])}")
    if "temperature" in r:
        tc = r["temperature"]
        print(f"  temperature {tc['min']:.2f} .. {tc['max']:.2f} C, rank correlation with time "
              f"{tc['rank_corr_with_time']:+.3f}")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("recording")
    parser.add_argument("--ref", help="reference column (default: the wrench column that varies most)")
    parser.add_argument("--json")
    args = parser.parse_args()
    report = survey(args.recording, args.ref)
    print_report(report)
    if args.json:
        with open(args.json, "w", encoding="utf-8") as f:
            json.dump(report, f, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
