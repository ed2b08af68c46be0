"""The shared hostile meshes (tests/hostile/hostile_meshes.py) through every Hedge filter in the
runner (meshlabserver, hedge-mlx), each run with a time limit. MeshLab reads the file with its own
importer first, which refuses or alters some cases before any filter runs (what happens is
asserted and printed below, per version). No run crashes (exit codes other than 0 and the runner's
filter failure, 255 or 1); on a refusal MeshLab's log carries the
filter's message and nothing is saved; on success the saved mesh reads back (hedge info) with
finite coordinates, and Repair's result builds again without any repair. Prints the outcomes as
a Markdown table."""
import concurrent.futures
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "hostile"))
import hostile_meshes  # noqa: E402
import mesh_files  # noqa: E402
import meshlab_test as mt  # noqa: E402
import outcomes  # noqa: E402

CRASHES = {134: "abort", 139: "segmentation fault", -6: "abort", -11: "segmentation fault", -9: "killed"}
TIMEOUT = 90

# What MeshLab's importers do to a case before the filter sees it, as found by this test.
# Refused outright: the file, with this phrase in the runner's output and its exit code (no output).
IMPORT_REFUSED = {  # the OFF reader stops at a face of < 3 vertices
    "meshlabserver": ({"short_faces": "It was not possible to import mesh"}, 255),
    "hedge-mlx": ({"short_faces": "cannot load"}, 3),
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


# 2021.05+ (hedge-mlx), found per case by loading and saving the file with no filter first:
# MeshLab's reader may abort on a file (Debian's 2025.07 build keeps vcg's assertions: a face
# repeating a vertex stops its OFF reader), drop vertices with non-finite coordinates with the faces
# on them ("Warning mesh contains N vertices with NAN coords"), and MeshLab refuses a filter that
# needs faces on a mesh with none (the preconditions, as its GUI greys the filter out).
NONFINITE_DROPPED = "vertices with NAN coords"
NEEDS_FACES = "cannot run on this mesh: it needs"


def expected_refusal(case, op_id, output=""):
    expected = outcomes.expected_refusal(case, op_id)
    if case.name in IMPORT_TRIANGULATES and expected in POLYGON_REFUSALS:
        return None
    if case.defect and NONFINITE_DROPPED in output:
        return None  # MeshLab's reader removed what hedge would refuse
    return expected


def imported(ml, case, path):
    """How this MeshLab's reader takes the file, with no filter: exit code, faces kept, whether it dropped vertices."""
    out = ml.path(f"{case.name}.imported.ply")
    code, output, _ = ml.convert(path, out)
    faces = mesh_files.ply_count(out, "face") if code == 0 and mesh_files.nonempty(out) else None
    return {"code": code, "faces": faces, "output": output}


def importer_outcome(ml, checks, table, label, case, op, code, output, out, view):
    """Checks a run whose outcome MeshLab decides before the filter runs; True if it was one."""
    if view["code"] not in (0, 3):
        checks.check(code == view["code"], f"{label}: MeshLab's reader stops on this file with no filter too "
                                           f"(exit {view['code']}); with the filter exit {code}")
        table.set(case.name, op["id"], f"MeshLab's reader aborts (exit {view['code']}, no filter needed)")
        return True
    if view["code"] == 0 and view["faces"] == 0:
        checks.check(code == ml.filter_failed and NEEDS_FACES in output and not os.path.exists(out),
                     f"{label}: MeshLab refuses the filter on a mesh without faces (exit {code})")
        table.set(case.name, op["id"], "MeshLab: the filter needs faces (its reader kept none)")
        return True
    return False


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
            try:
                code, output, seconds = ml.apply(path, out, [mt.hedge_filter(ml, op["id"])], name,
                                                         timeout=TIMEOUT)
            except mt.Failure as e:
                return case, op, out, None, str(e), TIMEOUT
            return case, op, out, code, output, seconds

        refused, refused_code = IMPORT_REFUSED[ml.runner]
        views = {case.name: imported(ml, case, path) for case, path in cases} if ml.runner == "hedge-mlx" else {}
        with concurrent.futures.ThreadPoolExecutor(2) as pool:
            futures = [pool.submit(one, case, path, op) for case, path in cases for op in ops]
            for future in futures:
                case, op, out, code, output, seconds = future.result()
                label = f"{case.name} / {op['id']}"
                if not checks.check(code is not None, f"{label}: finished within {TIMEOUT} s"):
                    table.set(case.name, op["id"], f"TIMEOUT > {TIMEOUT} s")
                    continue
                if case.name in views and importer_outcome(ml, checks, table, label, case, op, code, output, out,
                                                           views[case.name]):
                    continue
                crashed = code not in (0, ml.filter_failed) and not (case.name in refused and code == refused_code)
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
                if case.name in refused:
                    checks.check(code == refused_code and refused[case.name] in output and not os.path.exists(out),
                                 f"{label}: MeshLab's importer refuses the file, exit {refused_code}, nothing saved")
                    table.set(case.name, op["id"], "MeshLab's reader refuses the file")
                    continue
                expected = expected_refusal(case, op["id"], output)
                if code == ml.filter_failed:
                    checks.check(not os.path.exists(out), f"{label}: nothing saved after exit {code}")
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
        mt.write_table(ml, table, "hostile_table.md")
    finally:
        ml.close()
    checks.finish()


def mt_nonempty(path):
    return os.path.isfile(path) and os.path.getsize(path) > 0


if __name__ == "__main__":
    main()
