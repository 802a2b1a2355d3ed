#!/usr/bin/python3
"""sdf-build on mutated copies of mesh files: each run must end in success or in one error line.

The libFuzzer targets (scripts/fuzz.sh) reach the project's own readers in process; this reaches
what assimp makes of a damaged file and what the tools then do with it, the way a user meets it:
a download cut short, a byte flipped, a number run into the next. Seeds: the car sample (OBJ and
its morph-target GLB, made by sample-gen), the knight (OFF) and a binary PLY from the shared data,
ASCII PLY, PLY triangle strips (ASCII and binary), both STLs and a COLLADA file written from the knight, and OBJ prisms of polygons (a
12-gon's and a heptagram's, whose ends cross themselves, with quads around). Each run mutates one seed
(bytes changed, inserted, deleted or copied, a number swapped for an extreme one, the file cut
short), writes it and runs `sdf-build IN -o OUT --resolution 32 --threads 1 -q` under a time and
a memory limit.

A run passes when it exits 0 with the field written, or exits 1-3 with exactly one `Error:` line
and no field. Anything else (a signal, an abort, a hang, a half-written field, several lines) is
kept as OUT_DIR/failed-RUN.EXT and listed; the script then exits 1.

usage: mutate-meshes.py BUILD_DIR DATA_DIR OUT_DIR [--runs N] [--seed S] [--timeout SECONDS]
"""
import math
import subprocess
import sys

import mutation_runs
from mesh_writers import collada, ply_ascii, ply_strips, stl_ascii, stl_binary

EXTREMES = [b"0", b"-1", b"2147483648", b"4294967295", b"1e39", b"nan", b"inf", b"99999999999"]
TOKENS = [b"-", b"e", b"9", b".", b" ", b"\n", b"/", b"f ", b"v ", b"3 "]


def read_off(path):
    words = open(path).read().split()
    nv, nf = int(words[1]), int(words[2])
    at = 4
    verts = [tuple(map(float, words[at + 3 * k:at + 3 * k + 3])) for k in range(nv)]
    at += 3 * nv
    faces = []
    for _ in range(nf):
        n = int(words[at])
        faces.append(tuple(map(int, words[at + 1:at + 1 + n])))
        at += 1 + n
    return verts, faces


def prism_obj(n, step):
    """A prism of polygons: the ends the n corners 2 pi step i / n (step > 1: a star), quads around."""
    lines = ["v %.6f %.6f %d" % (math.cos(2 * math.pi * step * i / n), math.sin(2 * math.pi * step * i / n), z)
             for z in (0, 1) for i in range(n)]
    lines.append("f " + " ".join(str(n - i) for i in range(n)))
    lines.append("f " + " ".join(str(n + 1 + i) for i in range(n)))
    lines += ["f %d %d %d %d" % (i + 1, (i + 1) % n + 1, n + (i + 1) % n + 1, n + i + 1) for i in range(n)]
    return ("\n".join(lines) + "\n").encode()


def doubled_faces(obj):
    """The OBJ with every face listed twice (faces doubled, as a copy left in place writes them)."""
    return obj + b"".join(line + b"\n" for line in obj.splitlines() if line.startswith(b"f "))


def both_ways(obj):
    """The OBJ with every face also listed in the other turn, from another corner (a double-sided export)."""
    return obj + b"".join(b"f " + b" ".join(line.split()[:0:-1][1:] + line.split()[-1:]) + b"\n"
                          for line in obj.splitlines() if line.startswith(b"f "))


def seeds(build, data, out):
    subprocess.run([build + "/apps/sample-gen", "car", "-o", out + "/seeds", "-q"], check=True)
    verts, faces = read_off(data + "/static/decimated-knight.off")
    return [("obj", open(out + "/seeds/rest.obj", "rb").read()),
            ("glb", open(out + "/seeds/car-morph.glb", "rb").read()),
            ("off", open(data + "/static/decimated-knight.off", "rb").read()),
            ("ply", open(data + "/broken/cube_with_fold.ply", "rb").read()),
            ("ply", ply_ascii(verts, faces)),
            ("ply", ply_strips(verts, faces, False)),
            ("ply", ply_strips(verts, faces, True)),
            ("stl", stl_binary(verts, faces)),
            ("stl", stl_ascii(verts, faces)),
            ("dae", collada(verts, faces)),
            ("obj", prism_obj(12, 1)),
            ("obj", prism_obj(7, 3)),
            ("obj", doubled_faces(prism_obj(12, 1))),
            ("obj", both_ways(prism_obj(12, 1))),
            ("stl", stl_binary(verts, faces + [tuple(reversed(f)) for f in faces]))]  # given both ways


def mutate(data, rng):
    b = bytearray(data)
    for _ in range(rng.randint(1, 8)):
        at = rng.randrange(len(b)) if b else 0
        kind = rng.random()
        if kind < 0.3 and b:
            b[at] = rng.randrange(256)
        elif kind < 0.45:
            b[at:at] = rng.choice(TOKENS + EXTREMES)
        elif kind < 0.6 and b:
            del b[at:at + rng.randint(1, 50)]
        elif kind < 0.75 and b:
            src = rng.randrange(len(b))
            b[at:at] = b[src:src + rng.randint(1, 200)]
        elif kind < 0.85:
            space = b.find(b" ", at)
            if space >= 0:
                b[space + 1:space + 1] = rng.choice(EXTREMES) + b" "
        else:
            del b[rng.randrange(len(b) + 1):]  # cut short
    return bytes(b)


def main():
    a = mutation_runs.arguments(__doc__)
    pool = seeds(a.build, a.data, a.out)

    def next_input(rng):
        ext, data = rng.choice(pool)
        return ext, mutate(data, rng), ""

    field = a.out + "/in.vdb"
    command = lambda path: ([a.build + "/apps/sdf-build", path, "-o", field, "--resolution", "32", "--threads", "1",
                             "-q"], field)
    return mutation_runs.run_all("mutate-meshes", a, next_input, command)


if __name__ == "__main__":
    sys.exit(main())
