"""Counting a mesh's defects from its indexed faces alone, independently of hedge's code, for the
host tests' promise that no operation leaves more of them than it was given: non-manifold edges
(3 or more face sides on one edge), non-manifold vertices (faces round the vertex forming more
than one fan, fans joined through edges at the vertex), duplicate faces (another face before it
has the same vertex set) and faces repeating a vertex. Plain Python (no numpy: the hosts'
Pythons differ), with an OFF/PLY reader and the small meshes made to have each defect.

  python3 defects.py                 the self-test
  python3 defects.py MESH.off|.ply   prints the counts
"""
import os
import struct
import sys
from collections import Counter

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import hostile_meshes  # noqa: E402

CATEGORIES = ("non_manifold_edges", "non_manifold_vertices", "duplicate_faces", "repeated_vertex_faces")


def count(faces):
    """The four counts (CATEGORIES) of a list of faces, each a sequence of vertex indices."""
    faces = [tuple(f) for f in faces]
    sides = Counter()
    for f in faces:
        for a, b in zip(f, f[1:] + f[:1]):
            if a != b:
                sides[(a, b) if a < b else (b, a)] += 1
    return {"non_manifold_edges": sum(1 for n in sides.values() if n >= 3),
            "non_manifold_vertices": _non_manifold_vertices(faces),
            "duplicate_faces": len(faces) - len({frozenset(f) for f in faces}),
            "repeated_vertex_faces": sum(1 for f in faces if len(set(f)) < len(f))}


def _non_manifold_vertices(faces):
    """Vertices whose faces fall into more than one group when faces sharing an edge at the
    vertex are joined (union-find over (vertex, face) pairs)."""
    node, first, parent = {}, {}, []

    def find(x):
        while parent[x] != x:
            parent[x] = parent[parent[x]]
            x = parent[x]
        return x

    for fi, f in enumerate(faces):
        n = len(f)
        for i, v in enumerate(f):
            x = node.setdefault((v, fi), len(parent))
            if x == len(parent):
                parent.append(x)
            for w in (f[i - 1], f[(i + 1) % n]):
                if w != v:
                    y = first.setdefault((v, w), x)
                    rx, ry = find(x), find(y)
                    if rx != ry:
                        parent[rx] = ry
    fans = Counter(v for (v, _), x in node.items() if find(x) == x)
    return sum(1 for n in fans.values() if n > 1)


def allowed(before, subdivision_steps=0):
    """The most of each category a result may have: the input's counts, except that each
    subdivision step splits every non-manifold edge in two and every duplicated face in four
    whose three inner edges the copies share (docs/architecture.md, "No mesh comes back worse")."""
    most = dict(before)
    for _ in range(subdivision_steps):
        most["non_manifold_edges"] = 2 * most["non_manifold_edges"] + 3 * most["duplicate_faces"]
        most["duplicate_faces"] *= 4
    return most


def verdicts(label, before, after, subdivision_steps=0):
    """One (passed, message) per category: the result (`after`) has no more than allowed()."""
    most = allowed(before, subdivision_steps)
    return [(after[k] <= most[k], f"{label}: {k} {before[k]} -> {after[k]}" + (f" (at most {most[k]})" if most[k] != before[k] else ""))
            for k in CATEGORIES]


def increases(before, after, subdivision_steps=0):
    """The categories past allowed(), as 'category b -> a' strings."""
    most = allowed(before, subdivision_steps)
    return [f"{k} {before[k]} -> {after[k]}" for k in CATEGORIES if after[k] > most[k]]


def describe(counts):
    return ", ".join(f"{k} {counts[k]}" for k in CATEGORIES)


CELL_KEY = "per cell: non-manifold edges / non-manifold vertices / duplicate faces / faces repeating a vertex"


def cell(counts):
    """The counts in a table cell, in the order of CELL_KEY."""
    return "/".join(str(counts[k]) for k in CATEGORIES)


# Reading ----------------------------------------------------------------------------------------

PLY_TYPES = {"char": "b", "int8": "b", "uchar": "B", "uint8": "B", "short": "h", "int16": "h", "ushort": "H",
             "uint16": "H", "int": "i", "int32": "i", "uint": "I", "uint32": "I", "float": "f", "float32": "f",
             "double": "d", "float64": "d"}


def read_mesh(path):
    """(vertices as (x, y, z) float tuples, faces as index tuples) of an OFF or PLY file (ASCII or
    binary; binary floats come back exactly as stored)."""
    if path.lower().endswith(".off"):
        return _read_off(path)
    with open(path, "rb") as f:
        data = f.read()
    end = data.index(b"end_header") + len(b"end_header")
    end = data.index(b"\n", end) + 1
    elements, fmt = [], None
    for line in data[:end].decode("ascii").splitlines():
        words = line.split()
        if words[:1] == ["format"]:
            fmt = words[1]
        elif words[:1] == ["element"]:
            elements.append((words[1], int(words[2]), []))
        elif words[:1] == ["property"]:
            elements[-1][2].append((words[-1], words[1:-1]))
    body = data[end:]
    rows = _ascii_rows(body, elements) if fmt == "ascii" else _binary_rows(body, elements, fmt)
    vertices, faces = [], []
    for name, _, props in elements:
        names = [p for p, _ in props]
        for row in next(rows):
            if name == "vertex":
                vertices.append(tuple(float(row[names.index(k)]) for k in "xyz"))
            elif name == "face":
                key = "vertex_indices" if "vertex_indices" in names else "vertex_index"
                faces.append(tuple(int(i) for i in row[names.index(key)]))
    return vertices, faces


