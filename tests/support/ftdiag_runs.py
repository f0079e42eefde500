"""Running ftdiag the way a load-cell user does, for the tests on hanging-weight recordings.

generate(): a recording of the independent generator (real_class_generator.py) and its truth;
diagnose(): the user's static linear sim (static_sim.py), then `ftdiag diagnose`, the JSON report
and the seconds it took. Shared by tests/diagnosis/diag_conditioning_test.py and
diag_ringing_real_test.py.
"""

import json
import os
import subprocess
import sys
import time

SUPPORT = os.path.dirname(os.path.abspath(__file__))
PY = sys.executable


def run(args):
    subprocess.run(args, check=True, stdout=subprocess.DEVNULL)


def generate(work, seed, *options):
    """Writes work/gen_SEED.csv (and its truth JSON) with the generator's options; returns both."""
    real = os.path.join(work, f"gen_{seed}.csv")
    run([PY, os.path.join(SUPPORT, "real_class_generator.py"), "--out", real, "--seed", str(seed),
         *options])
    with open(real[:-4] + ".json", encoding="utf-8") as f:
        return real, json.load(f)


def diagnose(ftdiag, real, work):
    """(report, seconds) of `ftdiag diagnose` on REAL against its static linear sim."""
    sim = os.path.join(work, os.path.basename(real) + ".sim.csv")
    out = os.path.join(work, os.path.basename(real) + ".report.json")
    run([PY, os.path.join(SUPPORT, "static_sim.py"), real, sim])
    t0 = time.monotonic()
    run([ftdiag, "diagnose", "--sim", sim, "--real", real, "--json", out])
    elapsed = time.monotonic() - t0
    with open(out, encoding="utf-8") as f:
        return json.load(f), elapsed
