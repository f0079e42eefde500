#!/usr/bin/env python3
"""Convert the CIE 324 swing-set load-cell calibration logs into the ftstack recording format.

Reads the two files vendored unchanged beside this script and writes, next to them:
  ketter133_2024-02-14.csv   from LoadCellCalibrationData.txt (16 columns, millis timestamps)
  seesl_2024-01-22.csv       from loadCellCalData.mat (MATLAB 5 file, no timestamps)

The raw HX711 codes go to b0..b5 unchanged (declared with `# converter:`). The reference Fz is
rebuilt the way the repository's author describes the test: 10-lb dead weights hung one by one
under two load cells in series and then removed. The weights were not logged, so the number of
weights on the hanger at each row is read from the two loaded cells: their glitch-free mean,
relative to the unloaded start, divided by the author's stated scale of 1000 counts per lb and
rounded to whole 10-lb weights, with hysteresis so that a level changes only once the signal has
settled near the next whole weight. The step is placed at the sample where the signal crosses
half-way between the two levels. Fz is then the weight's gravity force, n x 10 lb x g.

Usage: convert.py [--check]   (--check: compare with the committed CSVs instead of writing)
"""

import argparse
import os
import struct
import sys
import zlib

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
LB_KG = 0.45359237
G_MPS2 = 9.80665
WEIGHT_N = 10.0 * LB_KG * G_MPS2          # one 10-lb dead weight, N
COUNTS_PER_WEIGHT = 10.0 * 1000.0         # the author's calibration note: 1 lb per 1000 codes
SOURCE_REPO = "https://github.com/mvsivaselvan/CIE324-Swing-Project"
SOURCE_COMMIT = "18a8bc8041df7cfc85d4a2a6cc8673992b795e12"
CONVERTER = "bits=24, coding=signed, gain=128, ratiometric=yes"


def read_mat_double_matrix(path, name):
    """The named real double matrix of a MATLAB level-5 file (compressed or not), as a 2-D array."""
    with open(path, "rb") as f:
        data = f.read()
    if not data[:6] == b"MATLAB" or data[126:128] != b"IM":
        raise ValueError(f"{path}: not a little-endian MATLAB 5 file")
    pos = 128
    while pos + 8 <= len(data):
        kind, size = struct.unpack_from("<II", data, pos)
        body = data[pos + 8:pos + 8 + size]
        pos = (pos + 8 + size + 7) // 8 * 8
        if kind == 15:  # miCOMPRESSED wraps one element
            body = zlib.decompress(body)
            kind, size = struct.unpack_from("<II", body, 0)
            body = body[8:8 + size]
        if kind != 14:  # miMATRIX
            continue
        subs = []
        q = 0
        while q + 8 <= len(body):
            tag, sub_size = struct.unpack_from("<II", body, q)
            if tag >> 16:  # small data element: size and type share the first word
                sub_size, tag = tag >> 16, tag & 0xFFFF
                subs.append((tag, body[q + 4:q + 4 + sub_size]))
                q += 8
            else:
                subs.append((tag, body[q + 8:q + 8 + sub_size]))
                q = (q + 8 + sub_size + 7) // 8 * 8
        flags = struct.unpack_from("<I", subs[0][1], 0)[0]
        dims = np.frombuffer(subs[1][1], dtype="<i4")
        if subs[2][1].decode() != name:
            continue
        if flags & 0xFF != 6 or flags & 0x800 or len(dims) != 2:  # mxDOUBLE_CLASS, real, 2-D
            raise ValueError(f"{path}: {name} is not a real 2-D double matrix")
        dtypes = {9: "<f8", 7: "<f4", 5: "<i4", 6: "<u4", 3: "<i2", 4: "<u2", 1: "<i1", 2: "<u1"}
        values = np.frombuffer(subs[3][1], dtype=dtypes[subs[3][0]]).astype(float)
        return values.reshape(dims[::-1]).T  # MATLAB stores column-major
    raise ValueError(f"{path}: no matrix named {name}")


def median5(x):
    """Running median over 5 samples (edges repeated): removes isolated converter glitches."""
    padded = np.pad(x, (2, 2), mode="edge")
    return np.median(np.lib.stride_tricks.sliding_window_view(padded, 5), axis=1)


