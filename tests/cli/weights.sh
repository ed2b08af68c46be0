#!/usr/bin/env bash
# Decimate's weights and locks from the command line: they name vertex attributes, which a PLY
# gives as vertex properties hedge reads ("quality", "selected"). Weight 1 on half of the bunny
# keeps more of its triangles there; locked vertices come back where they were; a name the
# file lacks is refused with a message and no output file.
set -euo pipefail
HEDGE=$1
MESHES=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
bunny=$MESHES/bunny.off
[ -f "$bunny" ] || { echo "FAIL: missing $bunny: run scripts/fetch_meshes" >&2; exit 1; }

python3 - "$HEDGE" "$bunny" "$work" "$(dirname "$0")" <<'PY'
import json, os, subprocess, sys
hedge, bunny, work = sys.argv[1:4]
sys.path.insert(0, sys.argv[4])
import ascii_ply  # noqa: E402
subprocess.run([hedge, "convert", bunny, f"{work}/bunny.ply", "--ascii"], check=True)


def read_ply(path):
    """Vertex rows as dicts of their properties, faces as vertex index lists."""
    rows, faces, props = ascii_ply.read_ply(path)
    return [dict(zip(props["vertex"], row)) for row in rows], [list(map(int, f[1:])) for f in faces]


vertices, faces = read_ply(f"{work}/bunny.ply")
median = sorted(v["x"] for v in vertices)[len(vertices) // 2]
pinned = set(range(0, len(vertices), 50))
with open(f"{work}/marked.ply", "w") as f:
    f.write(f"ply\nformat ascii 1.0\nelement vertex {len(vertices)}\nproperty float x\nproperty float y\n"
            f"property float z\nproperty float quality\nproperty uchar selected\nelement face {len(faces)}\n"
            f"property list uchar int vertex_indices\nend_header\n")
    for i, v in enumerate(vertices):
        f.write(f"{v['x']!r} {v['y']!r} {v['z']!r} {int(v['x'] > median)} {int(i in pinned)}\n")
    for corners in faces:
        f.write(f"{len(corners)} " + " ".join(map(str, corners)) + "\n")


def decimate(name, *flags):
    out = f"{work}/{name}.ply"
    done = subprocess.run([hedge, "decimate", f"{work}/marked.ply", out, "--target-ratio", "0.1", "--json",
                           "--ascii", *flags], capture_output=True, text=True)
    return done, out


def faces_right(path):
    vs, fs = read_ply(path)
    return sum(sum(vs[i]["x"] for i in f) / len(f) > median for f in fs)


done, plain = decimate("plain")
assert done.returncode == 0, done.stderr
done, weighted = decimate("weighted", "--weight-attribute", "quality", "--lock-attribute", "selected")
assert done.returncode == 0, done.stderr
report = json.loads(done.stdout)
right, right_plain = faces_right(weighted), faces_right(plain)
print(f"faces right of the median: {right} weighted, {right_plain} without weights")
if not right > 1.25 * right_plain:
    sys.exit("FAIL: the weights did not keep more triangles where they are 1")
if report.get("locked_vertices") != len(pinned):
    sys.exit(f"FAIL: locked_vertices {report.get('locked_vertices')}, expected {len(pinned)}")
after = {(v["x"], v["y"], v["z"]) for v in read_ply(weighted)[0]}
moved = [i for i in pinned if (vertices[i]["x"], vertices[i]["y"], vertices[i]["z"]) not in after]
if moved:
    sys.exit(f"FAIL: {len(moved)} locked vertices moved or went")

done, out = decimate("refused", "--weight-attribute", "nope")
if done.returncode != 1 or "weight_attribute: the mesh has no vertex attribute 'nope'" not in done.stderr \
        or "quality" not in done.stderr or os.path.exists(out):
    sys.exit(f"FAIL: an unknown attribute: exit {done.returncode}, {done.stderr.strip()}")
print("weights and locks: ok")
PY
