"""The shared hostile meshes (tests/hostile/hostile_meshes.py) through every Hedge filter in
meshlabserver, each run with a time limit. MeshLab reads the file with its own importer first,
which refuses or alters some cases before any filter runs (what happens is asserted and printed
below). No run crashes (exit codes other than 0 and 255); on a refusal MeshLab's log carries the
filter's message and nothing is saved; on success the saved mesh reads back (hedge info) with
finite coordinates, and Repair's result builds again without any repair. Prints the outcomes as
a Markdown table."""
import concurrent.futures
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "hostile"))
import hostile_meshes  # noqa: E402
import meshlab_test as mt  # noqa: E402
import outcomes  # noqa: E402

CRASHES = {134: "abort", 139: "segmentation fault", -6: "abort", -11: "segmentation fault", -9: "killed"}
TIMEOUT = 90

# What MeshLab 2020.09's importers do to a case before the filter sees it, as found by this test.
# Refused outright: the file, with this phrase in meshlabserver's output (exit 255, no output).
IMPORT_REFUSED = {
    "short_faces": "It was not possible to import mesh",  # the OFF reader stops at a face of < 3 vertices
}
# Polygons triangulated on import (a fan, or GLU's tessellator), so the refusals that are about
# polygons (loop subdivision, Delaunay flips) do not apply, nor remesh's refusal of the
# 100,000-gon's mean edge length (the triangulation's diagonals make the mean 0.59).
IMPORT_TRIANGULATES = {"huge_polygon", "repeated_vertex_faces"}
POLYGON_REFUSALS = {outcomes.LOOP_TRIANGLES, outcomes.DELAUNAY_TRIANGLES, outcomes.REMESH_TOO_MANY}
# Kept with a face pointing past the end of the vertex array, which MeshLab then writes through
# (per-vertex normals): our filter refuses the face, but the heap is already corrupted and
# meshlabserver may crash on its own, before or after our filter, at random.
IMPORT_CORRUPTS = {"index_out_of_range"}


def expected_refusal(case, op_id):
    expected = outcomes.expected_refusal(case, op_id)
    if case.name in IMPORT_TRIANGULATES and expected in POLYGON_REFUSALS:
        return None
    return expected


def main():
    args = mt.parse_args()
    checks = outcomes.Checks()
    ml = mt.MeshLab(args)
    try:
        cases = hostile_meshes.write_all(os.path.join(ml.out, "cases"))
        ops = ml.catalogue["operations"]
        table = outcomes.Table([c.name for c, _ in cases], [op["id"] for op in ops])

        def one(case, path, op):
            name = f"{case.name}.{op['id']}"
            out = ml.path(name + ".ply")
            for attempt in range(3):
                try:
                    code, output, seconds = ml.apply(path, out, [mt.hedge_filter(ml, op["id"])], name, timeout=TIMEOUT)
                except mt.Failure as e:
                    return case, op, out, None, str(e), TIMEOUT
                # Once in a few hundred runs on a loaded machine, meshlabserver dies before it
                # loads any plugin (SIGPIPE, or Qt "could not connect to display" and abort): its
                # X connection failed, the run did not happen; run it again.
                if code in (0, 255) or "Loading Plugins" in output:
                    break
                print(f"  NOTE  {name}: meshlabserver died before starting (exit {code}); run again")
            return case, op, out, code, output, seconds

        with concurrent.futures.ThreadPoolExecutor(2) as pool:
            futures = [pool.submit(one, case, path, op) for case, path in cases for op in ops]
            for future in futures:
                case, op, out, code, output, seconds = future.result()
                label = f"{case.name} / {op['id']}"
                if not checks.check(code is not None, f"{label}: finished within {TIMEOUT} s"):
                    table.set(case.name, op["id"], f"TIMEOUT > {TIMEOUT} s")
                    continue
                crashed = code not in (0, 255)
                if crashed and case.name in IMPORT_CORRUPTS:
                    print(f"  NOTE  {label}: meshlabserver crashed (exit {code}) after its reader corrupted the heap")
                    table.set(case.name, op["id"], table.get(case.name, op["id"]) or "MeshLab crashed (its reader)")
                    continue
                checks.check(not crashed, f"{label}: no crash (exit {code} {CRASHES.get(code, '')})")
                if crashed:
                    print(output[-2000:])
                    table.set(case.name, op["id"], f"CRASH (exit {code})")
                    continue
                failed = f"{op['filter']} failed: "
                if case.name in IMPORT_REFUSED:
                    checks.check(code == 255 and IMPORT_REFUSED[case.name] in output and not os.path.exists(out),
                                 f"{label}: MeshLab's importer refuses the file, exit 255, nothing saved")
                    table.set(case.name, op["id"], "MeshLab's reader refuses the file")
                    continue
                expected = expected_refusal(case, op["id"])
                if code == 255:
                    checks.check(not os.path.exists(out), f"{label}: nothing saved after exit 255")
                    message = output.split(failed, 1)[1].splitlines()[0] if failed in output else ""
                    checks.check(expected is not None and expected in message,
                                 f"{label}: refused as expected ({expected!r}): {message or output[-1500:]}")
                    table.set(case.name, op["id"], outcomes.short(message, case))
                    continue
                if op["changes_mesh"]:
                    if not checks.check(mt_nonempty(out), f"{label}: result saved"):
                        continue
                    try:
                        info = ml.info(out)
                    except mt.Failure as e:
                        checks.check(False, f"{label}: the result reads back: {e}")
                        continue
                    if op["id"] == "repair":
                        bad = {k: v for k, v in info["repairs"].items() if v and k != "isolated_vertices"}
                        checks.check(not bad, f"{label}: builds again without repair ({bad or 'none'})")
                    table.set(case.name, op["id"], f"ok, {info['faces']} faces")
                else:
                    table.set(case.name, op["id"], "ok")
                checks.check(expected is None, f"{label}: succeeded, expected a refusal with {expected!r}")
                if case.name in IMPORT_TRIANGULATES:
                    table.set(case.name, op["id"], table.get(case.name, op["id"]) + " (triangulated by MeshLab's reader)")
        print(table.markdown())
        with open(ml.path("hostile_table.md"), "w") as f:
            f.write(table.markdown())
    finally:
        ml.close()
    checks.finish()


def mt_nonempty(path):
    return os.path.isfile(path) and os.path.getsize(path) > 0


if __name__ == "__main__":
    main()
