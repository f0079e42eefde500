#!/usr/bin/env python3
"""size_check.py — the size rule of the developers' guide: no file over 600 lines and no function
over 120 lines (signature line to closing brace) outside tests; in diagnosis/ no function over 80
lines, in tools/ no file over 250. A lightweight brace scanner (comments,
strings and character literals stripped); a function is a brace block that follows a parameter list
and sits in namespace or class scope. Usage: .ci/size_check.py [--list] [FILES...] (default: every
tracked .cpp/.hpp outside tests/ and the EXEMPT folders). Exit 1 when a limit is exceeded."""
import re
import subprocess
import sys

MAX_FILE_LINES = 600
MAX_FUNCTION_LINES = 120
# Stricter limits where the architecture asks for them: the diagnosis's functions (its engine is
# where long functions came from) and the programs of tools/ (argument parsing only).
FOLDER_FUNCTION_LINES = {"diagnosis/": 80}
FOLDER_FILE_LINES = {"tools/": 250}
EXEMPT = ("tests/",)

TOKEN = re.compile(r'//[^\n]*|/\*.*?\*/|R"([^(]*)\(.*?\)\1"|"(?:\\.|[^"\\\n])*"|\'(?:\\.|[^\'\\\n])*\'', re.S)


def blank(match):
    text = match.group(0)
    return re.sub(r"[^\n]", " ", text)


def functions(text):
    """Yields (name, first_line, last_line) for each function body in the text."""
    code = TOKEN.sub(blank, text)
    stack = []  # entries: ("scope"|"func"|"other", start_line, name)
    last_stmt = 0  # index after the last ';', '{' or '}'
    line = 1
    for i, ch in enumerate(code):
        if ch == "\n":
            line += 1
        elif ch == "{":
            head = code[last_stmt:i]
            kind, name = classify(head, stack)
            start = line - code[last_stmt:i].lstrip().count("\n")
            stack.append((kind, start, name))
            last_stmt = i + 1
        elif ch == "}":
            if stack:
                kind, start, name = stack.pop()
                if kind == "func":
                    yield name, start, line
            last_stmt = i + 1
        elif ch == ";":
            last_stmt = i + 1


def classify(head, stack):
    inside_function = any(k in ("func", "other") for k, _, _ in stack)
    h = " ".join(head.split())
    if inside_function:
        return "other", ""
    if re.search(r"\b(namespace|class|struct|union|enum)\b", h) and "(" not in h.split("{")[0].split(":")[0]:
        return "scope", ""
    if re.search(r"^extern\s*$", h) or h.startswith('extern "'):
        return "scope", ""
    if ")" in h and not h.rstrip().endswith("="):
        m = re.search(r"([~\w:<>]+|operator\s*\S+)\s*\(", h)
        return "func", (m.group(1) if m else h[:40])
    return "other", ""


def limit_for(path, folder_limits, default):
    for folder, limit in folder_limits.items():
        if path.startswith(folder):
            return limit
    return default


def main(argv):
    files = [a for a in argv if not a.startswith("--")]
    if not files:
        files = subprocess.run(["git", "ls-files", "*.cpp", "*.hpp"], capture_output=True, text=True,
                               check=True).stdout.split()
        files = [f for f in files if not f.startswith(EXEMPT)]
    bad = 0
    for path in files:
        with open(path, encoding="utf-8") as f:
            text = f.read()
        n = text.count("\n")
        file_limit = limit_for(path, FOLDER_FILE_LINES, MAX_FILE_LINES)
        function_limit = limit_for(path, FOLDER_FUNCTION_LINES, MAX_FUNCTION_LINES)
        if n > file_limit:
            print(f"{path}: file has {n} lines (limit {file_limit})")
            bad += 1
        for name, first, last in functions(text):
            length = last - first + 1
            if length > function_limit:
                print(f"{path}:{first}: function {name} has {length} lines (limit {function_limit})")
                bad += 1
    print(f"size_check: {len(files)} files, {bad} over the limits", file=sys.stderr)
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
