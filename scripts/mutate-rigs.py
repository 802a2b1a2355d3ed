#!/usr/bin/python3
"""pose-extract on glTF assets changed one member or one value at a time: each run must end in
success or in one error line.

scripts/mutate-meshes.py changes a file's bytes, which in a GLB mostly breaks its JSON before any
reader goes further. This changes what a reader follows: a member of the skins, the node tree, the
clips, the meshes, the accessors and their views (an index moved by one, past its list or
negative; a list emptied, cut, lengthened or reversed; a member dropped; a name swapped for
another of glTF's), a channel's target named by a KHR_animation_pointer (its own, another
object's, a malformed one), a node given a second parent or made its own ancestor, a mesh placed
again by a node of its own (without a skin, with the same or another, or a skin past the list), or a value in the data
an accessor holds (a joint index, a weight, a position, a matrix, a key time or a key's value set
to NaN, an infinity, 0, a huge number). The file stays a well-formed GLB; what assimp and the tools
make of it is the test. Seeds: RiggedSimple and the rigged elephant from the shared data, and the
robot (skinned) and the car's morph targets written by sample-gen; each run changes one seed once
or twice, writes it and runs `pose-extract IN -o OUT -q --threads 1` with `--animation 0 --select
2` (or `--morph-targets`) under a time limit.

With `--tool sdf-build` each run is `sdf-build IN -o OUT.vdb --resolution 32 -q --threads 1`
instead: the mesh a rigged file gives where its skin places it, with the same changes. With
`--tool proxy-eval` the seeds are RiggedSimple and the car's morph targets, each first taken
through the chain (the samples Makefile at 32 cells) to its proxy, and each run is `proxy-eval
PROXY --asset IN --every 4 --chart OUT.svg` on the changed asset: the clip played as a host plays
it, by the skin or by the morph weights (it passes with the chart written and nothing said but
warnings).

A run passes when it exits 0 with poses.json (the field) written and nothing said (sdf-build may
warn), or exits 1-3 with exactly one `Error:` line and no poses.json (field). Anything else (a signal, an abort, a hang, several lines) is
kept as OUT_DIR/failed-RUN.glb and listed; the script then exits 1.

usage: mutate-rigs.py BUILD_DIR DATA_DIR OUT_DIR [--runs N] [--seed S] [--timeout SECONDS]
                      [--tool pose-extract|sdf-build|proxy-eval]
"""
import copy
import json
import os
import struct
import subprocess
import sys

import mutation_runs

COMPONENTS = {5120: ("b", 1), 5121: ("B", 1), 5122: ("h", 2), 5123: ("H", 2), 5125: ("I", 4), 5126: ("f", 4)}
WIDTH = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4, "MAT2": 4, "MAT3": 9, "MAT4": 16}
FLOATS = [float("nan"), float("inf"), -float("inf"), 0.0, -1.0, 1e38, -1e38, 1e-40, 2.0, 1e6]
WHOLE = [0, 1, 2, 24, 25, 26, 100, 255, 65535, 2 ** 31 - 1, 2 ** 32 - 1]
NAMES = ["LINEAR", "STEP", "CUBICSPLINE", "weights", "scale", "rotation", "translation", "SCALAR", "VEC3", "VEC4",
         "MAT4", "bogus", ""]
# The lists a member is changed in, those of the rig and clips twice as often.
LISTS = ["skins", "skins", "nodes", "nodes", "animations", "animations", "accessors", "bufferViews", "meshes", "scenes"]


def read_glb(path):
    b = open(path, "rb").read()
    n = struct.unpack("<I", b[12:16])[0]
    doc = json.loads(b[20:20 + n])
    at = 20 + n
    data = bytearray(b[at + 8:at + 8 + struct.unpack("<I", b[at:at + 4])[0]]) if at < len(b) else bytearray()
    return doc, data


def glb(doc, data):
    text = json.dumps(doc).encode()
    text += b" " * (-len(text) % 4)
    data = bytes(data) + b"\0" * (-len(data) % 4)
    out = struct.pack("<III", 0x46546C67, 2, 12 + 8 + len(text) + 8 + len(data))
    return out + struct.pack("<II", len(text), 0x4E4F534A) + text + struct.pack("<II", len(data), 0x004E4942) + data


