"""A mesh (vertices, and faces as lists of vertex indices from 0) as the bytes of a file in one
format: what scripts/mutate-meshes.py seeds with and scripts/fuzz.sh seeds its corpus with."""
import struct


def ply_ascii(verts, faces):
    head = ("ply\nformat ascii 1.0\nelement vertex %d\nproperty float x\nproperty float y\nproperty float z\n"
            "element face %d\nproperty list uchar int vertex_indices\nend_header\n" % (len(verts), len(faces)))
    body = "".join("%g %g %g\n" % v for v in verts) + "".join("3 %d %d %d\n" % f for f in faces)
    return (head + body).encode()


def ply_strips(verts, faces, binary):
    """The triangles as strips of one each, restarted by -1 (a run of strips, as scanners write them)."""
    indices = []
    for f in faces:
        indices += ([-1] if indices else []) + list(f)
    head = ("ply\nformat %s 1.0\nelement vertex %d\nproperty float x\nproperty float y\nproperty float z\n"
            "element tristrips 1\nproperty list int int vertex_indices\nend_header\n"
            % ("binary_little_endian" if binary else "ascii", len(verts)))
    if binary:
        body = b"".join(struct.pack("<3f", *v) for v in verts) + struct.pack("<%di" % (len(indices) + 1), len(indices), *indices)
    else:
        body = ("".join("%g %g %g\n" % v for v in verts) + " ".join(map(str, [len(indices)] + indices)) + "\n").encode()
    return head.encode() + body


def stl_binary(verts, faces):
    out = bytearray(80) + struct.pack("<I", len(faces))
    for f in faces:
        out += struct.pack("<3f", 0, 0, 0) + b"".join(struct.pack("<3f", *verts[v]) for v in f) + b"\0\0"
    return bytes(out)


def stl_ascii(verts, faces):
    facets = "".join("facet normal 0 0 0\nouter loop\n" + "".join("vertex %g %g %g\n" % verts[v] for v in f) +
                     "endloop\nendfacet\n" for f in faces)
    return ("solid knight\n" + facets + "endsolid knight\n").encode()


def collada(verts, faces):
    floats = " ".join("%g" % c for v in verts for c in v)
    corners = " ".join("%d" % i for f in faces for i in f)
    return ("""<?xml version="1.0" encoding="utf-8"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
 <library_geometries><geometry id="g"><mesh>
  <source id="p"><float_array id="a" count="%d">%s</float_array>
   <technique_common><accessor source="#a" count="%d" stride="3">
    <param name="X" type="float"/><param name="Y" type="float"/><param name="Z" type="float"/>
   </accessor></technique_common></source>
  <vertices id="v"><input semantic="POSITION" source="#p"/></vertices>
  <triangles count="%d"><input semantic="VERTEX" source="#v" offset="0"/><p>%s</p></triangles>
 </mesh></geometry></library_geometries>
 <library_visual_scenes><visual_scene id="s"><node id="n"><instance_geometry url="#g"/></node></visual_scene>
 </library_visual_scenes>
 <scene><instance_visual_scene url="#s"/></scene>
</COLLADA>
""" % (3 * len(verts), floats, len(verts), len(faces), corners)).encode()
