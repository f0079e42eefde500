#!/usr/bin/env python3
"""What an ftdiag change did to the claims, case by case: a Markdown table of two report sets.

For every CASE.json found in both OLD_DIR and NEW_DIR: the verdict, each claimed effect with the
status of its typed parameters, its headline parameter values and its held-out improvement
(1 - rms_after / rms_before of the report), old beside new, and whether the row moved. Finer
field-by-field differences: diag_report_diff.py.

Usage: diag_claims_table.py OLD_DIR NEW_DIR
"""

import json
import os
import sys


def fmt(v):
    if isinstance(v, list):
        return "[" + ", ".join(fmt(x) for x in v) + "]"
    if isinstance(v, float):
        return f"{v:.4g}"
    return str(v)


def effect_text(e):
    statuses = sorted({p.get("status", "?") for p in e.get("parameters", [])} - {"resolved"})
    ranged = [p for p in e.get("parameters", []) if p.get("range") is not None]
    values = ", ".join(f"{p['key']}={fmt(p['value'])}" for p in ranged[:3])
    text = e["name"] + (f" ({values})" if values else "")
    if statuses:
        text += " [" + "/".join(statuses) + "]"
    if e.get("confounded_with"):
        text += " conf:" + "+".join(e["confounded_with"])
    return text


def summary(path):
    with open(path, encoding="utf-8") as f:
        r = json.load(f)
    h = r.get("holdout", {})
    before, after = h.get("rms_before"), h.get("rms_after")
    gain = None
    if isinstance(before, (int, float)) and isinstance(after, (int, float)) and before > 0:
        gain = 100.0 * (1.0 - after / before)
    claims = "; ".join(effect_text(e) for e in r.get("effects", [])) or "—"
    dropped = len(r.get("not_claimed", []))
    return r.get("verdict", "?"), claims, gain, dropped


def main():
    if len(sys.argv) != 3:
        sys.stderr.write(__doc__)
        return 2
    old_dir, new_dir = sys.argv[1], sys.argv[2]
    cases = sorted(n for n in os.listdir(old_dir)
                   if n.endswith(".json") and os.path.exists(os.path.join(new_dir, n)))
    print("| case | verdict old → new | claims old | claims new | held-out gain % old → new "
          "| not_claimed old → new | moved |")
    print("|---|---|---|---|---|---|---|")
    moved = 0
    for n in cases:
        o = summary(os.path.join(old_dir, n))
        w = summary(os.path.join(new_dir, n))
        same = o[0] == w[0] and o[1] == w[1] and o[3] == w[3] and (
            o[2] is None and w[2] is None or o[2] is not None and w[2] is not None
            and abs(o[2] - w[2]) < 0.05)
        moved += not same
        g = " → ".join("—" if x is None else f"{x:.1f}" for x in (o[2], w[2]))
        print(f"| {n[:-5]} | {o[0]} → {w[0]} | {o[1]} | {w[1]} | {g} | {o[3]} → {w[3]} "
              f"| {'no' if same else 'YES'} |")
    print(f"\n{len(cases)} cases, {moved} moved")
    return 0


if __name__ == "__main__":
    sys.exit(main())
