#!/usr/bin/python3
"""One job per file, short functions, headers that say what they offer.

Checks lib/ and samples/: no .cpp in lib/ over 500 lines; no function over 80 lines (a
definition is a line ending in '{' with a parameter list, counted to its matching brace);
every header in lib/ opens (after #pragma once) with a comment.
usage: check-sizes.py SOURCE_DIR     (exit 1 listing every breach)
"""
import os
import re
import sys

MAX_FILE, MAX_FUNCTION = 500, 80
CONTROL = re.compile(r"^\s*(if|for|while|switch|else|do|try|catch|namespace|class|struct|enum|union|return)\b")


def functions(lines):
    """(first line, length, text) of each function definition."""
    out = []
    for i, line in enumerate(lines):
        s = line.rstrip()
        if not s.endswith("{") or CONTROL.match(s) or s.lstrip().startswith("["):
            continue
        if not ("(" in s or s.endswith(") {") or s.endswith(") const {")):
            continue
        if "=" in s.split("(")[0] or " = [" in s or "](" in s:
            continue  # a lambda or an initialiser
        depth = 0
        for j in range(i, len(lines)):
            depth += lines[j].count("{") - lines[j].count("}")
            if depth <= 0:
                break
        out.append((i + 1, j - i + 1, s.strip()))
    return out


def main(root):
    problems = []
    for top in ("lib", "samples"):
        for folder, _, files in os.walk(os.path.join(root, top)):
            for name in sorted(files):
                path = os.path.join(folder, name)
                rel = os.path.relpath(path, root)
                if not name.endswith((".cpp", ".hpp", ".h")):
                    continue
                lines = open(path, encoding="utf-8", errors="replace").read().split("\n")
                if top == "lib" and name.endswith(".cpp") and len(lines) - 1 > MAX_FILE:
                    problems.append(f"{rel}: {len(lines) - 1} lines (at most {MAX_FILE})")
                if top == "lib" and name.endswith((".hpp", ".h")):
                    second = lines[1].strip() if len(lines) > 1 else ""
                    if lines[0].strip() == "#pragma once" and not second.startswith("//"):
                        problems.append(f"{rel}: the header does not open with a comment saying what it offers")
                for first, length, text in functions(lines):
                    if length > MAX_FUNCTION:
                        problems.append(f"{rel}:{first}: a function of {length} lines (at most {MAX_FUNCTION}): {text[:60]}")
    for p in problems:
        print(p)
    print(f"{len(problems)} breaches")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1]))
