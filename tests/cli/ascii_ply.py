"""The ASCII PLY files hedge writes (--ascii), read back for the CLI tests."""


def read_ply(path):
    """(vertex rows as numbers, face rows as words, {element: property names})."""
    lines = open(path).read().split("\n")
    end = lines.index("end_header")
    counts, props, current = {}, {"vertex": [], "face": []}, None
    for line in lines[:end]:
        words = line.split()
        if words[:1] == ["element"]:
            current = words[1]
            counts[current] = int(words[2])
        elif words[:1] == ["property"]:
            props[current].append(words[-1])
    body = lines[end + 1:]
    nv = counts["vertex"]
    vertices = [list(map(float, line.split())) for line in body[:nv]]
    faces = [line.split() for line in body[nv:nv + counts["face"]]]
    return vertices, faces, props
