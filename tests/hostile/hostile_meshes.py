"""The shared set of hostile meshes that every front end is tested with (tests/hostile/test_cli.py,
tests/meshlab/test_hostile.py, tests/blender/test_hostile.py). Each case is plain Python data
(vertex positions and faces as index tuples), so the Blender test builds it with from_pydata
and the file tests write it as OFF or, where text would blur the case (NaN and infinite
coordinates), as binary little-endian PLY.

  python3 hostile_meshes.py OUT_DIR     writes every case and prints its file name
"""
import math
import os
import struct
import sys


class Case:
    """A hostile mesh: `vertices` are (x, y, z) tuples, `faces` index tuples. `fmt` is the file
    format that carries it. `in_blender` is False for what a Blender mesh cannot hold at all
    (indices out of range). `defect` names, in a word or two, what a refusal must mention."""

    def __init__(self, name, description, vertices, faces, fmt="off", in_blender=True, defect=None):
        self.name = name
        self.description = description
        self.vertices = [tuple(float(x) for x in v) for v in vertices]
        self.faces = [tuple(int(i) for i in f) for f in faces]
        self.fmt = fmt
        self.in_blender = in_blender
        self.defect = defect

    @property
    def file_name(self):
        return f"{self.name}.{self.fmt}"

    @property
    def corners(self):
        return sum(len(f) for f in self.faces)


# Small building blocks -----------------------------------------------------------------------

def tetrahedron():
    v = [(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1)]
    f = [(0, 2, 1), (0, 1, 3), (0, 3, 2), (1, 2, 3)]
    return v, f


def octahedron(scale=1.0, centre=(0.0, 0.0, 0.0)):
    cx, cy, cz = centre
    v = [(cx + scale, cy, cz), (cx - scale, cy, cz), (cx, cy + scale, cz), (cx, cy - scale, cz),
         (cx, cy, cz + scale), (cx, cy, cz - scale)]
    f = [(0, 2, 4), (2, 1, 4), (1, 3, 4), (3, 0, 4), (2, 0, 5), (1, 2, 5), (3, 1, 5), (0, 3, 5)]
    return v, f


def grid(n, m, offset=(0.0, 0.0)):
    """An open n x m grid of squares in z = 0, each split into two triangles, counter-clockwise
    seen from +z."""
    ox, oy = offset
    v = [(ox + i, oy + j, 0.0) for j in range(m + 1) for i in range(n + 1)]
    f = []
    for j in range(m):
        for i in range(n):
            a = j * (n + 1) + i
            b, c, d = a + 1, a + n + 2, a + n + 1
            f += [(a, b, c), (a, c, d)]
    return v, f


def closed_cube_triangles(n):
    """A closed cube of 12 n^2 triangles, outward facing."""
    index, v, f = {}, [], []

    def vertex(p):
        if p not in index:
            index[p] = len(v)
            v.append(p)
        return index[p]

    for axis in range(3):
        for side in (0, n):
            for i in range(n):
                for j in range(n):
                    quad = []
                    for di, dj in ((0, 0), (1, 0), (1, 1), (0, 1)):
                        p = [0.0, 0.0, 0.0]
                        p[axis] = float(side)
                        p[(axis + 1) % 3] = float(i + di)
                        p[(axis + 2) % 3] = float(j + dj)
                        quad.append(vertex(tuple(p)))
                    if not side:
                        quad.reverse()
                    f += [(quad[0], quad[1], quad[2]), (quad[0], quad[2], quad[3])]
    return v, f


def joined(*parts):
    """Several (vertices, faces) parts as one mesh, indices shifted."""
    v, f = [], []
    for pv, pf in parts:
        base = len(v)
        v += list(pv)
        f += [tuple(base + i for i in face) for face in pf]
    return v, f


# The cases ------------------------------------------------------------------------------------

def _empty():
    return Case("empty", "no vertices, no faces", [], [])


def _vertices_only():
    return Case("vertices_only", "five vertices and no face", [(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1), (2, 2, 2)], [])


def _one_face():
    return Case("one_face", "a single triangle", [(0, 0, 0), (1, 0, 0), (0, 1, 0)], [(0, 1, 2)])


def _huge_polygon():
    n = 100_000
    v = [(math.cos(2 * math.pi * k / n), math.sin(2 * math.pi * k / n), 0.0) for k in range(n)]
    return Case("huge_polygon", "one face of 100,000 vertices (a circle)", v, [tuple(range(n))])


def _nan_coordinates():
    v, f = octahedron()
    v[3] = (0.0, float("nan"), 0.0)
    return Case("nan_coordinates", "an octahedron whose vertex 3 has a NaN y", v, f, fmt="ply", defect="NaN")


