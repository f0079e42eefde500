#!/usr/bin/env python3
"""Would a few bridge products, chosen by grouped validation, help the printed sensor? (numpy only)

An analysis written apart from ftcal, on the public printed 8-bridge sensor of
github.com/jonurce/FTS_Calibration (no licence, so not vendored: pass the folder of its
Datasets/12_final_extra_bounded/data/data_*.csv files, or set FTSTACK_PRINTED_FT_DIR).

The recording is read as tests/tools/ftcal_printed_test.cpp reads it (rows with a code outside
50 ... 950 dropped, orientation = direction of the reference force within 3 degrees) and split
three ways into three held-out sets of whole orientations (o mod 3, blocks o // 4, stride
(5 o mod 12) // 4). On each training set:
- ridge-linear: standardised bridges, lambda by 8-fold cross-validation over groups of poses whose
  force directions lie within 5 degrees (the rule of docs/calibration.md);
- ridge-linear plus products: forward selection, up to 4 products x_a x_b (squares included) of
  standardised bridges, each kept only when it lowers the grouped validation score by >= 2 %.
Each is scored on the held-out orientations as RMS over axes of error / largest |load| per axis,
as a ratio to plain affine least squares. Prints one line per split and the mean and worst ratio.
"""
import glob
import itertools
import os
import sys

import numpy as np

LAMBDAS = [0, 1e-5, 1e-4, 1e-3, 3e-3, 0.01, 0.03, 0.1, 0.3, 1]
SPLITS = {"mod": lambda o: o % 3, "blocks": lambda o: o // 4, "stride5": lambda o: (5 * o) % 12 // 4}


def read(folder):
    directions, parts = [], []
    for pose, name in enumerate(sorted(glob.glob(os.path.join(folder, "data_*.csv")))):
        a = np.loadtxt(name, delimiter=",", skiprows=1, ndmin=2)
        a = a[np.all((a[:, 7:] >= 50) & (a[:, 7:] <= 950), axis=1)] if a.shape[1] == 15 else a[:0]
        if len(a) == 0:
            continue
        u = a[0, 1:4] / np.linalg.norm(a[0, 1:4])
        o = next((i for i, d in enumerate(directions) if d @ u > np.cos(np.radians(3))), -1)
        if o < 0:
            o = len(directions)
            directions.append(u)
        parts.append(np.column_stack([np.full(len(a), len(parts)), np.full(len(a), o), a[:, 1:]]))
    r = np.vstack(parts)
    return r[:, 0].astype(int), r[:, 1].astype(int), r[:, 2:8], r[:, 8:16]


def features(x, mu, sd, products):
    z = (x - mu) / sd
    return np.hstack([z] + [(z[:, a] * z[:, b])[:, None] for a, b in products])


def ridge(f, y, lam):
    m, s = f.mean(0), f.std(0)
    s[s == 0] = 1
    fs = (f - m) / s
    b = np.linalg.solve(fs.T @ fs / len(f) + lam * np.eye(f.shape[1]), fs.T @ (y - y.mean(0)) / len(f))
    return lambda g: ((g - m) / s) @ b + y.mean(0)


def pose_groups(w, pose):
    directions, out = [], np.zeros(len(pose), int)
    for p in np.unique(pose):
        m = pose == p
        u = w[m, :3].mean(0)
        u /= np.linalg.norm(u)
        g = next((i for i, d in enumerate(directions) if d @ u > np.cos(np.radians(5))), -1)
        if g < 0:
            g = len(directions)
            directions.append(u)
        out[m] = g
    return out


def grouped_cv(f, w, groups, lam, scale):
    k = min(8, groups.max() + 1)
    errs = []
    for fold in range(k):
        te = groups % k == fold
        errs.append(((ridge(f[~te], w[~te], lam)(f[te]) - w[te]) / scale) ** 2)
    return np.mean(np.vstack(errs))


def main():
    folder = sys.argv[1] if len(sys.argv) > 1 else os.environ.get("FTSTACK_PRINTED_FT_DIR", "")
    if not os.path.isdir(folder):
        sys.exit("usage: printed_product_selection.py DATA_FOLDER (or FTSTACK_PRINTED_FT_DIR)")
    pose, orient, w, x = read(folder)
    scale = np.abs(w).max(0)
    score = lambda e: np.sqrt(np.mean((e / scale) ** 2))
    pairs = list(itertools.combinations_with_replacement(range(8), 2))
    for how, split_of in SPLITS.items():
        lin, sel = [], []
        for s in range(3):
            te = np.array([split_of(o) == s for o in orient])
            tr = ~te
            xt, wt = x[tr][::5], w[tr][::5]  # every 5th row: neighbours of a static pose agree
            groups = pose_groups(wt, pose[tr][::5])
            mu, sd = xt.mean(0), xt.std(0)
            a = np.column_stack([x[tr], np.ones(tr.sum())])
            beta = np.linalg.lstsq(a, w[tr], rcond=None)[0]
            ref = score(np.column_stack([x[te], np.ones(te.sum())]) @ beta - w[te])
            cv = lambda prods, lam: grouped_cv(features(xt, mu, sd, prods), wt, groups, lam, scale)
            lam0 = min(LAMBDAS, key=lambda l: cv([], l))
            chosen, best, lam = [], cv([], lam0), lam0
            for _ in range(4):
                c = min((cv(chosen + [p], l), p, l) for p in pairs if p not in chosen
                        for l in (0.01, 0.03, 0.1, 0.3))
                if c[0] >= 0.98 * best:
                    break
                best, lam = c[0], c[2]
                chosen.append(c[1])
            err = lambda prods, l: score(
                ridge(features(x[tr], mu, sd, prods), w[tr], l)(features(x[te], mu, sd, prods)) - w[te])
            lin.append(err([], lam0) / ref)
            sel.append(err(chosen, lam) / ref)
            print(f"{how} split {s}: linear (lambda {lam0:g}) {lin[-1]:.3f}x, "
                  f"+ products {chosen} (lambda {lam:g}) {sel[-1]:.3f}x", flush=True)
        print(f"{how}: linear mean {np.mean(lin):.3f} worst {max(lin):.3f}; "
              f"+ products mean {np.mean(sel):.3f} worst {max(sel):.3f}", flush=True)


if __name__ == "__main__":
    main()
