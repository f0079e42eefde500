#!/usr/bin/env python3
"""Independent generator of hanging-weight load-cell recordings read by HX711-class converters.

Written from the physics of the test, not from the project's simulator or diagnosis models, so
that methods tuned on one cannot pass by construction on the other. What it makes:

- a dead weight hung by hand and removed, several times: holds of minutes at whole multiples of
  one weight; each change takes a finite application time (raised-cosine ramp) and ends with a
  short, well-damped bounce of the hanger on the hook (a few Hz, a few % of the step);
- pendulum ringing of the hanging weight: one lightly damped line (0.5-2 Hz, Q 100-500) excited
  at every load change with a random phase and an amplitude of a few tenths of a percent of the
  step, seen by every cell with its own participation and sign, and carried across holds;
- creep: one or two first-order time constants (tens of seconds), a few tenths of a percent of
  each load change, per cell;
- zero shifts: at some load changes a cell's zero moves by a small random amount and stays;
- converter glitches: isolated single samples whose code has one high bit flipped (off by 2^17 to
  2^23 counts);
- an HX711 read-out: 24-bit signed codes at gain 128, ratiometric, white noise of tens of counts,
  sampled by the converter's own RC clock (a few % off nominal) and time-stamped by a logger with
  millisecond rounding and latency jitter.

Output: a recording (docs/spec/recording-format.md) with t, the reference wrench (Fz = the
nominal weight force as the operator would log it: a step at the logged time) and b0.. in counts,
declared with `# converter:`; and the truth as JSON beside it.

Usage: real_class_generator.py --out REC.csv [--truth REC.json] [--seed N] [--duration-s S]
       [--rate-hz R] [--channels N] [--effects ringing,creep,zero_shift,glitches,bounce,jitter,noise]
"""

import argparse
import json
import math
import os
import sys

import numpy as np

sys.dont_write_bytecode = True  # keep the source tree clean
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from recording_io import write_recording  # noqa: E402

ALL_EFFECTS = ("ringing", "creep", "zero_shift", "glitches", "bounce", "jitter", "noise")
BITS = 24
PGA_GAIN = 128
MVV_PER_COUNT = 1000.0 / PGA_GAIN / 2 ** (BITS - 1)   # ratiometric, signed, reference = excitation
CODE_MIN, CODE_MAX = -2 ** (BITS - 1), 2 ** (BITS - 1) - 1


def plan_holds(rng, duration_s, weight_n):
    """Load schedule: (t_change_s, new_load_n) list, holds of 60-240 s, loads 0..4 weights."""
    changes = []
    t = rng.uniform(20.0, 60.0)            # unloaded start
    level = 0
    max_weights = int(rng.integers(2, 5))
    while True:
        hold = rng.uniform(60.0, 240.0)
        if t + hold + 20.0 > duration_s:
            break
        if level == 0:
            new = int(rng.integers(1, max_weights + 1))
        elif level == max_weights or rng.random() < 0.4:
            new = int(rng.integers(0, level))
        else:
            new = int(rng.integers(level + 1, max_weights + 1))
        changes.append((t, new * weight_n))
        level = new
        t += hold
    if level != 0 and changes:
        changes.append((min(t, duration_s - 15.0), 0.0))   # unload before the end
    return changes


def sample_times(rng, duration_s, rate_hz, jitter):
    """True sampling instants (converter clock) and the logged time stamps."""
    clock_offset = rng.uniform(-0.03, 0.03) if jitter else 0.0
    period = 1.0 / (rate_hz * (1.0 + clock_offset))
    n = int(duration_s / period)
    t_true = np.arange(n) * period
    if jitter:
        t_true = t_true + rng.normal(0.0, 0.002 * period, n)       # conversion-ready jitter
        latency = rng.uniform(0.0, min(0.003, 0.3 * period), n)    # logger latency
        t_log = np.round((t_true + latency) * 1000.0) / 1000.0      # millis() stamps
        t_log = np.maximum.accumulate(t_log)
        for i in range(1, n):   # a repeated millisecond moves on by one
            if t_log[i] <= t_log[i - 1]:
                t_log[i] = t_log[i - 1] + 0.001
    else:
        t_log = t_true.copy()
    return t_true, t_log, clock_offset


def ramp(x):
    """Raised-cosine ramp from 0 (x <= 0) to 1 (x >= 1)."""
    x = np.clip(x, 0.0, 1.0)
    return 0.5 - 0.5 * np.cos(math.pi * x)