def _infinite_coordinates():
    v, f = octahedron()
    v[4] = (0.0, 0.0, float("inf"))
    v[5] = (0.0, 0.0, float("-inf"))
    return Case("infinite_coordinates", "an octahedron with vertex 4 at z = +inf and vertex 5 at z = -inf",
                v, f, fmt="ply", defect="infinite")


def _coincident():
    _, f = octahedron()
    return Case("coincident", "a closed octahedron whose six vertices are all at one point",
                [(0.5, 0.5, 0.5)] * 6, f)


def _zero_area():
    v, f = grid(3, 3)
    # A needle on the bottom boundary edge 1-2: (1, m, 2) with m its midpoint, collinear.
    m = len(v)
    v.append((1.5, 0.0, 0.0))
    f.append((1, m, 2))
    # A cap on the top boundary edge 12-13, its third vertex a distinct one at the place of 13.
    c = len(v)
    v.append(v[13])
    f.append((12, 13, c))
    # A lone face of three distinct vertices at one point, away from the rest.
    p = len(v)
    v += [(9.0, 9.0, 9.0)] * 3
    f.append((p, p + 1, p + 2))
    return Case("zero_area_faces", "a grid with a collinear needle, a cap with two vertices at one place, "
                "and a lone triangle of three vertices at one point", v, f)


def _many_faces_on_edge():
    # Edge 0-1 carries three triangles (a fin); edge 5-6 carries six (a book of pages).
    v = [(0, 0, 0), (1, 0, 0), (0.5, 1, 0), (0.5, -1, 0), (0.5, 0, 1)]
    f = [(0, 1, 2), (1, 0, 3), (0, 1, 4)]
    base = len(v)
    v += [(3, 0, 0), (4, 0, 0)]
    for k in range(6):
        a = 2 * math.pi * k / 6
        v.append((3.5, math.cos(a), math.sin(a)))
        f.append((base, base + 1, base + 2 + k) if k % 2 == 0 else (base + 1, base, base + 2 + k))
    return Case("many_faces_on_edge", "three triangles on one edge and six on another", v, f)


def _bow_tie():
    # Two triangles sharing only vertex 0, and two open square pyramids (fans) touching at
    # their apex 5.
    v = [(0, 0, 0), (1, 1, 0), (-1, 1, 0), (1, -1, 0), (-1, -1, 0)]
    f = [(0, 1, 2), (0, 4, 3)]
    apex = len(v)
    v.append((5, 0, 0))
    for z in (1.0, -1.0):
        ring = len(v)
        v += [(5 + x, y, z) for x, y in ((1, 0), (0, 1), (-1, 0), (0, -1))]
        for k in range(4):
            a, b = ring + k, ring + (k + 1) % 4
            f.append((apex, a, b) if z > 0 else (apex, b, a))
    return Case("bow_tie", "two triangles meeting at one vertex, two cones meeting at their apex", v, f)


def _inconsistent_orientation():
    v, f = closed_cube_triangles(2)
    f = [face[::-1] if k % 3 == 1 else face for k, face in enumerate(f)]
    return Case("inconsistent_orientation", "a closed cube of 48 triangles, every third one turned over", v, f)


def _moebius():
    n = 24
    v, f = [], []
    for k in range(n):
        t = 2 * math.pi * k / n
        for s in (-0.3, 0.3):
            r = 1 + s * math.cos(t / 2)
            v.append((r * math.cos(t), r * math.sin(t), s * math.sin(t / 2)))
    for k in range(n):
        a, b = 2 * k, 2 * k + 1
        if k + 1 < n:
            c, d = 2 * k + 2, 2 * k + 3
        else:
            c, d = 1, 0  # the half twist: the strip comes back with its sides swapped
        f += [(a, c, d), (a, d, b)]
    return Case("moebius", "a Moebius strip of 48 triangles (non-orientable)", v, f)


def _duplicate_faces():
    v, f = tetrahedron()
    f = f + [f[0], f[1][::-1], f[2][1:] + f[2][:1], f[0]]
    return Case("duplicate_faces", "a tetrahedron with one face twice more, one reversed and one rotated", v, f)


def _repeated_vertex_faces():
    v, f = grid(2, 2)
    v += [(3, 0, 0), (3, 1, 0), (4, 0, 0), (4, 1, 0), (5, 0.5, 0)]
    f += [(9, 10, 10, 11),  # a quad with a corner repeated: really a triangle
          (9, 11, 9),  # two distinct vertices
          (12, 12, 12),  # one distinct vertex
          (10, 11, 13, 10, 12, 9),  # a polygon passing twice through vertex 10
          (0, 1, 1, 1)]  # a quad on vertices 0 and 1 only
    return Case("repeated_vertex_faces", "faces repeating a vertex: next to itself, twice, three times, and a "
                "polygon passing twice through one vertex", v, f)


