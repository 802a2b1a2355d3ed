#!/usr/bin/python3
"""The layering of lib/ as the README draws it, checked on every include.

Each folder of lib/ may include only the folders listed for it below (its own included);
CLI11 is included only by lib/tool and apps/, and only apps/ and programs include lib/tool.
usage: check-layers.py SOURCE_DIR     (exit 1 listing every include that points the wrong way)
"""
import os
import re
import sys

# Lower layers first; a folder may include what it lists (never a folder listed later).
ALLOWED = {
    "runtime": set(),
    "bullet": {"runtime"},
    "core": set(),
    "mesh": {"core"},
    "io": {"core", "mesh", "runtime"},
    "sdf": {"core", "mesh", "io"},
    "pack": {"core", "mesh", "io"},
    "posemap": {"core", "mesh", "io", "sdf", "pack"},
    "extract": {"core", "mesh", "io"},
    "metrics": {"core", "mesh", "io", "runtime", "extract"},
    "export": {"core", "mesh", "io", "extract", "metrics", "runtime"},
    "synthetic": {"core", "mesh", "io"},
    "tool": {"core"},
}
INCLUDE = re.compile(r'^\s*#\s*include\s*[<"]([^">]+)[">]')


def main():
    root = sys.argv[1]
    problems = []
    for top in ("lib", "apps", "bench", "samples", "tests"):
        for folder, _, files in os.walk(os.path.join(root, top)):
            for name in files:
                if not name.endswith((".cpp", ".hpp", ".h")):
                    continue
                path = os.path.join(folder, name)
                rel = os.path.relpath(path, root)
                layer = rel.split(os.sep)[1] if top == "lib" else None
                for number, line in enumerate(open(path, encoding="utf-8", errors="replace"), 1):
                    m = INCLUDE.match(line)
                    if not m:
                        continue
                    target = m.group(1)
                    where = "%s:%d: %s" % (rel, number, target)
                    if target.startswith("CLI/") and not (rel.startswith("lib/tool/") or top == "apps"):
                        problems.append(where + " (CLI11 belongs to apps/ and lib/tool)")
                    if layer is None:
                        continue
                    if layer not in ALLOWED:
                        problems.append("%s: lib/%s is not in the layering" % (rel, layer))
                        break
                    head = target.split("/")[0] if "/" in target else None
                    if head in ALLOWED and head != layer and head not in ALLOWED[layer]:
                        problems.append(where + " (lib/%s may not include lib/%s)" % (layer, head))
    for p in problems:
        print("check-layers: " + p)
    print("%d passed, %d failed" % (0 if problems else 1, 1 if problems else 0))
    return 1 if problems else 0


sys.exit(main())
