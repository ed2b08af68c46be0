#!/usr/bin/env python3
"""Every hostile mesh of hostile_meshes.py through every catalogue operation of the hedge
command line, each run with a time limit. A run either succeeds with a valid result (read back
with `hedge info --json`: finite, indices in range, no faces repeating a vertex that the input
did not have, face counts as the operation promises, and for repair a mesh that builds again
without any repair) or exits 1 with a message naming the problem (the case's defect where it
has one; the expected refusals are listed below). Either way the input file is unchanged, and on
failure no output file exists. Prints the outcomes as a Markdown table.

  test_cli.py --hedge build/bin/hedge --out build/tests/hostile/cli
"""
import argparse
import concurrent.futures
import hashlib
import json
import math
import os
import shutil
import subprocess
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "meshlab"))
import hostile_meshes  # noqa: E402
import outcomes  # noqa: E402
from mesh_files import read_off  # noqa: E402  (plain OFF reading, no MeshLab needed)

CRASH_WORDS = ("internal", "std::", "basic_string", "vector::", "bad_alloc", "terminate", "Assertion")


def sha256(path):
    with open(path, "rb") as f:
        return hashlib.sha256(f.read()).hexdigest()


def repeats_vertex(face):
    return len(set(face)) != len(face)


class Runner:
    def __init__(self, hedge, out, timeout):
        self.hedge = hedge
        self.out = out
        self.timeout = timeout

    def run(self, arguments):
        """(exit code, stdout, stderr, seconds); exit code None on timeout."""
        start = time.monotonic()
        try:
            done = subprocess.run([self.hedge] + arguments, capture_output=True, text=True, errors="replace",
                                  timeout=self.timeout)
        except subprocess.TimeoutExpired:
            return None, "", "", time.monotonic() - start
        return done.returncode, done.stdout, done.stderr, time.monotonic() - start

    def info(self, path):
        code, out, err, _ = self.run(["info", path, "--json"])
        return (json.loads(out), None) if code == 0 else (None, err.strip())


