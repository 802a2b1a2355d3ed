#!/usr/bin/python3
"""Read back a binary PLY or a GLB the tools wrote, checking its structure byte for byte, and
print one JSON line of what it holds (counts, bounds of the positions).

usage: readback.py FILE.ply|FILE.glb
Exit 1, with the reason on stderr, when the file is not well formed.
"""
import json
import struct
import sys


def fail(msg):
    sys.stderr.write("readback: %s: %s\n" % (sys.argv[1], msg))
    sys.exit(1)


def bounds(points):
    if not points:
        return None
    return [[min(p[k] for p in points) for k in range(3)], [max(p[k] for p in points) for k in range(3)]]


def read_ply(data):
    end = data.find(b"end_header\n")
    if not data.startswith(b"ply\n") or end < 0:
        fail("no PLY header")
    header = data[:end].decode("ascii").split("\n")
    if "format binary_little_endian 1.0" not in header:
        fail("not binary little-endian")
    elements, current = [], None
    for line in header:
        w = line.split()
        if w and w[0] == "element":
            current = [w[1], int(w[2]), []]
            elements.append(current)
        elif w and w[0] == "property":
            current[2].append(w[1:])
    sizes = {"float": 4, "uchar": 1, "int": 4}
    fmt = {"float": "f", "uchar": "B", "int": "i"}
    at = end + len(b"end_header\n")
    out, points = {}, []
    for name, count, props in elements:
        for _ in range(count):
            row = []
            for p in props:
                if p[0] == "list":
                    n = data[at]
                    at += 1
                    vals = struct.unpack_from("<%d%s" % (n, fmt[p[2]]), data, at)
                    at += n * sizes[p[2]]
                    if name == "face" and (n != 3 or min(vals) < 0 or max(vals) >= out.get("vertex", 0)):
                        fail("face with bad indices %s" % (vals,))
                else:
                    row.append(struct.unpack_from("<" + fmt[p[0]], data, at)[0])
                    at += sizes[p[0]]
            if name == "vertex":
                points.append(row[:3])
        out[name] = count
    if at != len(data):
        fail("%d bytes after the last element" % (len(data) - at))
    return {"vertices": out.get("vertex", 0), "faces": out.get("face", 0),
            "colors": any(p[-1] == "red" for p in elements[0][2]), "bounds": bounds(points)}


def read_glb(data):
    magic, version, length = struct.unpack_from("<4sII", data, 0)
    if magic != b"glTF" or version != 2 or length != len(data):
        fail("bad GLB header")
    n, kind = struct.unpack_from("<I4s", data, 12)
    if kind != b"JSON":
        fail("first chunk is not JSON")
    doc = json.loads(data[20:20 + n])
    at = 20 + n
    binary = b""
    if at < len(data):
        m, kind = struct.unpack_from("<I4s", data, at)
        if kind != b"BIN\0" or at + 8 + m != len(data):
            fail("bad BIN chunk")
        binary = data[at + 8:at + 8 + m]
    for view in doc.get("bufferViews", []):
        if view.get("byteOffset", 0) + view["byteLength"] > len(binary):
            fail("a bufferView runs past the binary chunk")
    positions, vertices = [], 0
    for mesh in doc.get("meshes", []):
        for prim in mesh["primitives"]:
            acc = doc["accessors"][prim["attributes"]["POSITION"]]
            view = doc["bufferViews"][acc["bufferView"]]
            start = view.get("byteOffset", 0) + acc.get("byteOffset", 0)
            stride = view.get("byteStride", 12)
            for i in range(acc["count"]):
                positions.append(struct.unpack_from("<3f", binary, start + i * stride))
            vertices += acc["count"]
    translations = [node.get("translation", [0, 0, 0]) for node in doc.get("nodes", [])]
    return {"meshes": len(doc.get("meshes", [])), "nodes": len(doc.get("nodes", [])), "vertices": vertices,
            "translations": translations, "bounds": bounds(positions)}


def main():
    data = open(sys.argv[1], "rb").read()
    print(json.dumps(read_glb(data) if sys.argv[1].endswith(".glb") else read_ply(data)))


main()
