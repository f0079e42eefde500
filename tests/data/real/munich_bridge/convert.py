#!/usr/bin/env python3
"""Convert the Munich test-bridge load tests (strain gauge + support forces + air temperature).

Reads the archives vendored unchanged beside this script (imcs-compsim/munich-bridge-data) and
writes one recording per load test in the ftstack recording format:

  t        seconds from the test's first time stamp (the logger's own 100 Hz stamps)
  Fz       the summed reaction of the two force-measured supports, FRC-01 + FRC-02, in N
           (the reference: the bridge's load as the supports feel it)
  b0       the strain gauge DMS_CN, converted from um/m to mV/V as a quarter bridge with gauge
           factor 2.0 (1 um/m = 0.5e-3 mV/V); the real bridge circuit and gauge factor are not
           stated in the repository, so the scale is nominal (the diagnosis compares against a
           simulation made from the same column, so only the offset and gain depend on it)
  temp_C   the site's air temperature (1 Hz, 0.1 K steps), linearly interpolated onto t; it is
           air, not the gauge body
  frc01_kn, frc02_kn  the two support forces unchanged (kN), kept for the analysis

The archives' inner files are plain CSV despite their `.csv.zip` names (one zip layer only).
The time stamps say 2022-11-04, the file names and the temperature log 11.04.2022: the day and
month were swapped by the authors' export; only the time of day is used.

Usage: convert.py OUTDIR [--test load_01|load_02]   (default: both)
       convert.py --check   (convert into a temporary folder and compare every written row with
                             the archives read again by the csv module, row by row)
"""

import argparse
import csv
import io
import os
import sys
import tempfile
import zipfile

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
SOURCE_REPO = "https://github.com/imcs-compsim/munich-bridge-data"
SOURCE_COMMIT = "f1057c128065d7ded49e59768091b5534fdf801e"
MVV_PER_UM_M = 2.0 / 4.0 * 1e-3  # quarter bridge, gauge factor 2: dV/V = k*eps/4
TESTS = {
    "load_01": ("UniBw_2022-04-11_support_load_01", "UniBw_2022-04-11_support_load_01.csv"),
    "load_02": ("UniBw_2022-04-11_support_load_02", "UniBw_2022-04-11_support_load_02.csv"),
}


def read_zipped_text(archive, member=None):
    with zipfile.ZipFile(os.path.join(HERE, archive)) as z:
        names = z.namelist()
        name = member if member is not None else names[0]
        return z.read(name).decode("cp1252")


def seconds_of_day(stamp):
    """'2022-11-04 09:20:05.375' or '11.04.2022 09:20:05.818' -> seconds since midnight."""
    clock = stamp.strip().split(" ")[-1]
    h, m, s = clock.split(":")
    return int(h) * 3600.0 + int(m) * 60.0 + float(s)


def parse_columns(text, where):
    lines = [ln for ln in text.splitlines() if ln.strip()]
    rows_t, rows_v = [], []
    for number, line in enumerate(lines[1:], start=2):
        fields = [f for f in line.split(",") if f != ""]
        try:
            rows_t.append(seconds_of_day(fields[0]))
            rows_v.append([float(f) for f in fields[1:]])
        except (ValueError, IndexError) as err:
            raise SystemExit(f"{where}:{number}: cannot read '{line}': {err}")
    values = np.array(rows_v)
    if not np.all(np.isfinite(values)):
        raise SystemExit(f"{where}: a value is not finite")
    return lines[0], np.array(rows_t), values


