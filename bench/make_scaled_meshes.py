#!/usr/bin/env python3
"""Writes transformed copies of closed OFF meshes into bench/scaled-data/ (not committed): the
same surface scaled by 1e-5 and 1e5 about its centroid, moved a few million units from the origin,
stretched 20 times along z, flattened to 1/20 along z, and the same triangles as a binary STL
(in single precision: a triangle soup the reader must weld). A map should not care about the first three; the last
three are shapes and files users make (first run 2026-12-06, thirty-third session; bench/unseen.md
has the results).

  python3 bench/make_scaled_meshes.py ../shared/data/dev/elk.off ../shared/data/dev/eight.off
  build/polycube map bench/scaled-data/elk_flat.off -o out
"""
import os
import struct
import sys

from make_cad_meshes import write as write_off


def read_off(path):
    """Vertices and faces of an OFF file (comments and blank lines skipped)."""
    with open(path) as f:
        words = []
        for line in f:
            line = line.split("#", 1)[0].strip()
            if line:
                words.extend(line.split())
    if not words or words[0] != "OFF":
        raise SystemExit(path + ": not a plain OFF file (no COFF, NOFF or 4OFF)")
    words = words[1:]
    nv, nf = int(words[0]), int(words[1])
    at = 3
    vertices = []
    for _ in range(nv):
        vertices.append(tuple(float(x) for x in words[at:at + 3]))
        at += 3
    faces = []
    for _ in range(nf):
        n = int(words[at])
        faces.append(tuple(int(x) for x in words[at + 1:at + 1 + n]))
        at += 1 + n
    return vertices, faces


def write_binary_stl(path, vertices, faces):
    """Polygons fanned into triangles; the normals left zero (readers recompute them)."""
    triangles = [(t[0], t[k], t[k + 1]) for t in faces for k in range(1, len(t) - 1)]
    with open(path, "wb") as f:
        f.write(b"polycube bench: binary STL".ljust(80, b" "))
        f.write(struct.pack("<I", len(triangles)))
        for t in triangles:
            f.write(struct.pack("<3f", 0.0, 0.0, 0.0))
            for i in t:
                f.write(struct.pack("<3f", *vertices[i]))
            f.write(b"\0\0")


def main():
    if len(sys.argv) < 2:
        raise SystemExit(__doc__)
    out = os.path.join(os.path.dirname(os.path.abspath(__file__)), "scaled-data")
    os.makedirs(out, exist_ok=True)
    for path in sys.argv[1:]:
        name = os.path.splitext(os.path.basename(path))[0]
        vertices, faces = read_off(path)
        centre = tuple(sum(v[k] for v in vertices) / len(vertices) for k in range(3))
        about = lambda s: [tuple((v[k] - centre[k]) * s for k in range(3)) for v in vertices]
        variants = {
            "tiny": about(1e-5),
            "huge": about(1e5),
            "far": [(v[0] + 1e6, v[1] - 2e6, v[2] + 3e6) for v in vertices],
            "aniso": [(v[0], v[1], 20 * v[2]) for v in vertices],
            "flat": [(v[0], v[1], 0.05 * v[2]) for v in vertices],
        }
        for kind, moved in variants.items():
            write_off(os.path.join(out, "%s_%s.off" % (name, kind)), moved, faces)
        write_binary_stl(os.path.join(out, name + ".stl"), vertices, faces)
        print("wrote %d files for %s into %s" % (len(variants) + 1, name, out))


if __name__ == "__main__":
    main()
