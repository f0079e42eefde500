#!/usr/bin/env python3
"""Run `ftdiag diagnose` on dead-weight recordings the way a load-cell user would, and summarise.

For each REAL.csv: build the user's simulation (static_sim.py: a least-squares line per cell in
the reference force), run `ftdiag diagnose --sim --real --json --html`, time it, and print what
it claims: verdict, each effect with its headline parameters, the noise it assumed, and the
held-out RMS before and after. With --truth (a generator truth JSON) prints the truth beside it.
With --replace-glitches the real file is first copied with its isolated wrong codes replaced by
the neighbours' mean (the rule of hold_analysis.py), to show what the glitches alone do.

Usage: ftdiag_baseline.py --ftdiag BUILD/bin/ftdiag --out DIR REAL.csv [REAL.csv ...]
"""

import argparse
import json
import os
import subprocess
import sys
import time

sys.dont_write_bytecode = True  # keep the source tree clean
HERE = os.path.dirname(os.path.abspath(__file__))
HEADLINE = ("freq_hz", "damping_ratio", "freq2_hz", "damping_ratio2", "tau_s", "tau1_s", "tau2_s",
            "delay_s", "onset_s", "limit", "axis", "angle_deg", "coef_per_K")


def value_text(v):
    if isinstance(v, dict):
        v = v.get("value", v)
    if isinstance(v, list):
        return "[" + ", ".join(value_text(x) for x in v) + "]"
    if isinstance(v, float):
        return f"{v:.4g}"
    return str(v)


def replace_glitches(path, out):
    sys.path.insert(0, HERE)
    from hold_analysis import remove_glitches
    from recording_io import read_recording, write_recording
    rec = read_recording(path)
    columns = []
    for name in rec.names:
        values = rec.col(name)
        if name in rec.bridges():
            values = remove_glitches(values)[0]
        columns.append((name, values, "{:.6f}" if name == "t" else "{:.6g}"))
    write_recording(out, list(rec.meta.items()), columns)
    return out


def describe(report):
    lines = [f"verdict: {report.get('verdict')}"]
    for eff in report.get("effects", []):
        params = eff.get("params", {})
        sig = eff.get("uncertainty", {})
        parts = [f"{k} = {value_text(params[k])}" + (f" ± {value_text(sig[k])}" if k in sig else "")
                 for k in HEADLINE if k in params]
        for k in ("amplitude", "fraction", "fraction1", "fraction2", "participation"):
            if k in params:
                parts.append(f"{k} = {value_text(params[k])}")
        ident = "" if eff.get("identifiable", True) else " (not identifiable)"
        lines.append(f"  {eff.get('name')} [{eff.get('model', '')}]{ident} on {eff.get('channels')}: "
                     + "; ".join(parts))
        oiml = eff.get("standard", {}).get("oiml_r60")
        if oiml:
            lines.append(f"    OIML R 60 creep over 30 min: {value_text(oiml.get('creep_30min_pct'))} %")
    lines.append("  noise_rms (mV/V): " + value_text(report.get("noise_rms")))
    h = report.get("holdout", {})
    before, after = h.get("rms_before"), h.get("rms_after")
    if before:
        lines.append(f"  held-out RMS {before:.4g} -> {after:.4g} mV/V "
                     f"({100.0 * (1.0 - after / before):.1f} % lower), {h.get('rows')} rows")
    return "\n".join(lines)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--ftdiag", required=True)
    parser.add_argument("--out", required=True, help="directory for sims, JSON and HTML reports")
    parser.add_argument("--truth", action="append", default=[], help="truth JSON, in file order")
    parser.add_argument("--replace-glitches", action="store_true")
    parser.add_argument("real", nargs="+")
    args = parser.parse_args()
    os.makedirs(args.out, exist_ok=True)
    for n, real in enumerate(args.real):
        stem = os.path.splitext(os.path.basename(real))[0]
        if args.replace_glitches:
            stem += "_deglitched"
            real = replace_glitches(real, os.path.join(args.out, stem + ".csv"))
        sim = os.path.join(args.out, stem + "_sim.csv")
        subprocess.run([sys.executable, os.path.join(HERE, "static_sim.py"), real, sim], check=True,
                       stdout=subprocess.DEVNULL)
        report_path = os.path.join(args.out, stem + ".json")
        start = time.monotonic()
        run = subprocess.run([args.ftdiag, "diagnose", "--sim", sim, "--real", real, "--json", report_path,
                              "--html", os.path.join(args.out, stem + ".html")],
                             capture_output=True, text=True)
        elapsed = time.monotonic() - start
        print(f"== {stem}: ftdiag exit {run.returncode} in {elapsed:.2f} s")
        if run.returncode != 0:
            print("  " + run.stderr.strip())
            continue
        with open(report_path, encoding="utf-8") as f:
            print(describe(json.load(f)))
        if n < len(args.truth):
            with open(args.truth[n], encoding="utf-8") as f:
                truth = json.load(f)
            ring, creep = truth.get("ringing"), truth.get("creep")
            text = "  truth:"
            if ring:
                text += f" ringing {ring['freq_hz']:.4f} Hz, Q {ring['q']:.0f} (zeta {ring['damping_ratio']:.2e});"
            if creep:
                text += (f" creep tau {', '.join(f'{v:.1f}' for v in creep['tau_s'])} s, total fraction "
                         f"{', '.join(f'{100 * v:.2f}' for v in creep['fraction_total'])} %;")
            noise = truth["noise_counts_rms"]
            per_count = truth["mvv_per_count"]
            text += (f" {len(truth['glitches'])} glitches; noise "
                     + ", ".join(f"{v:.0f}" for v in noise) + " counts = "
                     + ", ".join(f"{v * per_count:.2e}" for v in noise) + " mV/V")
            print(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
