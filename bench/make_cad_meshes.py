#!/usr/bin/env python3
"""Writes small CAD-like closed meshes into bench/cad-data/ (not committed): meshed as CAD
exports are (one quad per flat side along its whole length, caps by strips or fans), no one tuned
polycube on them (first run 2026-12-06, thirty-second session; bench/map.md has the results).

  python3 bench/make_cad_meshes.py
  build/polycube quad bench/cad-data/pipe.off -o pipe.obj        # or map, or quad_bench.py
"""
import math
import os


def write(path, vertices, faces):
    with open(path, "w") as f:
        f.write("OFF\n%d %d 0\n" % (len(vertices), len(faces)))
        for v in vertices:
            f.write("%.17g %.17g %.17g\n" % v)
        for t in faces:
            f.write("%d %s\n" % (len(t), " ".join(str(i) for i in t)))


def quad(faces, a, b, c, d):
    """A quad a, b, c, d counter-clockwise seen from outside, as two triangles."""
    faces.append((a, b, c))
    faces.append((a, c, d))


def pipe(outer, inner, length, sides):
    """A thin-walled pipe along z (genus 1): each wall one quad per side along its length, each end
    an annulus one quad wide."""
    vertices, faces = [], []
    for radius in (outer, inner):
        for z in (0.0, length):
            for k in range(sides):
                t = 2 * math.pi * k / sides
                vertices.append((radius * math.cos(t), radius * math.sin(t), z))

    def at(wall, top, k):
        return (wall * 2 + top) * sides + k % sides

    for k in range(sides):
        quad(faces, at(0, 0, k), at(0, 0, k + 1), at(0, 1, k + 1), at(0, 1, k))  # outer wall
        a, b, c, d = at(1, 0, k), at(1, 0, k + 1), at(1, 1, k + 1), at(1, 1, k)
        faces += [(a, c, b), (a, d, c)]  # inner wall, facing the axis
        quad(faces, at(0, 1, k), at(0, 1, k + 1), at(1, 1, k + 1), at(1, 1, k))  # end at z = length
        a, b, c, d = at(0, 0, k), at(0, 0, k + 1), at(1, 0, k + 1), at(1, 0, k)
        faces += [(a, c, b), (a, d, c)]  # end at z = 0, facing down
    return vertices, faces


def box(x, y, z):
    vertices = [(i * x, j * y, k * z) for i in (0, 1) for j in (0, 1) for k in (0, 1)]  # index 4i + 2j + k
    faces = []
    for q in ((0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)):
        quad(faces, *q)
    return vertices, faces


def bracket(wall, height):
    """An L-shaped prism: legs of length 1 and thickness wall, extruded by height; caps fanned."""
    outline = [(0, 0), (1, 0), (1, wall), (wall, wall), (wall, 1), (0, 1)]
    n = len(outline)
    vertices = [(x, y, 0.0) for x, y in outline] + [(x, y, height) for x, y in outline]
    faces = []
    for k in range(n):
        quad(faces, k, (k + 1) % n, n + (k + 1) % n, n + k)
    for a, b, c in ((0, 1, 2), (0, 2, 3), (0, 3, 4), (0, 4, 5)):
        faces.append((a, c, b))
        faces.append((n + a, n + b, n + c))
    return vertices, faces


def square_tube(side, wall, height):
    """A square tube along z (genus 1)."""
    outer = [(0, 0), (side, 0), (side, side), (0, side)]
    inner = [(wall, wall), (side - wall, wall), (side - wall, side - wall), (wall, side - wall)]
    vertices = []
    for z in (0.0, height):
        vertices += [(x, y, z) for x, y in outer] + [(x, y, z) for x, y in inner]

    def o(top, k):
        return top * 8 + k % 4

    def i(top, k):
        return top * 8 + 4 + k % 4

    faces = []
    for k in range(4):
        quad(faces, o(0, k), o(0, k + 1), o(1, k + 1), o(1, k))
        quad(faces, i(0, k), i(1, k), i(1, k + 1), i(0, k + 1))
        quad(faces, o(1, k), o(1, k + 1), i(1, k + 1), i(1, k))
        quad(faces, o(0, k), i(0, k), i(0, k + 1), o(0, k + 1))
    return vertices, faces


def open_box(side, wall, height):
    """A box with a cavity open at the top (genus 0)."""
    outer = [(0, 0), (side, 0), (side, side), (0, side)]
    inner = [(wall, wall), (side - wall, wall), (side - wall, side - wall), (wall, side - wall)]
    vertices = [(x, y, 0.0) for x, y in outer] + [(x, y, height) for x, y in outer]
    vertices += [(x, y, height) for x, y in inner] + [(x, y, wall) for x, y in inner]
    faces = []
    quad(faces, 0, 3, 2, 1)  # bottom
    for k in range(4):
        k1 = (k + 1) % 4
        quad(faces, k, k1, 4 + k1, 4 + k)  # outer side
        quad(faces, 4 + k, 4 + k1, 8 + k1, 8 + k)  # rim
        quad(faces, 8 + k, 8 + k1, 12 + k1, 12 + k)  # inner side
    quad(faces, 12, 13, 14, 15)  # the cavity's floor
    return vertices, faces


def main():
    out = os.path.join(os.path.dirname(os.path.abspath(__file__)), "cad-data")
    os.makedirs(out, exist_ok=True)
    shapes = {
        "pipe": pipe(1.0, 0.97, 2.0, 48),
        "washer": pipe(1.0, 0.5, 0.02, 48),
        "plate100": box(1.0, 1.0, 0.01),
        "plate1000": box(1.0, 1.0, 0.001),
        "bracket": bracket(0.02, 0.5),
        "square-tube": square_tube(1.0, 0.02, 1.0),
        "open-box": open_box(1.0, 0.02, 0.6),
    }
    for name, (vertices, faces) in shapes.items():
        write(os.path.join(out, name + ".off"), vertices, faces)
        print("%s: %d vertices, %d triangles" % (name, len(vertices), len(faces)))


if __name__ == "__main__":
    main()