def _short_faces():
    v, f = grid(1, 1)
    v.append((3, 3, 3))
    f += [(0, 3), (4,)]
    return Case("short_faces", "a square and faces of two vertices and of one", v, f)


def _self_crossing_polygon():
    v = [(0, 0, 0), (2, 2, 0), (2, 0, 0), (0, 2, 0), (1, 3, 0), (3, 3, 0)]
    return Case("self_crossing_polygon", "a quad whose sides cross (a figure eight) and a pentagon over it",
                v, [(0, 1, 2, 3), (3, 1, 5, 4, 0)])


def _high_valence():
    n = 20_000
    v = [(0, 0, 0)] + [(math.cos(2 * math.pi * k / n), math.sin(2 * math.pi * k / n), 0.1 * math.sin(7 * k))
                       for k in range(n)]
    f = [(0, 1 + k, 1 + (k + 1) % n) for k in range(n)]
    return Case("high_valence", "a closed fan of 20,000 triangles around one vertex", v, f)


def _scaled(name, scale, what):
    v, f = closed_cube_triangles(2)
    v = [(x * scale, y * scale, z * scale) for x, y, z in v]
    f = f[:-2]  # an open cube: a hole for fill_holes
    return Case(name, f"an open cube of 46 triangles {what}", v, f)


def _index_out_of_range():
    v, f = tetrahedron()
    f.append((0, 1, 7))
    return Case("index_out_of_range", "a tetrahedron with a face using vertex 7 of 4", v, f, in_blender=False,
                defect="7")


def small_open_cube():
    """The mesh the parameter-limit tests run on: small enough for every operation at its
    limits (subdivide 6 times, smooth 1000 times), with a hole for fill_holes."""
    return _scaled("small_open_cube", 1.0, "(the parameter-limit mesh)")


def all_cases():
    return [_empty(), _vertices_only(), _one_face(), _huge_polygon(), _nan_coordinates(), _infinite_coordinates(),
            _coincident(), _zero_area(), _many_faces_on_edge(), _bow_tie(), _inconsistent_orientation(), _moebius(),
            _duplicate_faces(), _repeated_vertex_faces(), _short_faces(), _self_crossing_polygon(), _high_valence(),
            _scaled("huge_coordinates", 1e37, "scaled to 2e37 (float sums and squares overflow)"),
            _scaled("tiny_coordinates", 1e-30, "scaled to 2e-30 (float squares underflow to zero)"),
            _index_out_of_range()]


# Files -----------------------------------------------------------------------------------------

def write_off(path, case):
    with open(path, "w") as f:
        f.write(f"OFF\n{len(case.vertices)} {len(case.faces)} 0\n")
        for v in case.vertices:
            f.write(" ".join(_text(x) for x in v) + "\n")
        for face in case.faces:
            f.write(f"{len(face)} {' '.join(map(str, face))}\n")


def _text(x):
    if math.isnan(x):
        return "nan"
    if math.isinf(x):
        return "inf" if x > 0 else "-inf"
    return repr(x)


def write_ply(path, case):
    """Binary little-endian PLY, float positions, faces as uchar-counted int lists (MeshLab's
    own layout); NaN and infinities go through bit for bit."""
    if any(len(face) > 255 for face in case.faces):
        raise ValueError(f"{case.name}: a face of more than 255 vertices does not fit a uchar list count")
    header = ["ply", "format binary_little_endian 1.0", f"comment hedge hostile case {case.name}",
              f"element vertex {len(case.vertices)}", "property float x", "property float y", "property float z",
              f"element face {len(case.faces)}", "property list uchar int vertex_indices", "end_header"]
    body = bytearray()
    for v in case.vertices:
        body += struct.pack("<3f", *v)
    for face in case.faces:
        body += struct.pack(f"<B{len(face)}i", len(face), *face)
    with open(path, "wb") as f:
        f.write(("\n".join(header) + "\n").encode())
        f.write(body)


def write(case, folder):
    """Writes one case into `folder`; returns the path."""
    path = os.path.join(folder, case.file_name)
    (write_ply if case.fmt == "ply" else write_off)(path, case)
    return path


def write_all(folder):
    """Writes every case; returns [(case, path)]."""
    os.makedirs(folder, exist_ok=True)
    return [(case, write(case, folder)) for case in all_cases()]


if __name__ == "__main__":
    if len(sys.argv) != 2:
        raise SystemExit(__doc__)
    for case, path in write_all(sys.argv[1]):
        print(path)
