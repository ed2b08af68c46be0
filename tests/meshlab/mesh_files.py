"""Small mesh-file helpers for the MeshLab tests: OFF reading and writing, holes punched into
a real mesh, a PLY with vertex colours, face colours and per-wedge texture coordinates, and
the header of a PLY as MeshLab saved it."""
import os
import random
import struct


def nonempty(path):
    return os.path.isfile(path) and os.path.getsize(path) > 0


def read_off(path):
    with open(path) as f:
        words = [w for line in f for w in line.split("#")[0].split()]
    if words[0] != "OFF":
        raise ValueError(f"{path}: not an OFF file")
    nv, nf = int(words[1]), int(words[2])
    at = 4
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


def write_off(path, vertices, faces):
    with open(path, "w") as f:
        f.write(f"OFF\n{len(vertices)} {len(faces)} 0\n")
        for v in vertices:
            f.write("%r %r %r\n" % v)
        for face in faces:
            f.write(f"{len(face)} {' '.join(map(str, face))}\n")


def punch_holes(source, target, count, seed=7):
    """Removes the faces around `count` vertices whose 2-rings do not touch, and those vertices:
    `count` holes, each bounded by a vertex's link. Returns the number of holes."""
    vertices, faces = read_off(source)
    neighbours = [set() for _ in vertices]
    for face in faces:
        for a in face:
            neighbours[a].update(face)
    rng = random.Random(seed)
    order = list(range(len(vertices)))
    rng.shuffle(order)
    taken, seeds = set(), []
    for v in order:
        ring2 = set().union(*(neighbours[n] for n in neighbours[v]))
        if ring2 & taken:
            continue
        seeds.append(v)
        taken |= set().union(*(neighbours[n] for n in ring2))
        if len(seeds) == count:
            break
    removed = set(seeds)
    kept_faces = [f for f in faces if not removed & set(f)]
    index, kept_vertices = {}, []
    for i, v in enumerate(vertices):
        if i not in removed:
            index[i] = len(kept_vertices)
            kept_vertices.append(v)
    write_off(target, kept_vertices, [tuple(index[i] for i in f) for f in kept_faces])
    return len(seeds)


def write_attributed_ply(source_off, target, seed=11):
    """The mesh of `source_off` as a binary PLY with RGBA vertex colours, RGBA face colours, a
    float quality per vertex and per face, and per-wedge texture coordinates with seams (a
    strip of faces gets its own UV island), as MeshLab reads them."""
    vertices, faces = read_off(source_off)
    rng = random.Random(seed)
    header = ["ply", "format binary_little_endian 1.0", "comment made by tests/meshlab/mesh_files.py",
              f"element vertex {len(vertices)}", "property float x", "property float y", "property float z",
              "property uchar red", "property uchar green", "property uchar blue", "property uchar alpha",
              "property float quality",
              f"element face {len(faces)}", "property list uchar int vertex_indices",
              "property list uchar float texcoord",
              "property uchar red", "property uchar green", "property uchar blue", "property uchar alpha",
              "property float quality", "end_header"]
    lo = [min(v[k] for v in vertices) for k in range(3)]
    hi = [max(v[k] for v in vertices) for k in range(3)]
    body = bytearray()
    for v in vertices:
        body += struct.pack("<3f", *v)
        body += bytes(rng.randrange(256) for _ in range(3)) + bytes([255])
        body += struct.pack("<f", rng.uniform(0, 10))
    for i, face in enumerate(faces):
        body += struct.pack("<B3i", 3, *face)
        island = 0.5 if i % 7 == 0 else 0.0  # every 7th face on another island: UV seams
        uv = []
        for a in face:
            x, y = vertices[a][0], vertices[a][1]
            uv += [island + 0.5 * (x - lo[0]) / (hi[0] - lo[0]), (y - lo[1]) / (hi[1] - lo[1])]
        body += struct.pack("<B6f", 6, *uv)
        body += bytes(rng.randrange(256) for _ in range(4))
        body += struct.pack("<f", rng.uniform(-1, 1))
    with open(target, "wb") as f:
        f.write(("\n".join(header) + "\n").encode())
        f.write(body)


def ply_header(path):
    """The header lines of a PLY file."""
    lines = []
    with open(path, "rb") as f:
        for raw in f:
            line = raw.decode("ascii", "replace").strip()
            lines.append(line)
            if line == "end_header":
                break
    return lines


def ply_count(path, element):
    """The number of `element` (vertex, face) a PLY file declares."""
    for line in ply_header(path):
        words = line.split()
        if len(words) == 3 and words[0] == "element" and words[1] == element:
            return int(words[2])
    return None


def write_quad_cube(path, n):
    """A closed cube of 6 n^2 quads as an OFF file: MeshLab reads it as a polygonal mesh
    (triangle pairs joined by faux edges). Not OBJ: MeshLab 2020.09's OBJ reader aborts on quads."""
    index, vertices, faces = {}, [], []

    def vertex(p):
        if p not in index:
            index[p] = len(vertices)
            vertices.append(p)
        return index[p]

    for axis in range(3):
        for side in (0, n):
            for i in range(n):
                for j in range(n):
                    corners = []
                    for di, dj in ((0, 0), (1, 0), (1, 1), (0, 1)):
                        p = [0.0, 0.0, 0.0]
                        p[axis] = float(side)
                        p[(axis + 1) % 3] = float(i + di)
                        p[(axis + 2) % 3] = float(j + dj)
                        corners.append(vertex(tuple(p)))
                    faces.append(tuple(corners if side else corners[::-1]))
    write_off(path, vertices, faces)
    return len(faces)