def _ascii_rows(body, elements):
    words = iter(body.split())
    for _, n, props in elements:
        rows = []
        for _ in range(n):
            row = []
            for _, kind in props:
                if kind[0] == "list":
                    row.append([float(next(words)) for _ in range(int(next(words)))])
                else:
                    row.append(float(next(words)))
            rows.append(row)
        yield rows


def _binary_rows(body, elements, fmt):
    order = "<" if fmt == "binary_little_endian" else ">"
    at = 0
    for _, n, props in elements:
        rows = []
        if all(kind[0] != "list" for _, kind in props):
            layout = struct.Struct(order + "".join(PLY_TYPES[kind[0]] for _, kind in props))
            rows = list(layout.iter_unpack(body[at:at + n * layout.size]))
            at += n * layout.size
            yield rows
            continue
        for _ in range(n):
            row = []
            for _, kind in props:
                if kind[0] == "list":
                    size = struct.Struct(order + PLY_TYPES[kind[1]])
                    (k,) = size.unpack_from(body, at)
                    item = struct.Struct(order + str(k) + PLY_TYPES[kind[2]])
                    row.append(item.unpack_from(body, at + size.size))
                    at += size.size + item.size
                else:
                    scalar = struct.Struct(order + PLY_TYPES[kind[0]])
                    row.append(scalar.unpack_from(body, at)[0])
                    at += scalar.size
            rows.append(row)
        yield rows


def _read_off(path):
    with open(path) as f:
        words = [w for line in f for w in line.split("#")[0].split()]
    nv, nf = int(words[1]), int(words[2])
    vertices = [tuple(float(x) for x in words[4 + 3 * i:7 + 3 * i]) for i in range(nv)]
    faces, at = [], 4 + 3 * nv
    for _ in range(nf):
        n = int(words[at])
        faces.append(tuple(int(i) for i in words[at + 1:at + 1 + n]))
        at += 1 + n
    return vertices, faces


# Meshes made to have defects ------------------------------------------------------------------

def _holes_sharing_vertex():
    # A closed cube with two faces cut away that meet only at a corner of both: two holes whose
    # borders pass through one vertex (a bow-tie border), whose faces form two fans.
    v, f = hostile_meshes.closed_cube_triangles(3)
    corner = Counter(i for face in f for i in face).most_common()
    for centre, _ in corner:
        round_it = [k for k, face in enumerate(f) if centre in face]
        for a in round_it:
            for b in round_it:
                if a < b and set(f[a]) & set(f[b]) == {centre}:
                    kept = [face for k, face in enumerate(f) if k not in (a, b)]
                    return hostile_meshes.Case("holes_sharing_vertex", "a closed cube with two holes touching at a "
                                               "vertex (a bow-tie border)", v, kept)
    raise AssertionError("no two faces of the cube meet at a vertex alone")


def _fin_and_duplicate():
    # An open grid with a third face on an inner edge and one face twice.
    v, f = hostile_meshes.grid(3, 3)
    top = len(v)
    v.append((1.5, 1.5, 1.0))
    a, b = f[8][0], f[8][1]  # an inner edge of the grid's middle square
    return hostile_meshes.Case("fin_and_duplicate", "a grid with a third triangle on an inner edge and one "
                               "triangle twice", v, f + [(a, b, top), f[3]])


def cases():
    """The meshes made to have defects that the host tests run every operation on: the shared
    hostile bow tie (triangles meeting at a vertex, cones at their apex), 3 and 6 faces on an
    edge, duplicate faces, and two of this module's."""
    wanted = {"bow_tie", "many_faces_on_edge", "duplicate_faces"}
    return [c for c in hostile_meshes.all_cases() if c.name in wanted] + [_holes_sharing_vertex(),
                                                                            _fin_and_duplicate()]


def _self_test():
    expected = {
        "bow_tie": (0, 2, 0, 0),
        "many_faces_on_edge": (2, 0, 0, 0),
        "duplicate_faces": (6, 0, 4, 0),  # the repeated faces put 3 or more sides on all 6 edges
        "repeated_vertex_faces": (2, 1, 0, 5),  # 9-11: 3 sides; 12: a 1-gon and a polygon
        "short_faces": (1, 0, 0, 0),  # a 2-gon on the square's diagonal: 4 sides
        "self_crossing_polygon": (0, 1, 0, 0),  # the two polygons meet at vertex 1 without an edge
        "holes_sharing_vertex": (0, 1, 0, 0),
        "fin_and_duplicate": (3, 0, 1, 0),  # the fin's edge, and two more under the repeated face
    }
    found = {c.name: c for c in hostile_meshes.all_cases() + cases()}
    failed = 0
    for name, numbers in expected.items():
        got = count(found[name].faces)
        if tuple(got[k] for k in CATEGORIES) != numbers:
            print(f"FAIL {name}: {describe(got)}, expected {numbers}")
            failed += 1
    closed = count(hostile_meshes.closed_cube_triangles(2)[1])
    if any(closed.values()):
        print(f"FAIL closed cube: {describe(closed)}")
        failed += 1
    print(f"defects self-test: {len(expected) + 1 - failed} passed, {failed} failed")
    return failed


if __name__ == "__main__":
    if len(sys.argv) == 2:
        print(describe(count(read_mesh(sys.argv[1])[1])))
    else:
        sys.exit(1 if _self_test() else 0)
