#!/usr/bin/env bash
# The hedge command line on real meshes: info (text and JSON), convert, list, help, the
# report operation, and clear non-zero exits on bad input.
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