def accessors_by_role(doc):
    """Accessor indices by what reads them: attributes by name, indices, targets, matrices, times, values."""
    roles = {}
    add = lambda role, a: roles.setdefault(role, []).append(a)
    for mesh in doc.get("meshes", []):
        for p in mesh.get("primitives", []):
            for name, a in p.get("attributes", {}).items():
                add(name, a)
            if "indices" in p:
                add("indices", p["indices"])
            for target in p.get("targets", []):
                for name, a in target.items():
                    add("target " + name, a)
    for skin in doc.get("skins", []):
        if "inverseBindMatrices" in skin:
            add("matrices", skin["inverseBindMatrices"])
    for clip in doc.get("animations", []):
        for s in clip.get("samplers", []):
            add("times", s["input"])
            add("values", s["output"])
    return roles


def change_value(doc, data, rng):
    """One to four components of an accessor's data set to an extreme value; what it changed, or None."""
    role, indices = rng.choice(sorted(accessors_by_role(doc).items()))
    acc = doc["accessors"][rng.choice(indices)]
    view = doc["bufferViews"][acc["bufferView"]]
    fmt, size = COMPONENTS[acc["componentType"]]
    n = WIDTH[acc["type"]]
    stride = view.get("byteStride", size * n)
    base = view.get("byteOffset", 0) + acc.get("byteOffset", 0)
    for _ in range(rng.randint(1, 4)):
        at = base + rng.randrange(acc["count"]) * stride + rng.randrange(n) * size
        if at + size > len(data):
            return None
        if fmt == "f":
            struct.pack_into("<f", data, at, rng.choice(FLOATS + ([0.5, 0.1, 100.0] if role == "times" else [])))
        else:
            v = rng.choice(WHOLE) % (1 << (8 * size))
            struct.pack_into("<" + fmt.upper(), data, at, v)
    return "a value of its " + role


def change_member(doc, rng):
    """A member somewhere in one of the document's lists changed, dropped or emptied."""
    top = rng.choice([name for name in LISTS if doc.get(name)])
    path, parent, key = [top], doc, top
    while isinstance(parent[key], (dict, list)) and parent[key] and (len(path) < 2 or rng.random() > 0.15):
        parent = parent[key]
        key = rng.choice(list(parent)) if isinstance(parent, dict) else rng.randrange(len(parent))
        path.append(key)
    old = parent[key]
    if isinstance(parent, dict) and rng.random() < 0.25:
        del parent[key]
        return "%s dropped" % path
    if isinstance(old, bool):
        new = not old
    elif isinstance(old, int):
        new = rng.choice([old + 1, old - 1, 0, -1, old * 2, 2 ** 31, len(doc.get("nodes", [])),
                          len(doc.get("accessors", []))])
    elif isinstance(old, float):
        new = rng.choice([0.0, -old, old * 1e6, 1e300])
    elif isinstance(old, str):
        new = rng.choice(NAMES)
    elif isinstance(old, list):
        new = rng.choice([[], old[:-1], old + old[:1], old[::-1]])
    else:
        new = {} if rng.random() < 0.3 or not old else {k: v for k, v in old.items() if k != rng.choice(list(old))}
    parent[key] = new
    return "%s set to %s" % (path, json.dumps(new)[:60])


def change_tree(doc, rng):
    """A node given another node as a child: a second parent, or a cycle."""
    nodes = doc.get("nodes", [])
    a, b = rng.randrange(len(nodes)), rng.randrange(len(nodes))
    nodes[a].setdefault("children", []).append(b)
    return "node %d given child %d" % (a, b)


def change_placement(doc, rng):
    """A mesh placed again by a node of its own: with no skin, the same skin or another."""
    node = {"mesh": rng.randrange(len(doc["meshes"])), "translation": [rng.choice([0, 3]), 0, 0]}
    skins = len(doc.get("skins", []))
    if skins and rng.random() < 0.6:
        node["skin"] = rng.randrange(skins + 1)
    doc["nodes"].append(node)
    doc["scenes"][doc.get("scene", 0)]["nodes"].append(len(doc["nodes"]) - 1)
    return "mesh %d placed again by a node %s" % (node["mesh"], "with skin %d" % node["skin"] if "skin" in node else "without a skin")