def weights_on_hanger(loaded_counts):
    """Whole number of 10-lb weights per row, from the loaded cells' codes (rows x cells)."""
    clean = np.mean([median5(c) for c in loaded_counts.T], axis=0)
    n_raw = (clean - np.median(clean[:50])) / COUNTS_PER_WEIGHT
    n = np.zeros(len(n_raw), dtype=int)
    level = 0
    last_settled = 0
    for i, v in enumerate(n_raw):
        nearest = int(round(v))
        if nearest != level and abs(v - nearest) < 0.15:
            # Settled on a new whole weight: the change happened at the half-way crossing.
            half = 0.5 * (level + nearest)
            seg = n_raw[last_settled:i + 1]
            crossed = np.nonzero(np.sign(seg - half) != np.sign(seg[0] - half))[0]
            start = last_settled + (int(crossed[0]) if len(crossed) else i - last_settled)
            n[start:] = nearest
            level = nearest
        if abs(v - level) < 0.15:
            last_settled = i
    return n


def write_recording(path, t_s, codes, n_weights, header_lines):
    fz = n_weights * WEIGHT_N
    cols = ["t", "Fx", "Fy", "Fz", "Mx", "My", "Mz"] + [f"b{i}" for i in range(codes.shape[1])]
    lines = [f"# {h}" for h in header_lines] + [",".join(cols)]
    for i in range(len(t_s)):
        row = [f"{t_s[i]:.3f}", "0", "0", f"{fz[i]:.4f}", "0", "0", "0"]
        row += [str(int(v)) for v in codes[i]]
        lines.append(",".join(row))
    return "\n".join(lines) + "\n"


def convert_ketter():
    raw = np.loadtxt(os.path.join(HERE, "LoadCellCalibrationData.txt"), delimiter=",")
    t_s = (raw[:, 0] - raw[0, 0]) / 1000.0
    codes = raw[:, 10:16]
    n = weights_on_hanger(codes[:, :2])
    header = [
        f"source: {SOURCE_REPO} commit {SOURCE_COMMIT}, calibration/LoadCellCalibrationData.txt (MIT)",
        "setup: two load cells in series (b0, b1) with 10-lb dead weights hung by hand and removed; "
        "b2..b5 are the swing frame's other HX711 channels, not loaded by this test",
        f"converter: {CONVERTER}",
        "reference: Fz = weights on the hanger x 10 lb x 9.80665 m/s^2 (N, tension positive); the "
        "count of weights is read from b0,b1 (see convert.py), the hanger's own weight is not included",
        "time: Arduino millis() of each row, from the first row",
    ]
    return write_recording(os.path.join(HERE, "ketter133_2024-02-14.csv"), t_s, codes, n, header), n


def convert_seesl():
    raw = read_mat_double_matrix(os.path.join(HERE, "loadCellCalData.mat"), "acquiredData")
    codes = raw[:, 3:5]
    t_s = np.arange(len(codes)) * 0.1
    n = weights_on_hanger(codes)
    header = [
        f"source: {SOURCE_REPO} commit {SOURCE_COMMIT}, calibration/loadCellCalData.mat (MIT)",
        "setup: two load cells in series (b0, b1) with 10-lb dead weights hung by hand and removed "
        "(earlier breadboard logger)",
        f"converter: {CONVERTER}",
        "reference: Fz = weights on the hanger x 10 lb x 9.80665 m/s^2 (N, tension positive); the "
        "count of weights is read from b0,b1 (see convert.py), the hanger's own weight is not included",
        "time: NOT RECORDED. t is the row number x 0.1 s (the logger waited 100 ms between reads); "
        "the true period lies between about 0.1 and 0.2 s, so frequencies and time constants in "
        "this file are known only to within a factor of up to 2",
    ]
    return write_recording(os.path.join(HERE, "seesl_2024-01-22.csv"), t_s, codes, n, header), n


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--check", action="store_true",
                        help="compare with the committed CSVs instead of writing them")
    args = parser.parse_args()
    status = 0
    for name, (text, n) in (("ketter133_2024-02-14.csv", convert_ketter()),
                            ("seesl_2024-01-22.csv", convert_seesl())):
        path = os.path.join(HERE, name)
        levels = [int(v) for v in n[np.r_[True, np.diff(n) != 0]]]
        if args.check:
            with open(path) as f:
                same = f.read() == text
            print(f"{name}: {'same' if same else 'DIFFERS'}; weights sequence {levels}")
            status |= 0 if same else 1
        else:
            with open(path, "w") as f:
                f.write(text)
            rows = sum(1 for line in text.splitlines() if not line.startswith("#")) - 1
            print(f"wrote {name}: {rows} rows; weights sequence {levels}")
    return status


if __name__ == "__main__":
    sys.exit(main())
