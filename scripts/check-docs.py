#!/usr/bin/python3
"""The README and the measurement logs still say what the project has.

Checks that README.md keeps its top-level sections (an edit that drops the rest of the file
fails here, not in a reader's hands); that every relative link in it and in docs/*.md names a
file that exists, and every anchor (`#anchor`, the README's contents list, `docs/x.md#anchor`) a
heading of the file it names; and that every test the README and docs/*.md and docs/notes/*.md cite (`Suite.Name`, where Suite is a test
suite of tests/*.cpp) is a test, or the start of one's name (the docs shorten long names with
"...").
usage: check-docs.py SOURCE_DIR     (exit 1 listing every breach)
"""
import glob
import os
import re
import sys

SECTIONS = ["The two commands", "The tools", "Speed and accuracy", "Robustness", "The runtime header",
            "A host in Bullet", "Samples", "Layout and layers"]
TEST = re.compile(r"\bTEST(?:_F|_P)?\(\s*(\w+)\s*,\s*(\w+)\s*\)")
CITED = re.compile(r"\b([A-Z]\w+)\.([A-Z]\w+)\b")
# A relative link's file (empty: this one) and its anchor (empty: none).
LINK = re.compile(r"\]\(([^)#\s]*)(?:#([^)\s]+))?\)")


def anchor_of(heading):
    """The anchor GitHub gives a heading: lowercase, punctuation dropped, spaces to hyphens."""
    return re.sub(r"[^\w\- ]", "", heading.lower()).replace(" ", "-")


def tests_of(root):
    out = set()
    for path in glob.glob(os.path.join(root, "tests", "*.cpp")):
        with open(path, encoding="utf-8") as f:
            out.update(f"{a}.{b}" for a, b in TEST.findall(f.read()))
    return out


def anchors_of(path):
    """The anchors of a Markdown file's headings."""
    with open(path, encoding="utf-8") as f:
        prose = re.sub(r"^```.*?^```", "", f.read(), flags=re.M | re.S)  # a code block's "# ..." is no heading
    return {anchor_of(h) for h in re.findall(r"^#{1,6} (.*)$", prose, re.M)}


def link_breaches(root, path):
    """Each relative link of the file at path that names no file, or no heading of it."""
    out = []
    here = os.path.relpath(path, root)
    with open(path, encoding="utf-8") as f:
        text = f.read()
    for target, anchor in LINK.findall(text):
        if "://" in target:
            continue
        if target:
            linked = os.path.normpath(os.path.join(os.path.dirname(path), target))
            if not os.path.exists(linked):
                out.append(f"{here}: link to {target}, which does not exist")
                continue
        else:
            linked = path
        if anchor and linked.endswith(".md") and anchor not in anchors_of(linked):
            out.append(f"{here}: link to {target}#{anchor}, which no heading is")
    return out


def breaches(root):
    out = []
    with open(os.path.join(root, "README.md"), encoding="utf-8") as f:
        readme = f.read()
    headings = re.findall(r"^## (.*)$", readme, re.M)
    for s in SECTIONS:
        if not any(h.startswith(s) for h in headings):
            out.append(f"README.md: the section '## {s}' is missing")
    pages = [os.path.join(root, "README.md")] + sorted(glob.glob(os.path.join(root, "docs", "*.md")))
    for path in pages:
        out += link_breaches(root, path)
    tests = tests_of(root)
    suites = {t.split(".")[0] for t in tests}
    docs = pages + sorted(glob.glob(os.path.join(root, "docs", "notes", "*.md")))
    for path in docs:
        with open(path, encoding="utf-8") as f:
            text = f.read()
        for suite, name in sorted(set(CITED.findall(text))):
            cited = f"{suite}.{name}"
            if suite in suites and not any(t.startswith(cited) for t in tests):
                out.append(f"{os.path.relpath(path, root)}: cites the test {cited}, which no test is")
    return out


def main():
    root = sys.argv[1] if len(sys.argv) > 1 else "."
    found = breaches(root)
    for b in found:
        print(b)
    print(f"{len(found)} breaches")
    return 1 if found else 0


if __name__ == "__main__":
    sys.exit(main())
