#!/usr/bin/env python3
"""Every parameter of every operation of the hedge command line at its limits (limits.py): the
value exactly at min and at max is accepted and runs (within a time limit, to a result that
reads back), the nearest value beyond is refused with exit 1, a message naming the operation,
the parameter and its range, and no output file. Runs on a small open cube so that every
operation at its maximum (subdivide 6 times, smooth 1000 times, remesh 100 times) stays quick;
prints the slowest runs.

  test_limits.py --hedge build/bin/hedge --out build/tests/hostile/limits
"""
import argparse
import concurrent.futures
import json
import os
import shutil
import subprocess
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import hostile_meshes  # noqa: E402
import limits  # noqa: E402
import outcomes  # noqa: E402


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--hedge", required=True)
    parser.add_argument("--out", required=True)
    parser.add_argument("--timeout", type=float, default=60, help="seconds per run")
    parser.add_argument("--jobs", type=int, default=2)
    args = parser.parse_args()
    out = os.path.abspath(args.out)
    hedge = os.path.abspath(args.hedge)
    shutil.rmtree(out, ignore_errors=True)
    os.makedirs(out)
    checks = outcomes.Checks()
    mesh = hostile_meshes.write(hostile_meshes.small_open_cube(), out)
    operations = json.loads(subprocess.run([hedge, "list", "--json"], check=True, capture_output=True,
                                           text=True).stdout)["operations"]

    def one(op, p, value, accepted, k):
        result = os.path.join(out, f"{op['id']}.{p['id']}.{k}.ply")
        arguments = [hedge, op["id"], mesh] + ([result] if op["changes_mesh"] else [])
        arguments += ["--" + p["id"].replace("_", "-"), limits.text(value)]
        start = time.monotonic()
        try:
            done = subprocess.run(arguments, capture_output=True, text=True, timeout=args.timeout)
        except subprocess.TimeoutExpired:
            return op, p, value, accepted, result, None, "", args.timeout
        return op, p, value, accepted, result, done.returncode, done.stderr.strip(), time.monotonic() - start

    jobs = [(op, p, value, accepted, k) for op in operations for p in op["params"]
            for k, (value, accepted) in enumerate(limits.cases(p))]
    timings = []
    with concurrent.futures.ThreadPoolExecutor(args.jobs) as pool:
        for future in [pool.submit(one, *job) for job in jobs]:
            op, p, value, accepted, result, code, stderr, seconds = future.result()
            label = f"{op['id']} --{p['id'].replace('_', '-')} {limits.text(value)}"
            timings.append((seconds, label))
            if not checks.check(code is not None, f"{label}: finished within {args.timeout:.0f} s"):
                continue
            if accepted:
                if checks.check(code == 0, f"{label}: accepted and run ({stderr or 'ok'})") and op["changes_mesh"]:
                    info = subprocess.run([hedge, "info", result, "--json"], capture_output=True, text=True)
                    checks.check(info.returncode == 0, f"{label}: the result reads back ({info.stderr.strip() or 'ok'})")
            else:
                checks.check(code == 1 and limits.refusal_names_parameter(stderr, op["id"], p),
                             f"{label}: refused naming the parameter and its range: {stderr}")
                checks.check(not os.path.exists(result), f"{label}: no output file")
    print(f"{len(jobs)} runs; the slowest:")
    for seconds, label in sorted(timings, reverse=True)[:8]:
        print(f"  {seconds:6.2f} s  {label}")
    checks.finish()


if __name__ == "__main__":
    main()
