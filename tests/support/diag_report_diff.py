#!/usr/bin/env python3
"""Compare two ftdiag JSON reports field by field and print what moved.

Walks both reports together. Objects are matched by key; lists of objects that carry a "name"
(effects, candidates, not_claimed, findings) are matched by name (and occurrence), other lists by
position. Numbers are equal when |new - old| <= abs_tol + rel_tol * max(|old|, |new|); a list of
numbers is one row (how many elements moved and the largest relative change). A subtree present
on one side only is one row ("added" / "removed", with its number of leaves). Timing keys
(--ignore, a regular expression on the path) are skipped.

Usage:
  diag_report_diff.py OLD.json NEW.json [--rel 1e-9] [--abs 1e-15] [--markdown]
  diag_report_diff.py --tree DIR OLDNAME NEWNAME [...]   every DIR/*/OLDNAME against DIR/*/NEWNAME
Exit code: 0 every field equal within the tolerances, 1 something moved, 2 bad input.
"""

import argparse
import json
import math
import os
import re
import sys

DEFAULT_IGNORE = r"(^|\.)(elapsed_s|seconds|time_s|wall_s|cpu_s)$"


class Row:
    """One difference: the field's path, what kind of change, the old and new text, a size."""

    def __init__(self, path, kind, old, new, rel=None):
        self.path, self.kind, self.old, self.new, self.rel = path, kind, old, new, rel


def leaves(value):
    if isinstance(value, dict):
        return sum(leaves(v) for v in value.values())
    if isinstance(value, list):
        return sum(leaves(v) for v in value)
    return 1


def is_number(value):
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def short(value, width=48):
    if is_number(value):
        return f"{value:.6g}"
    if isinstance(value, (dict, list)):
        return f"<{type(value).__name__} of {leaves(value)} fields>"
    text = json.dumps(value, ensure_ascii=False)
    return text if len(text) <= width else text[: width - 1] + "…"


def text_difference(old, new, context=12, width=48):
    """The two texts from a little before their first difference, each cut to width."""
    start = 0
    while start < min(len(old), len(new)) and old[start] == new[start]:
        start += 1
    start = max(0, start - context)
    lead = "…" if start else ""
    return short(lead + old[start:], width), short(lead + new[start:], width)


def rel_change(old, new):
    scale = max(abs(old), abs(new))
    return 0.0 if scale == 0.0 else abs(new - old) / scale


class Differ:
    def __init__(self, rel_tol, abs_tol, ignore):
        self.rel_tol, self.abs_tol = rel_tol, abs_tol
        self.ignore = re.compile(ignore) if ignore else None
        self.rows, self.compared = [], 0

    def numbers_equal(self, old, new):
        if isinstance(old, float) and isinstance(new, float) and math.isnan(old) and math.isnan(new):
            return True
        return abs(new - old) <= self.abs_tol + self.rel_tol * max(abs(old), abs(new))

    def walk(self, path, old, new):
        if self.ignore and self.ignore.search(path):
            return
        if isinstance(old, dict) and isinstance(new, dict):
            self.walk_dict(path, old, new)
        elif isinstance(old, list) and isinstance(new, list):
            self.walk_list(path, old, new)
        elif is_number(old) and is_number(new):
            self.compared += 1
            if not self.numbers_equal(old, new):
                self.rows.append(Row(path, "moved", short(old), short(new), rel_change(old, new)))
        else:
            self.compared += 1
            if old != new:
                if isinstance(old, str) and isinstance(new, str):
                    self.rows.append(Row(path, "text", *text_difference(old, new)))
                else:
                    kind = "changed" if type(old) is type(new) else "type"
                    self.rows.append(Row(path, kind, short(old), short(new)))

    def walk_dict(self, path, old, new):
        for key in sorted(set(old) | set(new)):
            sub = f"{path}.{key}" if path else key
            if self.ignore and self.ignore.search(sub):
                continue
            self.walk_member(sub, old, new, key)

    def walk_member(self, sub, old, new, key):
        """One key of two mappings (a dict's, or a list's items by their key): removed, added or walked."""
        if key not in new:
            self.rows.append(Row(sub, "removed", short(old[key]), "", leaves(old[key])))
        elif key not in old:
            self.rows.append(Row(sub, "added", "", short(new[key]), leaves(new[key])))
        else:
            self.walk(sub, old[key], new[key])

    def walk_list(self, path, old, new):
        if old and new and all(is_number(v) for v in old + new) and len(old) == len(new):
            self.walk_numbers(path, old, new)
            return
        old_keys, new_keys = self.list_keys(old), self.list_keys(new)
        old_map, new_map = dict(zip(old_keys, old)), dict(zip(new_keys, new))
        for key in old_keys + [k for k in new_keys if k not in old_map]:
            sub = f"{path}[{key}]"
            self.walk_member(sub, old_map, new_map, key)
        if [k for k in old_keys if k in new_map] != [k for k in new_keys if k in old_map]:
            self.rows.append(Row(path, "order", " ".join(old_keys), " ".join(new_keys)))

    def walk_numbers(self, path, old, new):
        self.compared += len(old)
        moved = [i for i, (a, b) in enumerate(zip(old, new)) if not self.numbers_equal(a, b)]
        if moved:
            worst = max(moved, key=lambda i: rel_change(old[i], new[i]))
            self.rows.append(Row(f"{path}[{worst}]", f"moved {len(moved)}/{len(old)}", short(old[worst]),
                                 short(new[worst]), rel_change(old[worst], new[worst])))

    @staticmethod
    def list_keys(items):
        named = items and all(isinstance(v, dict) and isinstance(v.get("name"), str) for v in items)
        if not named:
            return [str(i) for i in range(len(items))]
        seen, keys = {}, []
        for v in items:
            n = seen.get(v["name"], 0)
            seen[v["name"]] = n + 1
            keys.append(v["name"] if n == 0 else f"{v['name']}#{n + 1}")
        return keys


