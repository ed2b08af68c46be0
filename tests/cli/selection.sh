#!/usr/bin/env bash
# selection_only from the command line: a PLY's vertex or face property "selected" is the
# selection (read and written back). Half of the bunny selected, every operation that has the
# parameter leaves the unselected faces as they were; nothing selected changes nothing.
set -euo pipefail
HEDGE=$1
MESHES=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
bunny=$MESHES/bunny.off
[ -f "$bunny" ] || { echo "FAIL: missing $bunny: run scripts/fetch_meshes" >&2; exit 1; }

"$HEDGE" convert "$bunny" "$work/bunny.ply" --ascii
python3 - "$HEDGE" "$work" "$(dirname "$0")" <<'PY'
import json, subprocess, sys
hedge, work = sys.argv[1], sys.argv[2]
sys.path.insert(0, sys.argv[3])
from ascii_ply import read_ply  # noqa: E402


def write_ply(path, vertices, faces, selected):
    with open(path, "w") as f:
        f.write(f"ply\nformat ascii 1.0\nelement vertex {len(vertices)}\nproperty float x\nproperty float y\n"
                f"property float z\nelement face {len(faces)}\nproperty list uchar int vertex_indices\n"
                f"property uchar selected\nend_header\n")
        for v in vertices:
            f.write(" ".join(repr(c) for c in v[:3]) + "\n")
        for corners, s in zip(faces, selected):
            f.write(f"{len(corners)} " + " ".join(map(str, corners)) + f" {s}\n")


def faces_of(path, want):
    """Faces with selection `want`, as corner positions from the smallest on, sorted."""
    vertices, faces, props = read_ply(path)
    column = props["face"].index("selected")
    out = []
    for row in faces:
        n = int(row[0])
        corners = [tuple(vertices[int(i)][:3]) for i in row[1:1 + n]]
        if int(row[column + n]) != want:
            continue
        first = corners.index(min(corners))
        out.append(tuple(corners[first:] + corners[:first]))
    return sorted(out)


vertices, rows, _ = read_ply(f"{work}/bunny.ply")
faces = [list(map(int, r[1:1 + int(r[0])])) for r in rows]
median = sorted(vertices[f[0]][0] for f in faces)[len(faces) // 2]
half = [1 if vertices[f[0]][0] < median else 0 for f in faces]
write_ply(f"{work}/half.ply", vertices, faces, half)
write_ply(f"{work}/none.ply", vertices, faces, [0] * len(faces))

ops = [op["id"] for op in json.loads(subprocess.run([hedge, "list", "--json"], check=True, capture_output=True,
                                                    text=True).stdout)["operations"]
       if any(p["id"] == "selection_only" for p in op["params"])]
assert {"decimate", "remesh", "smooth", "make_delaunay", "fill_holes", "triangulate"} <= set(ops), ops
outside = faces_of(f"{work}/half.ply", 0)
for op in ops:
    out = f"{work}/{op}.ply"
    report = json.loads(subprocess.run([hedge, op, f"{work}/half.ply", out, "--selection-only", "true", "--json",
                                        "--ascii"], check=True, capture_output=True, text=True).stdout)
    if faces_of(out, 0) != outside:
        sys.exit(f"FAIL: {op} changed faces outside the selection: {report}")
    print(f"{op}: {len(outside)} unselected faces kept, {len(faces_of(out, 1))} selected after")
    out = f"{work}/{op}_none.ply"
    done = subprocess.run([hedge, op, f"{work}/none.ply", out, "--selection-only", "true", "--json", "--ascii"],
                          check=True, capture_output=True, text=True)
    if "nothing is selected" not in done.stdout + done.stderr or faces_of(out, 0) != faces_of(f"{work}/none.ply", 0):
        sys.exit(f"FAIL: {op} with nothing selected: {done.stdout} {done.stderr}")
decimated = len(faces_of(f"{work}/decimate.ply", 1))
if not decimated < len(faces) - len(outside):
    sys.exit(f"FAIL: decimate did not reduce the selection ({decimated} faces)")
print("selection_only: every operation keeps the unselected faces")
PY
