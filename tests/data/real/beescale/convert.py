#!/usr/bin/env python3
"""Convert the Mois beescale raw log (two hive scales + temperatures, 18 days) — NOT vendored.

The file `sensorik_pure.csv` of https://github.com/bee-mois/beescale (commit
790b2b907793a53844148fa2c1dc7f9f4f9d9463, added in b4aa5e1 on 2017-03-17, sha256
7b27b29c19d1b0557d9b703eff3ef833b9368c551ea9b8fa39c4c36654d0743b) is under the GNU GPL v3, not
one of the permissive licences this repository takes test data under, so it is not copied here.
Fetch it yourself:
    git clone https://github.com/bee-mois/beescale && cd beescale && git checkout 790b2b9
    convert.py sensorik_pure.csv beescale_2017-02-27.csv [--until-h=H]
(--until-h: only the rows of the first H hours, an excerpt; 257 keeps the part before the first
wrong weight reading.)

Original columns: Date (local time, 'YYYY/MM/DD hh:mm:ss'), 'Gewicht Kiste1' (kg, 3 decimals),
'Innentemperatur' (deg C), Vin, Helligkeit (light), 'Gewicht Kiste2' (kg), 'Aussentemperatur',
and from 2017-03-06 on four more columns (humidity and temperature per hive). The scales are read
by ADS1231 24-bit converters and logged already in kg.

Written: t (s from the first row; the clock's local time, no time-zone change is assumed), the
wrench all zero (no load was changed on purpose: the boxes' weight is part of the zero), b0, b1 =
the two scales' kg times a NOMINAL 0.01 mV/V per kg (a 2 mV/V cell of 200 kg capacity; the
real cells and excitation are not stated), temp_C = 'Innentemperatur', t_out_C =
'Aussentemperatur'. Rows whose fields do not all parse as numbers (serial-line garbage in the raw
log) and blank lines are dropped and counted; their line numbers are printed.
"""

import datetime
import sys

MVV_PER_KG = 0.01  # nominal: 2 mV/V at 200 kg


def parse(path):
    kept, dropped = [], []
    with open(path, encoding="utf-8", errors="replace") as f:
        header = f.readline()
        if not header.startswith("Date,Gewicht Kiste1"):
            raise SystemExit(f"{path}:1: not the beescale header: {header.strip()!r}")
        for line_no, line in enumerate(f, start=2):
            fields = line.rstrip("\r\n").split(",")
            if len(fields) < 7:
                dropped.append(line_no)
                continue
            try:
                stamp = datetime.datetime.strptime(fields[0], "%Y/%m/%d %H:%M:%S")
                values = [float(fields[i]) for i in (1, 2, 5, 6)]
            except ValueError:
                dropped.append(line_no)
                continue
            kept.append((stamp, values))
    return kept, dropped


def main():
    args = [a for a in sys.argv[1:] if not a.startswith("--until-h=")]
    until = [float(a.split("=", 1)[1]) for a in sys.argv[1:] if a.startswith("--until-h=")]
    if len(args) != 2:
        print(__doc__)
        return 2
    kept, dropped = parse(args[0])
    t0 = kept[0][0]
    if until:
        kept = [row for row in kept if (row[0] - t0).total_seconds() < until[0] * 3600.0]
    last = None
    with open(args[1], "w", encoding="utf-8") as out:
        out.write("# source: https://github.com/bee-mois/beescale commit "
                  "790b2b907793a53844148fa2c1dc7f9f4f9d9463 sensorik_pure.csv (GPL-3.0: not "
                  "redistributed)\n")
        out.write("# bridge_unit: mV/V\n")
        out.write("# b0, b1: hive scales 1 and 2, kg x 0.01 (nominal); temp_C: Innentemperatur; "
                  "no load change (wrench zero)\n")
        out.write("t,Fx,Fy,Fz,Mx,My,Mz,b0,b1,temp_C,t_out_C\n")
        repeated = 0
        for stamp, (w1, t_in, w2, t_out) in kept:
            t = (stamp - t0).total_seconds()
            if last is not None and t <= last:
                repeated += 1  # a repeated or backward clock stamp: the format needs t increasing
                continue
            last = t
            out.write(f"{t:.0f},0,0,0,0,0,0,{w1 * MVV_PER_KG:.6g},{w2 * MVV_PER_KG:.6g},"
                      f"{t_in:g},{t_out:g}\n")
    print(f"{args[1]}: {len(kept) - repeated} rows; dropped {len(dropped)} unreadable lines "
          f"{dropped[:20]}{' ...' if len(dropped) > 20 else ''}, {repeated} non-increasing stamps")
    return 0


if __name__ == "__main__":
    sys.exit(main())