def compare(old, new, rel_tol, abs_tol, ignore):
    d = Differ(rel_tol, abs_tol, ignore)
    d.walk("", old, new)
    return d


def claims(report):
    return "+".join(e.get("name", "?") for e in report.get("effects", [])) or "-"


def headline(old, new):
    """The figures a reader looks at first: verdict, claims, held-out RMS before -> after."""
    def holdout(r):
        h = r.get("holdout", {})
        return f"{h.get('rms_after', float('nan')):.4g}" if h else "-"
    return (f"verdict {old.get('verdict')} -> {new.get('verdict')}; claims {claims(old)} -> {claims(new)}; "
            f"held-out RMS after {holdout(old)} -> {holdout(new)}")


def print_rows(rows, markdown, limit, out):
    shown = rows[:limit] if limit else rows
    if markdown:
        out.write("| field | change | old | new | rel. change |\n|---|---|---|---|---|\n")
    for r in shown:
        rel = "" if r.rel is None else (f"{r.rel:.2e}" if isinstance(r.rel, float) else f"{r.rel} fields")
        cells = (r.path, r.kind, r.old, r.new, rel)
        if markdown:
            out.write("| " + " | ".join(c.replace("|", "\\|") for c in cells) + " |\n")
        else:
            out.write(f"  {r.path:<60} {r.kind:<11} {r.old:>14} -> {r.new:<14} {rel}\n")
    if len(rows) > len(shown):
        out.write(f"  … {len(rows) - len(shown)} more\n")


def load(path):
    try:
        with open(path, encoding="utf-8") as f:
            return json.load(f)
    except (OSError, json.JSONDecodeError) as err:
        sys.stderr.write(f"diag_report_diff: {path}: {err}\n")
        sys.exit(2)


def run_pair(old_path, new_path, args, out, label=None):
    old, new = load(old_path), load(new_path)
    d = compare(old, new, args.rel, args.abs, args.ignore)
    name = label or f"{old_path} -> {new_path}"
    out.write(f"== {name}: {d.compared} fields compared, {len(d.rows)} differ; {headline(old, new)}\n")
    print_rows(d.rows, args.markdown, args.max_rows, out)
    return d


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("old", nargs="?")
    p.add_argument("new", nargs="?")
    p.add_argument("--tree", nargs=3, metavar=("DIR", "OLDNAME", "NEWNAME"))
    p.add_argument("--rel", type=float, default=1e-9, help="relative tolerance (default 1e-9)")
    p.add_argument("--abs", type=float, default=1e-15, help="absolute tolerance (default 1e-15)")
    p.add_argument("--ignore", default=DEFAULT_IGNORE, help="regex of field paths to skip")
    p.add_argument("--markdown", action="store_true", help="rows as a Markdown table")
    p.add_argument("--max-rows", type=int, default=0, help="rows shown per report (0: all)")
    args = p.parse_args(argv)
    out = sys.stdout
    if args.tree:
        root, old_name, new_name = args.tree
        moved = 0
        for sub in sorted(os.listdir(root)):
            o, n = os.path.join(root, sub, old_name), os.path.join(root, sub, new_name)
            if os.path.isfile(o) and os.path.isfile(n):
                moved += bool(run_pair(o, n, args, out, label=sub).rows)
        out.write(f"{moved} report(s) differ\n")
        return 1 if moved else 0
    if not (args.old and args.new):
        p.error("give OLD.json NEW.json or --tree DIR OLDNAME NEWNAME")
    return 1 if run_pair(args.old, args.new, args, out).rows else 0


if __name__ == "__main__":
    sys.exit(main())