def change_to_pointer(doc, rng):
    """A channel's target named by KHR_animation_pointer: its own node and path, or a pointer the
    tools must pass over or refuse (another object's property, a node past the list, a malformed
    index)."""
    clip = rng.choice(doc["animations"])
    channel = rng.choice(clip["channels"])
    target = channel["target"]
    nodes = len(doc.get("nodes", []))
    pointer = rng.choice(["/nodes/%s/%s" % (target.get("node"), target.get("path")),
                          "/nodes/%d/%s" % (rng.randrange(nodes + 2), rng.choice(NAMES)),
                          "/materials/0/pbrMetallicRoughness/baseColorFactor", "/meshes/0/weights",
                          "/meshes/%d/weights" % len(doc.get("meshes", [])), "/nodes/01/rotation",
                          "/nodes/-1/scale", "/nodes/99999999999/translation", "/nodes/0", "", 7])
    channel["target"] = {"path": "pointer", "extensions": {"KHR_animation_pointer": {"pointer": pointer}}}
    return "animations' channel given the pointer %s" % json.dumps(pointer)


def mutate(doc, data, rng):
    said = []
    for _ in range(rng.randint(1, 2)):
        kind = rng.random()
        try:  # a change before may have left the document so that this one cannot be made
            said.append(change_value(doc, data, rng) if kind < 0.45 else
                        change_member(doc, rng) if kind < 0.9 else
                        change_to_pointer(doc, rng) if kind < 0.95 else
                        change_tree(doc, rng) if kind < 0.975 else change_placement(doc, rng))
        except (KeyError, IndexError, TypeError, ValueError, AttributeError):
            pass
    return [s for s in said if s]


def main():
    a = mutation_runs.arguments(__doc__, lambda ap: ap.add_argument(
        "--tool", choices=["pose-extract", "sdf-build", "proxy-eval"], default="pose-extract"))
    for sample in ("robot", "car"):
        subprocess.run([a.build + "/apps/sample-gen", sample, "-o", a.out + "/seeds/" + sample, "-q"], check=True)
    clip = ["--animation", "0", "--select", "2"]
    rigged, morph = a.data + "/rigged-simple/RiggedSimple.glb", a.out + "/seeds/car/car-morph.glb"
    seeds = [(read_glb(rigged), clip),
             (read_glb(a.data + "/elephant/elephant-rigged.glb"), clip),
             (read_glb(a.out + "/seeds/robot/robot.glb"), clip),
             (read_glb(morph), ["--morph-targets"])]
    if a.tool == "proxy-eval":  # each seed's proxy, through the chain: the run's options name it
        seeds = [(read_glb(rigged), [chain_proxy(a, "rigged", rigged, clip)]),
                 (read_glb(morph), [chain_proxy(a, "car-morph", morph, ["--morph-targets"])])]
    args = []  # the chosen seed's options, for the same run's command

    def next_input(rng):
        (doc, data), args[:] = rng.choice(seeds)
        doc, data = copy.deepcopy(doc), bytearray(data)
        said = mutate(doc, data, rng)
        return "glb", glb(doc, data), "; ".join([" ".join(args)] + said)

    # Every run into one folder, as a user's runs again: what a failed run left there is the next
    # run's to clear (the manifest, written last, is what says a run ended).
    poses = a.out + "/poses"
    command = lambda path: ([a.build + "/apps/pose-extract", path, "-o", poses, "-q", "--threads", "1"] + args,
                            poses + "/poses.json")
    if a.tool == "sdf-build":
        field = a.out + "/in.vdb"
        command = lambda path: ([a.build + "/apps/sdf-build", path, "-o", field, "--resolution", "32", "-q",
                                 "--threads", "1"], field)
    if a.tool == "proxy-eval":
        chart = a.out + "/clip.svg"
        command = lambda path: ([a.build + "/apps/proxy-eval", args[0], "--asset", path, "--every", "4", "--chart",
                                 chart, "--report", a.out + "/eval.json", "-q", "--threads", "1"], chart)
    return mutation_runs.run_all("mutate-rigs", a, next_input, command, None if a.tool == "pose-extract" else a.tool)


def chain_proxy(a, name, asset, extract_flags):
    """The proxy the samples Makefile makes of `asset` at 32 cells."""
    subprocess.run(["make", "-s", "-C", os.path.dirname(os.path.abspath(__file__)) + "/../samples",
                    "BIN=" + a.build + "/apps", "OUT=" + a.out + "/chain", "RES=32", "QUIET=1", "NAME=" + name,
                    "ASSET_FILE=" + os.path.abspath(asset), "EXTRACT_FLAGS=" + " ".join(extract_flags),
                    "%s/chain/%s/%s.proxy.json" % (a.out, name, name)], check=True)
    return "%s/chain/%s/%s.proxy.json" % (a.out, name, name)


if __name__ == "__main__":
    sys.exit(main())
