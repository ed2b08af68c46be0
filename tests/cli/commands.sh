#!/usr/bin/env bash
# The hedge command line on real meshes: info (text and JSON), convert, list, help, distance,
# the report operation, and clear non-zero exits on bad input.
set -euo pipefail
HEDGE=$1
MESHES=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }

bunny=$MESHES/bunny.off
dragon4=$MESHES/dragon_res4.ply
[ -f "$bunny" ] || fail "missing $bunny: run scripts/fetch_meshes"

# info --json carries every documented key.
json=$("$HEDGE" info "$bunny" --json)
for key in vertices edges faces halfedges boundary_loops components euler_characteristic genus repairs; do
  grep -q "\"$key\"" <<<"$json" || fail "info --json lacks $key: $json"
done
python3 - "$json" <<'PY'
import json, sys
d = json.loads(sys.argv[1])
assert d["faces"] == 3674 and d["vertices"] == 1839, d
assert d["halfedges"] == 2 * d["edges"], d
assert d["euler_characteristic"] == d["vertices"] - d["edges"] + d["faces"] - d["isolated_vertices"], d
for k in ["non_manifold_edges", "non_manifold_vertices", "flipped_faces", "skipped_faces"]:
    assert k in d["repairs"], d
PY

# The low-resolution dragon has non-manifold edges: info says what building repaired.
"$HEDGE" info "$dragon4" > "$work/info.txt"
grep -q "repaired" "$work/info.txt" || fail "dragon_res4 info shows no repair: $(cat "$work/info.txt")"

# convert between every format keeps the counts.
for ext in ply obj stl off; do
  "$HEDGE" convert "$bunny" "$work/bunny.$ext"
  [ -s "$work/bunny.$ext" ] || fail "convert to $ext wrote nothing"
  f=$("$HEDGE" info "$work/bunny.$ext" --json | python3 -c 'import json,sys; print(json.load(sys.stdin)["faces"])')
  [ "$f" = "$(python3 -c 'import json,sys; print(json.loads(sys.argv[1])["faces"])' "$json")" ] || fail "$ext: $f faces"
done
"$HEDGE" convert "$bunny" "$work/ascii.ply" --ascii
head -c 20 "$work/ascii.ply" | grep -q "ply" || fail "ascii ply header"

# list and help come from the catalogue.
"$HEDGE" list | grep -q "^report" || fail "list lacks report"
"$HEDGE" help report | grep -qi "euler" || fail "help report"

# report runs without an output file; --json is one object.
"$HEDGE" report "$bunny" --json | python3 -c 'import json,sys; d=json.load(sys.stdin); assert d["faces"] > 0'

# distance: a mesh is at distance 0 from itself and has no flipped face; a decimated copy is
# near but not at 0; a copy with every face turned over has them (nearly) all flipped (where
# the bunny bends sharply, a face also has input turned its way close by: not counted).
"$HEDGE" distance "$bunny" "$bunny" --json > "$work/same.json"
"$HEDGE" decimate "$bunny" "$work/small.off" --target-ratio 0.2 > /dev/null
"$HEDGE" distance "$bunny" "$work/small.off" --json > "$work/small.json"
python3 - "$bunny" "$work/flipped.off" <<'PY'
import sys
lines = open(sys.argv[1]).read().split("\n")
nv, nf = map(int, lines[1].split()[:2])
out = lines[:2 + nv]
for line in lines[2 + nv:2 + nv + nf]:
    n, *idx = line.split()
    out.append(" ".join([n] + idx[::-1]))
open(sys.argv[2], "w").write("\n".join(out) + "\n")
PY
"$HEDGE" distance "$bunny" "$work/flipped.off" --json > "$work/flipped.json"
python3 - "$work/same.json" "$work/small.json" "$work/flipped.json" <<'PY'
import json, sys
same, small, flipped = (json.load(open(p)) for p in sys.argv[1:])
assert same["hausdorff_over_diagonal"] < 1e-9 and same["flipped_faces"] == 0 and same["faces_b"] == 3674, same
assert 0 < small["hausdorff_over_diagonal"] < 0.02 and abs(small["faces_b"] - 735) <= 1, small
assert small["a_to_b"]["max"] <= small["hausdorff"] and small["b_to_a"]["max"] <= small["hausdorff"], small
assert small["flipped_faces"] == 0, small
assert flipped["hausdorff_over_diagonal"] < 1e-9 and flipped["flipped_faces"] > 0.95 * 3674, flipped
PY
"$HEDGE" distance "$bunny" "$work/small.off" | grep -q "symmetric Hausdorff" || fail "distance text output"
if "$HEDGE" distance "$bunny" 2> "$work/err.txt"; then fail "distance with one file accepted"; fi
grep -q "two files" "$work/err.txt" || fail "distance message: $(cat "$work/err.txt")"
if "$HEDGE" distance "$bunny" "$bunny" --samples-per-face x 2> "$work/err.txt"; then fail "bad density accepted"; fi
grep -q "samples-per-face" "$work/err.txt" || fail "density message: $(cat "$work/err.txt")"

# Bad input: non-zero exit and a message naming the problem; nothing written.
printf 'OFF\n3 1 0\n0 0 0\n1 0 0\nnan 1 0\n3 0 1 2\n' > "$work/nan.off"
if "$HEDGE" info "$work/nan.off" 2> "$work/err.txt"; then fail "NaN accepted"; fi
grep -qi "nan" "$work/err.txt" || fail "NaN message: $(cat "$work/err.txt")"
printf 'OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n' > "$work/range.off"
if "$HEDGE" convert "$work/range.off" "$work/out.ply" 2> "$work/err.txt"; then fail "bad index accepted"; fi
grep -q "7" "$work/err.txt" || fail "index message: $(cat "$work/err.txt")"
[ ! -e "$work/out.ply" ] || fail "output written on failure"
if "$HEDGE" info "$work/missing.off" 2> "$work/err.txt"; then fail "missing file accepted"; fi
grep -q "missing.off" "$work/err.txt" || fail "missing-file message"
if "$HEDGE" nonsense "$bunny" 2> "$work/err.txt"; then fail "unknown operation accepted"; fi
grep -q "unknown operation" "$work/err.txt" || fail "unknown-operation message"
if "$HEDGE" convert "$bunny" "$work/out.xyz" 2> "$work/err.txt"; then fail "unknown format accepted"; fi
echo "cli commands: ok"
