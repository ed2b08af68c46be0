#!/usr/bin/env bash
# OpenMesh's .om through the CLI: PLY -> OM -> PLY keeps faces and attributes, a non-manifold
# mesh reaches .om whole, operations read and write .om, bad .om files get a message.
set -euo pipefail
HEDGE=$1
MESHES=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }
faces() { "$HEDGE" info "$1" --json | python3 -c 'import json,sys; print(json.load(sys.stdin)["faces"])'; }

bunny=$MESHES/bunny.off
dragon4=$MESHES/dragon_res4.ply
[ -f "$bunny" ] || fail "missing $bunny: run scripts/fetch_meshes"
"$HEDGE" convert "$bunny" "$work/bunny.ply"
if ! "$HEDGE" convert "$work/bunny.ply" "$work/bunny.om" 2> "$work/err.txt"; then
  grep -q "built with OpenMesh" "$work/err.txt" || fail "no .om and no reason: $(cat "$work/err.txt")"
  echo "hedge built without OpenMesh: skipped"
  exit 0
fi

# PLY -> OM -> PLY: same faces, same vertices, positions bit for bit (ASCII compare).
"$HEDGE" convert "$work/bunny.om" "$work/back.ply"
[ "$(faces "$work/back.ply")" = 3674 ] || fail "bunny back from .om: $(faces "$work/back.ply") faces"
"$HEDGE" convert "$work/bunny.ply" "$work/a.ply" --ascii
"$HEDGE" convert "$work/back.ply" "$work/b.ply" --ascii
cmp -s "$work/a.ply" "$work/b.ply" || fail "bunny PLY -> OM -> PLY differs"

# Attributes travel by name: vertex colours and normals, face colours.
python3 - "$work/attr.ply" <<'PY'
import sys
v = [(0,0,0),(1,0,0),(1,1,0),(0,1,0)]
out = ["ply","format ascii 1.0","element vertex 4","property float x","property float y","property float z",
       "property float nx","property float ny","property float nz",
       "property uchar red","property uchar green","property uchar blue","property uchar alpha",
       "element face 2","property list uchar int vertex_indices",
       "property uchar red","property uchar green","property uchar blue","property uchar alpha","end_header"]
for i, p in enumerate(v): out.append("%g %g %g 0 0 1 %d %d %d 255" % (p + (10 * i, 20 * i, 30 * i)))
out += ["3 0 1 2 200 100 50 255", "3 0 2 3 1 2 3 255"]
open(sys.argv[1], "w").write("\n".join(out) + "\n")
PY
"$HEDGE" convert "$work/attr.ply" "$work/attr.om"
"$HEDGE" convert "$work/attr.om" "$work/attr_back.ply" --ascii
"$HEDGE" convert "$work/attr.ply" "$work/attr_ascii.ply" --ascii
cmp -s "$work/attr_ascii.ply" "$work/attr_back.ply" || fail "attributes PLY -> OM -> PLY differ: $(diff "$work/attr_ascii.ply" "$work/attr_back.ply")"
"$HEDGE" info "$work/attr.om" | grep -q "color (face" || fail "face colours missing from .om"

# A non-manifold mesh reaches .om with every face, saying what was duplicated.
if [ -f "$dragon4" ]; then
  "$HEDGE" convert "$dragon4" "$work/d4.om" 2> "$work/d4.txt"
  grep -q "vertices written twice" "$work/d4.txt" || fail "no note of duplicated vertices: $(cat "$work/d4.txt")"
  [ "$(faces "$work/d4.om")" = "$(faces "$dragon4")" ] || fail "dragon_res4 lost faces in .om"
fi

# Operations read and write .om.
"$HEDGE" decimate "$work/bunny.om" "$work/small.om" --target-ratio 0.5 -q > /dev/null
f=$(faces "$work/small.om")
[ "$f" -gt 1700 ] && [ "$f" -lt 1900 ] || fail "decimate .om -> .om: $f faces"

# Bad .om files: exit 1, the path and why, no crash.
printf 'not a mesh' > "$work/bad.om"
head -c 100 "$work/bunny.om" > "$work/cut.om"
for bad in "$work/bad.om" "$work/cut.om" "$work/missing.om"; do
  set +e
  "$HEDGE" convert "$bad" "$work/x.ply" 2> "$work/err.txt"
  rc=$?
  set -e
  [ $rc = 1 ] || fail "$bad: exit $rc"
  grep -q "$bad" "$work/err.txt" || fail "$bad: message does not name the file: $(cat "$work/err.txt")"
done
echo "ok"