def load_test(key):
    stem, temp_member = TESTS[key]
    _, t_dms, dms = parse_columns(read_zipped_text(stem + "DMS_CNAt100Hz.csv.zip"), stem + " DMS")
    _, t_frc, frc = parse_columns(read_zipped_text(stem + "ForceAt100Hz.csv.zip"), stem + " Force")
    _, t_air, air = parse_columns(read_zipped_text("TemperatureData2022-04-11.zip", temp_member),
                                  temp_member)
    if len(t_dms) != len(t_frc) or np.max(np.abs(t_dms - t_frc)) > 1e-6:
        raise SystemExit(f"{stem}: strain and force time stamps differ")
    if not np.all(np.diff(t_dms) > 0):
        raise SystemExit(f"{stem}: time stamps are not increasing")
    t0 = t_dms[0]
    temp = np.interp(t_dms, t_air, air[:, 0])
    return {
        "t": t_dms - t0,
        "Fz": (frc[:, 0] + frc[:, 1]) * 1000.0,
        "b0": dms[:, 0] * MVV_PER_UM_M,
        "temp_C": temp,
        "frc01_kn": frc[:, 0],
        "frc02_kn": frc[:, 1],
        "air_span_s": (t_air[0] - t0, t_air[-1] - t0),
    }


def write(path, key, rec):
    names = ["t", "Fx", "Fy", "Fz", "Mx", "My", "Mz", "b0", "temp_C", "frc01_kn", "frc02_kn"]
    zeros = "0,0"
    with open(path, "w", encoding="utf-8") as out:
        out.write(f"# source: {SOURCE_REPO} commit {SOURCE_COMMIT}, {TESTS[key][0]}\n")
        out.write("# bridge_unit: mV/V\n")
        out.write("# b0: strain gauge DMS_CN, um/m x 0.5e-3 (quarter bridge, gauge factor 2.0 "
                  "assumed)\n")
        out.write("# Fz: FRC-01 + FRC-02 support reactions, N; temp_C: air temperature\n")
        out.write(",".join(names) + "\n")
        for i in range(len(rec["t"])):
            out.write(f"{rec['t'][i]:.3f},{zeros},{rec['Fz'][i]:.4f},0,0,0,"
                      f"{rec['b0'][i]:.9g},{rec['temp_C'][i]:.4f},"
                      f"{rec['frc01_kn'][i]:.9g},{rec['frc02_kn'][i]:.9g}\n")


def check():
    """Every converted row against the original rows, read here by another parser."""
    bad = 0
    with tempfile.TemporaryDirectory() as tmp:
        for key, (stem, _) in sorted(TESTS.items()):
            path = os.path.join(tmp, key + ".csv")
            write(path, key, load_test(key))
            with open(path, encoding="utf-8") as f:
                rows = [r for r in csv.reader(f) if r and not r[0].startswith("#")]
            names, rows = rows[0], rows[1:]
            strain = list(csv.reader(io.StringIO(read_zipped_text(stem + "DMS_CNAt100Hz.csv.zip"))))[1:]
            force = list(csv.reader(io.StringIO(read_zipped_text(stem + "ForceAt100Hz.csv.zip"))))[1:]
            if not len(rows) == len(strain) == len(force) == 72000:
                print(f"{key}: {len(rows)} rows written, {len(strain)} / {len(force)} in the archives")
                bad += 1
                continue
            col = {n: i for i, n in enumerate(names)}
            for i, (row, s_row, f_row) in enumerate(zip(rows, strain, force)):
                fz = (float(f_row[1]) + float(f_row[2])) * 1000.0
                b0 = float(s_row[1]) * 0.5e-3
                if (abs(float(row[col["Fz"]]) - fz) > 1e-3 or abs(float(row[col["b0"]]) - b0) > 1e-10
                        or abs(float(row[col["t"]]) - 0.01 * i) > 0.002):
                    print(f"{key}: row {i + 2} differs: {row[:8]} vs {s_row} {f_row}")
                    bad += 1
                    break
            else:
                print(f"{key}: {len(rows)} rows checked against the archives")
    return 1 if bad else 0


def main():
    if sys.argv[1:] == ["--check"]:
        return check()
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("outdir")
    parser.add_argument("--test", choices=sorted(TESTS), action="append")
    args = parser.parse_args()
    os.makedirs(args.outdir, exist_ok=True)
    for key in args.test or sorted(TESTS):
        rec = load_test(key)
        path = os.path.join(args.outdir, f"munich_bridge_{key}.csv")
        write(path, key, rec)
        print(f"{path}: {len(rec['t'])} rows, {rec['t'][-1]:.2f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