def generate(seed, duration_s, rate_hz, channels, effects):
    rng = np.random.default_rng(seed)
    weight_n = rng.uniform(20.0, 80.0)
    changes = plan_holds(rng, duration_s, weight_n)
    t, t_log, clock_offset = sample_times(rng, duration_s, rate_hz, "jitter" in effects)
    n = len(t)
    nyquist = 0.5 * rate_hz * (1.0 + clock_offset)

    # Cells: sensitivity (counts per N, either sign: some are wired the other way), zero, noise.
    full_load_n = max([abs(load) for _, load in changes] + [weight_n])
    full_scale_mvv = rng.uniform(0.1, 1.2, channels)
    sens = full_scale_mvv / MVV_PER_COUNT / full_load_n * rng.choice([-1.0, 1.0], channels)
    zero = rng.uniform(-0.4, 0.4, channels) / MVV_PER_COUNT
    noise = rng.uniform(30.0, 120.0, channels) * math.sqrt(rate_hz / 10.0)

    # Pendulum ringing: one mode for the whole record (same hanger, same string).
    ring_f = rng.uniform(0.5, min(2.0, 0.4 * nyquist))
    ring_q = rng.uniform(100.0, 500.0)
    ring_zeta = 1.0 / (2.0 * ring_q)
    ring_decay_s = 1.0 / (ring_zeta * 2.0 * math.pi * ring_f)
    ring_part = rng.uniform(0.3, 1.0, channels) * rng.choice([-1.0, 1.0], channels)

    # Creep: one or two time constants shared by the cells, fractions per cell.
    n_tau = int(rng.integers(1, 3))
    taus = np.sort(np.array([rng.uniform(15.0, 40.0), rng.uniform(60.0, 150.0)][:n_tau]))
    creep_frac = rng.uniform(0.001, 0.004, (n_tau, channels)) / n_tau

    force_true = np.zeros(n)        # the load the cells really carry (ramp + bounce), N
    force_ref = np.zeros(n)         # the load the operator logs (a step), N
    extra = np.zeros((n, channels))  # counts: ringing, creep, zero shifts
    previous = 0.0
    transitions = []
    for t_ref, load in changes:
        step = load - previous
        app_s = rng.uniform(0.4, 2.0)
        t0 = t_ref - rng.uniform(0.1, 0.9) * app_s      # the operator logs a time inside it
        t1 = t0 + app_s
        force_true += step * ramp((t - t0) / app_s)
        force_ref[t_log >= t_ref] += step
        tr = {"t_ref_s": t_ref, "load_before_n": previous, "load_after_n": load,
              "application_start_s": t0, "application_end_s": t1, "application_s": app_s}
        settled = t1
        if "bounce" in effects:
            b_f = rng.uniform(1.5, max(1.6, min(4.0, 0.8 * nyquist)))
            b_zeta = rng.uniform(0.1, 0.3)
            b_frac = rng.uniform(0.02, 0.1) * (1.0 if step > 0 else 0.5)
            b_decay = 1.0 / (b_zeta * 2.0 * math.pi * b_f)
            after = t - t1
            on = after > 0
            force_true[on] += (step * b_frac * np.exp(-after[on] / b_decay)
                               * np.sin(2.0 * math.pi * b_f * after[on]))
            settled = t1 + 5.0 * b_decay
            tr["bounce"] = {"freq_hz": b_f, "damping_ratio": b_zeta, "fraction_of_step": b_frac,
                            "decay_s": b_decay}
        tr["settled_s"] = settled
        if "ringing" in effects:
            amp = rng.uniform(0.001, 0.006)
            phase = rng.uniform(0.0, 2.0 * math.pi)
            after = t - t1
            on = after > 0
            wave = np.exp(-after[on] / ring_decay_s) * np.cos(2.0 * math.pi * ring_f * after[on] + phase)
            extra[on] += np.outer(wave, abs(step) * amp * ring_part * np.abs(sens))
            tr["ringing_fraction_of_step"] = amp
            tr["ringing_phase_rad"] = phase
        if "creep" in effects:
            t_mid = 0.5 * (t0 + t1)
            after = t - t_mid
            on = after > 0
            for k in range(n_tau):
                extra[on] += np.outer(1.0 - np.exp(-after[on] / taus[k]), step * creep_frac[k] * sens)
        if "zero_shift" in effects and transitions and rng.random() < 0.6:
            shift = rng.normal(0.0, 0.0005, channels) * full_load_n * np.abs(sens)
            extra[t > settled] += shift
            tr["zero_shift_counts"] = shift.tolist()
        transitions.append(tr)
        previous = load

    signal = zero + np.outer(force_true, sens) + extra
    if "noise" in effects:
        signal = signal + rng.normal(0.0, 1.0, (n, channels)) * noise
    codes = np.clip(np.round(signal), CODE_MIN, CODE_MAX).astype(np.int64)

    glitches = []
    if "glitches" in effects:
        count = int(rng.integers(3, 9)) * channels
        used = set()
        while len(glitches) < count:
            i = int(rng.integers(3, n - 3))
            k = int(rng.integers(0, channels))
            if any(abs(i - j) < 3 for j, kk in used if kk == k):
                continue
            bit = int(rng.integers(17, BITS))
            raw = int(codes[i, k]) & 0xFFFFFF
            raw ^= 1 << bit
            value = raw - (1 << BITS) if raw & (1 << (BITS - 1)) else raw
            glitches.append({"index": i, "t_s": float(t_log[i]), "channel": k, "bit": bit,
                             "delta_counts": int(value - codes[i, k])})
            codes[i, k] = value
            used.add((i, k))
        glitches.sort(key=lambda g: (g["index"], g["channel"]))

    holds = []
    bounds = [0.0] + [tr["settled_s"] for tr in transitions] + [float(t_log[-1])]
    loads = [0.0] + [tr["load_after_n"] for tr in transitions]
    for j, load in enumerate(loads):
        end = transitions[j]["application_start_s"] if j < len(transitions) else float(t_log[-1])
        holds.append({"start_s": bounds[j], "end_s": end, "load_n": load})

    truth = {
        "generator": "tests/support/real_class_generator.py",
        "seed": seed, "effects": sorted(effects), "duration_s": duration_s,
        "rate_hz_nominal": rate_hz, "rate_hz_actual": rate_hz * (1.0 + clock_offset),
        "clock_offset": clock_offset, "rows": n, "channels": channels,
        "converter": f"bits={BITS}, coding=signed, gain={PGA_GAIN}, ratiometric=yes",
        "mvv_per_count": MVV_PER_COUNT, "weight_n": weight_n,
        "sensitivity_counts_per_n": sens.tolist(), "zero_counts": zero.tolist(),
        "noise_counts_rms": (noise if "noise" in effects else np.zeros(channels)).tolist(),
        "ringing": ({"freq_hz": ring_f, "q": ring_q, "damping_ratio": ring_zeta,
                     "decay_s": ring_decay_s, "participation": ring_part.tolist()}
                    if "ringing" in effects else None),
        "creep": ({"tau_s": taus.tolist(), "fraction": creep_frac.tolist(),
                   "fraction_total": creep_frac.sum(axis=0).tolist()}
                  if "creep" in effects else None),
        "transitions": transitions, "holds": holds, "glitches": glitches,
    }
    return t_log, force_ref, codes, truth


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", required=True, help="recording to write (CSV)")
    parser.add_argument("--truth", help="truth JSON (default: OUT with .json)")
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--duration-s", type=float, default=1800.0)
    parser.add_argument("--rate-hz", type=float, default=10.0)
    parser.add_argument("--channels", type=int, default=3)
    parser.add_argument("--effects", default=",".join(ALL_EFFECTS),
                        help=f"comma-separated subset of {','.join(ALL_EFFECTS)} ('' for none)")
    args = parser.parse_args()
    effects = [e for e in args.effects.split(",") if e]
    unknown = sorted(set(effects) - set(ALL_EFFECTS))
    if unknown:
        parser.error(f"unknown effects {unknown}; known: {', '.join(ALL_EFFECTS)}")
    if not 5.0 <= args.rate_hz <= 100.0:
        parser.error("--rate-hz must lie in 5 ... 100")
    if args.duration_s < 200.0:
        parser.error("--duration-s must be at least 200 (holds of minutes)")
    if not 1 <= args.channels <= 16:
        parser.error("--channels must lie in 1 ... 16")

    t, fz, codes, truth = generate(args.seed, args.duration_s, args.rate_hz, args.channels, effects)
    zeros = np.zeros(len(t))
    columns = [("t", t, "{:.3f}")] + [(name, fz if name == "Fz" else zeros, "{:.4f}")
                                      for name in ("Fx", "Fy", "Fz", "Mx", "My", "Mz")]
    columns += [(f"b{k}", codes[:, k], "{:d}") for k in range(args.channels)]
    meta = [("generator", f"tests/support/real_class_generator.py seed={args.seed} "
             f"rate_hz={args.rate_hz:g} channels={args.channels} effects={','.join(effects) or 'none'}"),
            ("converter", truth["converter"]),
            ("reference", "Fz = the dead weight's force as logged by the operator (a step at the "
             "logged time; the real load ramps and bounces around it), N")]
    write_recording(args.out, meta, columns)
    truth_path = args.truth or os.path.splitext(args.out)[0] + ".json"
    with open(truth_path, "w", encoding="utf-8") as f:
        json.dump(truth, f, indent=1)
    print(f"wrote {args.out} ({len(t)} rows, {args.channels} channels, "
          f"{len(truth['transitions'])} load changes) and {truth_path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
