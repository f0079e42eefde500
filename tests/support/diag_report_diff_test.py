#!/usr/bin/env python3
"""Checks diag_report_diff.py on two hand-written reports (tests/data/diag_report_diff/) against
the differences written down here by reading them, not by running the tool."""

import io
import os
import shutil
import sys
import tempfile

sys.dont_write_bytecode = True  # keep the source tree clean
HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import diag_report_diff as drd  # noqa: E402

DATA = os.path.join(HERE, "..", "data", "diag_report_diff")
OLD, NEW = os.path.join(DATA, "old.json"), os.path.join(DATA, "new.json")

# (path, kind) of every difference between old.json and new.json at the default tolerances, in
# the order the tool walks them (keys sorted, named lists by name): elapsed_s is a timing key,
# holdout.rms_after moved by 1e-13 relative (inside 1e-9), fraction did not move.
EXPECTED = [
    ("candidates[resonance].eligible", "changed"),
    ("candidates[resonance].not_resolved", "added"),
    ("candidates[resonance].z", "moved"),
    ("candidates", "order"),
    ("effects[creep].evidence", "text"),
    ("effects[creep].identifiable", "type"),
    ("effects[creep].spread", "added"),
    ("effects[zero_drift]", "removed"),
    ("findings", "added"),
    ("noise_rms[1]", "moved 1/3"),
]


def rows_of(rel=1e-9):
    d = drd.compare(drd.load(OLD), drd.load(NEW), rel, 1e-15, drd.DEFAULT_IGNORE)
    return d, [(r.path, r.kind) for r in d.rows]


def main():
    failures = []

    def check(ok, what):
        print(("ok   " if ok else "FAIL ") + what)
        if not ok:
            failures.append(what)

    d, rows = rows_of()
    check(rows == EXPECTED, f"rows at the default tolerance: {rows}")
    by_path = {r.path: r for r in d.rows}
    check(abs(by_path["candidates[resonance].z"].rel - 0.5) < 1e-12, "z 9 -> 4.5 is a relative change of 0.5")
    check(abs(by_path["noise_rms[1]"].rel - 0.05) < 1e-12, "noise 2e-4 -> 1.9e-4 is 0.05 relative")
    check(by_path["effects[creep].spread"].rel == 2, "the added spread counts its 2 leaves")
    check(by_path["candidates"].old == "creep resonance time_skew"
          and by_path["candidates"].new == "creep time_skew resonance", "order lists both orders")
    check(by_path["effects[creep].evidence"].new.startswith('"…tau = 10.0 s; the'), "text shown from its first difference")
    _, loose = rows_of(rel=0.06)
    check(("noise_rms[1]", "moved 1/3") not in loose and ("candidates[resonance].z", "moved") in loose,
          "a 5 % move is inside --rel 0.06, a 50 % one is not")
    silent = io.StringIO()
    sys.stdout, saved = silent, sys.stdout
    try:
        same = drd.main([OLD, OLD])
        differ = drd.main([OLD, NEW])
        work = tempfile.mkdtemp()
        for sub, new in (("a", OLD), ("b", NEW)):
            os.makedirs(os.path.join(work, sub))
            shutil.copy(OLD, os.path.join(work, sub, "old.json"))
            shutil.copy(new, os.path.join(work, sub, "new.json"))
        tree = drd.main(["--tree", work, "old.json", "new.json"])
        shutil.rmtree(work)
    finally:
        sys.stdout = saved
    check(same == 0 and differ == 1, f"exit codes: same report {same}, moved {differ}")
    check(tree == 1 and "1 report(s) differ" in silent.getvalue(), "--tree counts the one report that moved")
    try:
        sys.stderr, err = io.StringIO(), sys.stderr
        drd.main([OLD, os.path.join(DATA, "missing.json")])
        code = 0
    except SystemExit as e:
        code = e.code
    finally:
        sys.stderr = err
    check(code == 2, f"a missing report exits 2 (got {code})")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
