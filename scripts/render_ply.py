#!/usr/bin/env python3
"""Render a binary PLY with vertex colours (as proxy-export/proxy-eval write) to a PNG.

usage: render_ply.py IN.ply OUT.png [--view side|top|front] [--size 800]
Orthographic, z-buffered, Lambert-shaded; standard library only, for quick looks and docs.
"""
import math
import struct
import sys
import zlib


def read_ply(path):
    data = open(path, "rb").read()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    header = data[:end].decode().splitlines()
    nv = nf = 0
    props = []
    current = None
    for line in header:
        w = line.split()
        if w[:2] == ["element", "vertex"]:
            nv, current = int(w[2]), "vertex"
        elif w[:2] == ["element", "face"]:
            nf, current = int(w[2]), "face"
        elif w[0] == "property" and current == "vertex":
            props.append((w[1], w[2]))
    fmt = "<" + "".join("f" if t == "float" else "B" for t, _ in props)
    size = struct.calcsize(fmt)
    names = [n for _, n in props]
    verts, cols, at = [], [], end
    for _ in range(nv):
        v = dict(zip(names, struct.unpack_from(fmt, data, at)))
        at += size
        verts.append((v["x"], v["y"], v["z"]))
        cols.append((v.get("red", 200), v.get("green", 200), v.get("blue", 200)))
    faces = []
    for _ in range(nf):
        n = data[at]
        faces.append(struct.unpack_from("<%di" % n, data, at + 1))
        at += 1 + 4 * n
    return verts, cols, faces


def render(verts, cols, faces, view, size):
    axes = {"side": (0, 2, 1), "front": (1, 2, 0), "top": (0, 1, 2)}[view]
    ax, ay, az = axes
    xs = [v[ax] for v in verts]
    ys = [v[ay] for v in verts]
    lo_x, hi_x, lo_y, hi_y = min(xs), max(xs), min(ys), max(ys)
    scale = (size - 20) / max(hi_x - lo_x, hi_y - lo_y, 1e-30)
    w, h = int((hi_x - lo_x) * scale) + 20, int((hi_y - lo_y) * scale) + 20
    img = [[(255, 255, 255)] * w for _ in range(h)]
    zbuf = [[-1e300] * w for _ in range(h)]
    light = (0.3, -0.5, 0.8)
    ln = math.sqrt(sum(c * c for c in light))
    for f in faces:
        for k in range(1, len(f) - 1):
            tri = (f[0], f[k], f[k + 1])
            p = [((verts[i][ax] - lo_x) * scale + 10, h - ((verts[i][ay] - lo_y) * scale + 10), verts[i][az]) for i in tri]
            a, b, c = (verts[i] for i in tri)
            u = [b[j] - a[j] for j in range(3)]
            v = [c[j] - a[j] for j in range(3)]
            n = (u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0])
            nn = math.sqrt(sum(x * x for x in n)) or 1
            shade = 0.35 + 0.65 * abs(sum(n[j] * light[j] for j in range(3)) / nn / ln)
            col = [sum(cols[i][j] for i in tri) / 3 * shade for j in range(3)]
            x0, x1 = max(0, int(min(q[0] for q in p))), min(w - 1, int(max(q[0] for q in p)) + 1)
            y0, y1 = max(0, int(min(q[1] for q in p))), min(h - 1, int(max(q[1] for q in p)) + 1)
            den = (p[1][1] - p[2][1]) * (p[0][0] - p[2][0]) + (p[2][0] - p[1][0]) * (p[0][1] - p[2][1])
            if abs(den) < 1e-12:
                continue
            for y in range(y0, y1 + 1):
                for x in range(x0, x1 + 1):
                    l0 = ((p[1][1] - p[2][1]) * (x - p[2][0]) + (p[2][0] - p[1][0]) * (y - p[2][1])) / den
                    l1 = ((p[2][1] - p[0][1]) * (x - p[2][0]) + (p[0][0] - p[2][0]) * (y - p[2][1])) / den
                    l2 = 1 - l0 - l1
                    if l0 < 0 or l1 < 0 or l2 < 0:
                        continue
                    z = l0 * p[0][2] + l1 * p[1][2] + l2 * p[2][2]
                    if z > zbuf[y][x]:
                        zbuf[y][x] = z
                        img[y][x] = tuple(min(255, int(cc)) for cc in col)
    return img


def write_png(path, img):
    h, w = len(img), len(img[0])
    raw = b"".join(b"\x00" + bytes(c for px in row for c in px) for row in img)
    def chunk(tag, body):
        return struct.pack(">I", len(body)) + tag + body + struct.pack(">I", zlib.crc32(tag + body) & 0xFFFFFFFF)
    png = b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0))
    png += chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b"")
    open(path, "wb").write(png)


if __name__ == "__main__":
    args = sys.argv[1:]
    view = args[args.index("--view") + 1] if "--view" in args else "side"
    size = int(args[args.index("--size") + 1]) if "--size" in args else 800
    write_png(args[1], render(*read_ply(args[0]), view, size))