def check_result(checks, label, op, case, input_info, result_path, runner):
    """The output of a successful run is valid and its counts are what `op` promises."""
    info, error = runner.info(result_path)
    if not checks.check(info is not None, f"{label}: the result reads back ({error or 'ok'})"):
        return None, None
    vertices, faces = read_off(result_path)
    checks.check(all(math.isfinite(x) for v in vertices for x in v), f"{label}: every coordinate finite")
    checks.check(all(0 <= i < len(vertices) for f in faces for i in f), f"{label}: every index in range")
    checks.check(all(len(f) >= 3 for f in faces), f"{label}: every face has 3 or more corners")
    repeated_in = sum(repeats_vertex(f) for f in case.faces)
    repeated_out = sum(repeats_vertex(f) for f in faces)
    allowed = 0 if op["id"] == "repair" else repeated_in
    what = f"{label}: {repeated_out} faces repeat a vertex (the input has {repeated_in}; allowed {allowed})"
    defect = outcomes.known_defect(case.name, op["id"])
    defect_seen = None
    if defect:
        if repeated_out > allowed:
            defect_seen = defect
            print(f"  KNOWN DEFECT {label}: {defect}")
        else:
            print(f"  NOTE  {label}: the known defect '{defect}' no longer happens: remove it from outcomes.py")
    else:
        checks.check(repeated_out <= allowed, what)
    n_in = input_info["faces"]  # faces of the built input (faces of fewer than 3 vertices skipped)
    n_out = len(faces)
    triangles = all(len(f) == 3 for f in faces)
    op_id = op["id"]
    if op_id in ("smooth", "make_delaunay"):
        checks.check(n_out == n_in and len(vertices) == len(case.vertices),
                     f"{label}: faces and vertices kept ({n_out} of {n_in} faces, {len(vertices)} of "
                     f"{len(case.vertices)} vertices)")
    elif op_id == "triangulate":
        bound = sum(len(f) for f in case.faces) + n_in
        checks.check(triangles and n_in <= n_out <= bound, f"{label}: triangles only, {n_in} <= {n_out} <= {bound}")
    elif op_id == "decimate":
        bound = sum(max(len(f) - 2, 1) for f in case.faces)
        checks.check(triangles and n_out <= bound, f"{label}: triangles only, {n_out} <= {bound}")
    elif op_id == "subdivide":  # loop, one step, by default
        checks.check(triangles and n_out == 4 * n_in, f"{label}: {n_out} = 4 x {n_in} triangles")
    elif op_id == "fill_holes":
        checks.check(n_out >= n_in, f"{label}: {n_out} >= {n_in} faces")
    elif op_id == "remesh":
        checks.check(triangles, f"{label}: triangles only ({n_out})")
    elif op_id == "repair":
        bad = {k: v for k, v in info["repairs"].items() if v and k != "isolated_vertices"}
        checks.check(not bad and info["isolated_vertices"] == 0,
                     f"{label}: builds again without repair, no isolated vertex ({bad or 'none'})")
        checks.check(n_out <= sum(max(len(f) - 2, 1) for f in case.faces), f"{label}: {n_out} faces")
    return n_out, defect_seen


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--hedge", required=True)
    parser.add_argument("--out", required=True)
    parser.add_argument("--timeout", type=float, default=60, help="seconds per run")
    parser.add_argument("--jobs", type=int, default=2)
    parser.add_argument("--table", help="also write the outcome table (Markdown) here")
    args = parser.parse_args()
    out = os.path.abspath(args.out)
    shutil.rmtree(out, ignore_errors=True)
    os.makedirs(os.path.join(out, "results"))
    runner = Runner(os.path.abspath(args.hedge), out, args.timeout)
    checks = outcomes.Checks()

    code, text, err, _ = runner.run(["list", "--json"])
    operations = json.loads(text)["operations"]
    cases = hostile_meshes.write_all(os.path.join(out, "cases"))
    input_info = {}
    for case, path in cases:
        info, error = runner.info(path)
        input_info[case.name] = info
        if case.defect:
            checks.check(info is None and case.defect in (error or ""),
                         f"{case.name}: hedge info refuses it naming {case.defect!r}: {error}")

    def one(case, path, op):
        label = f"{case.name} / {op['id']}"
        result = os.path.join(out, "results", f"{case.name}.{op['id']}.off")
        before = sha256(path)
        arguments = [op["id"], path] + ([result] if op["changes_mesh"] else []) + ["--json"]
        code, stdout, stderr, seconds = runner.run(arguments)
        return label, case, op, result, before, code, stdout, stderr, seconds

    jobs = [(case, path, op) for case, path in cases for op in operations]
    table = outcomes.Table([c.name for c, _ in cases], [op["id"] for op in operations])
    with concurrent.futures.ThreadPoolExecutor(args.jobs) as pool:
        futures = [pool.submit(one, *job) for job in jobs]
        for future in futures:
            label, case, op, result, before, code, stdout, stderr, seconds = future.result()
            path = os.path.join(out, "cases", case.file_name)
            checks.check(sha256(path) == before, f"{label}: input file unchanged")
            if code is None:
                checks.check(False, f"{label}: finished within {args.timeout:.0f} s")
                table.set(case.name, op["id"], f"TIMEOUT > {args.timeout:.0f} s")
                continue
            if code == 0:
                checks.check(not case.defect, f"{label}: succeeded although the input has {case.defect!r}")
                n, defect = check_result(checks, label, op, case, input_info[case.name], result, runner) \
                    if op["changes_mesh"] else (None, None)
                cell = "ok" if n is None else f"ok, {n} faces"
                if defect:
                    cell += f" (known defect: {defect})"
                table.set(case.name, op["id"], cell)
                continue
            message = stderr.strip().removeprefix("hedge: ")
            checks.check(code == 1, f"{label}: exit 1, not {code} (a crash?)")
            checks.check(not os.path.exists(result), f"{label}: no output file after the failure")
            checks.check(message and not any(w in message for w in CRASH_WORDS), f"{label}: a message for people: {message}")
            expected = outcomes.expected_refusal(case, op["id"])
            checks.check(expected is not None and expected in message,
                         f"{label}: refused as expected ({expected!r}): {message}")
            table.set(case.name, op["id"], outcomes.short(message, case))
        for case, path in cases:
            for op in operations:
                expected = outcomes.expected_refusal(case, op["id"])
                if expected is not None:
                    checks.check(not table.get(case.name, op["id"]).startswith("ok"),
                                 f"{case.name} / {op['id']}: the refusal listed in outcomes.py still happens")

    print(table.markdown())
    for path in [os.path.join(out, "table.md")] + ([args.table] if args.table else []):
        with open(path, "w") as f:
            f.write(table.markdown())
    checks.finish()


if __name__ == "__main__":
    main()
