#!/usr/bin/env python3
"""ftdiag's typed `parameters` on real and generated recordings: every key of every effect's,
finding's `params` has an entry (and every candidate's entry) with key, unit, value, sigma, range, spread and
status, and its unit is the effect vocabulary's. No claimed effect carries a parameter whose
status is not resolved (or chosen), and a candidate that carries one is not resolved.

The reference for the units is the vocabulary's source (measurement/effect_vocabulary.hpp), read
here with a regular expression, not ftdiag's writer. Recordings: the vendored real files
(tests/data/real/cie324_swing) and two seeds of the independent generator.

Usage: diag_parameters_test.py FTDIAG
"""

import os
import re
import sys
import tempfile

sys.dont_write_bytecode = True
HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
REAL = os.path.join(ROOT, "tests", "data", "real", "cie324_swing")
sys.path.insert(0, os.path.join(ROOT, "tests", "support"))
from ftdiag_runs import diagnose, generate  # noqa: E402

FIELDS = ("key", "unit", "value", "sigma", "range", "spread", "status")
STATUSES = {"resolved", "at_bound", "pieces_disagree", "not_identified", "chosen"}


def vocabulary_units():
    """{effect name: {key: unit}} from the vocabulary's source."""
    with open(os.path.join(ROOT, "measurement", "effect_vocabulary.hpp"), encoding="utf-8") as f:
        text = f.read()
    arrays = dict(re.findall(r"inline constexpr std::array k(\w+) = \{(.*?)\};", text, re.S))
    channels = re.search(r'kChannels = \{\s*"channels", T::\w+, "([^"]*)"', text).group(1)
    units = {}
    for camel, body in arrays.items():
        name = re.sub(r"(?<!^)([A-Z])", r"_\1", camel).lower()
        keys = dict(re.findall(r'P\{"(\w+)",\s*T::\w+,\s*"([^"]*)"', body))
        if re.search(r"\bkChannels\b", body):
            keys.setdefault("channels", channels)
        units[name] = keys
    return units


def check(report, what, units, failures):
    checked = 0
    for section in ("effects", "candidates", "findings"):
        for e in report.get(section, []):
            typed = {p["key"]: p for p in e.get("parameters", [])}
            vocab = units.get(e["name"], {})
            # A candidate carries only `parameters` (its params stay in the engine): each entry
            # is checked for its fields and unit.
            params = e["params"] if "params" in e else {k: p["value"] for k, p in typed.items()}
            for key, value in params.items():
                p = typed.get(key)
                where = f"{what}: {section} {e['name']}.{key}"
                if p is None:
                    failures.append(f"{where} has no parameters entry")
                    continue
                missing = [f for f in FIELDS if f not in p]
                if missing:
                    failures.append(f"{where} lacks {missing}")
                if key not in vocab:
                    failures.append(f"{where} is not in the vocabulary")
                elif p.get("unit") != vocab[key]:
                    failures.append(f"{where} unit {p.get('unit')!r}, vocabulary {vocab[key]!r}")
                if p.get("value") != value:
                    failures.append(f"{where} value {p.get('value')!r} != params {value!r}")
                if p.get("status") not in STATUSES:
                    failures.append(f"{where} status {p.get('status')!r}")
                # The claim rule and the status are one: a claim carries no parameter that is
                # not resolved (a count or label is "chosen"); a candidate with one says why.
                unresolved = p.get("status") not in ("resolved", "chosen")
                if unresolved and section == "effects":
                    failures.append(f"{where} is claimed with status {p.get('status')!r}")
                if unresolved and section == "candidates" and not e.get("not_resolved"):
                    failures.append(f"{where} is {p.get('status')!r}, the candidate resolved")
                checked += 1
    print(f"{what}: {checked} parameters checked")
    if checked == 0:
        failures.append(f"{what}: no parameters to check")


def main():
    if len(sys.argv) != 2:
        sys.exit("usage: diag_parameters_test.py FTDIAG")
    ftdiag = sys.argv[1]
    units = vocabulary_units()
    failures = []
    with tempfile.TemporaryDirectory() as work:
        for file in sorted(f for f in os.listdir(REAL) if f.endswith(".csv")):
            report, _ = diagnose(ftdiag, os.path.join(REAL, file), work)
            check(report, file, units, failures)
        for seed in (101, 106):
            real, _ = generate(work, seed)
            report, _ = diagnose(ftdiag, real, work)
            check(report, f"generator seed {seed}", units, failures)
    for f in failures:
        print("FAIL:", f)
    sys.exit(1 if failures else 0)


if __name__ == "__main__":
    main()
