#!/usr/bin/env python3
"""ftcal on the printed 8-bridge sensor with every pair of its 12 orientations held out (66 fits).

The acceptance protocol of docs/calibration.md ("Model choice"): the public printed sensor of
github.com/jonurce/FTS_Calibration (no licence, so not vendored: pass the folder of its
Datasets/12_final_extra_bounded/data/data_*.csv files, or set FTSTACK_PRINTED_FT_DIR), read as
printed_product_selection.py reads it. For each pair of orientations the other ten are written
as a recording without unit metadata and fitted with
    ftcal fit --rated <largest |load| per axis> --converter bits=10,coding=unsigned
the pair is written the same way and run through `ftcal apply` with no unit option (the
calibration's own converter decides), and the held-out error is compared with plain affine least
squares on the raw codes solved here with numpy. Error = sqrt(mean over axes (RMS / scale)^2),
scale = largest |load| per axis. Prints one line per split (the choice and its margin, as ftcal
printed them), the summary of the development half of the pairs (i + j even: the half a change
of the method is tuned on) and of the validation half (i + j odd), and the summary of all 66;
exits 1 when a target of the protocol is missed.

usage: printed_pairs.py DATA_FOLDER FTCAL_BINARY
"""
import itertools
import os
import re
import subprocess
import sys
import tempfile

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from printed_product_selection import read  # noqa: E402

NAMES = ["Fx", "Fy", "Fz", "Mx", "My", "Mz"]


def write(path, pose, w, x):
    with open(path, "w") as f:
        f.write("t,pose," + ",".join(NAMES) + "," + ",".join(f"b{c}" for c in range(8)) + "\n")
        for i in range(len(pose)):
            f.write(f"{i * 0.01:.2f},{pose[i]}," + ",".join(f"{v:.9g}" for v in w[i]) + "," +
                    ",".join(f"{int(v)}" for v in x[i]) + "\n")


def read_applied(path):
    with open(path) as f:
        lines = [ln for ln in f if not ln.startswith("#")]
    header = lines[0].strip().split(",")
    a = np.array([[float(v) for v in ln.split(",")] for ln in lines[1:]])
    return a[:, [header.index(n) for n in NAMES]], a[:, header.index("status")]


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    folder, ftcal = sys.argv[1], sys.argv[2]
    pose, orient, w, x = read(folder)
    scale = np.abs(w).max(0)
    rated = ",".join(f"{v:.9g}" for v in scale)
    score = lambda e: np.sqrt(np.mean((e / scale) ** 2))
    ratios, dev = [], []
    with tempfile.TemporaryDirectory() as tmp:
        train, test = os.path.join(tmp, "train.csv"), os.path.join(tmp, "test.csv")
        cal, applied = os.path.join(tmp, "cal.json"), os.path.join(tmp, "applied.csv")
        for i, j in itertools.combinations(range(orient.max() + 1), 2):
            te = (orient == i) | (orient == j)
            tr = ~te
            write(train, pose[tr], w[tr], x[tr])
            write(test, pose[te], w[te], x[te])
            fit = subprocess.run([ftcal, "fit", "--in", train, "--out", cal, "--rated", rated,
                                  "--converter", "bits=10,coding=unsigned"],
                                 capture_output=True, text=True)
            if fit.returncode != 0:
                sys.exit(f"pair {i},{j}: ftcal fit failed:\n{fit.stdout}{fit.stderr}")
            app = subprocess.run([ftcal, "apply", "--cal", cal, "--in", test, "--out", applied],
                                 capture_output=True, text=True)
            if app.returncode != 0:
                sys.exit(f"pair {i},{j}: ftcal apply failed:\n{app.stdout}{app.stderr}")
            got, status = read_applied(applied)
            a = np.column_stack([x[tr], np.ones(tr.sum())])
            beta = np.linalg.lstsq(a, w[tr], rcond=None)[0]
            ref = np.column_stack([x[te], np.ones(te.sum())]) @ beta - w[te]
            ratios.append(score(got - w[te]) / score(ref))
            dev.append((i + j) % 2 == 0)
            choice = re.search(r"^choice [^:]*: (.*)$", fit.stdout, re.M)
            print(f"pair {i:2d},{j:2d}: {ratios[-1]:.3f}x  flagged rows {int((status != 0).sum())}  "
                  f"{choice.group(1) if choice else '?'}", flush=True)
    r = np.array(ratios)
    dev = np.array(dev)
    for name, part in (("development half (i + j even)", r[dev]), ("validation half (i + j odd)", r[~dev])):
        print(f"{name}: {len(part)} splits, mean {part.mean():.3f}x, median {np.median(part):.3f}x, "
              f"worst {part.max():.3f}x, {int((part > 1.08).sum())} above 1.08x")
    above = int((r > 1.08).sum())
    print(f"{len(r)} splits: mean {r.mean():.3f}x, median {np.median(r):.3f}x, worst {r.max():.3f}x, "
          f"{above} above 1.08x (targets: mean <= 0.97, worst <= 1.20, at most 3 above 1.08)")
    sys.exit(0 if r.mean() <= 0.97 and r.max() <= 1.20 and above <= 3 else 1)


if __name__ == "__main__":
    main()
