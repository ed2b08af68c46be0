# The shared hostile meshes (tests/hostile/hostile_meshes.py), built with from_pydata, through
# every operation twice: the operator bpy.ops.mesh.hedge_<id> and the Python API hedge.run.
# Each run either succeeds with a mesh Blender finds valid (Mesh.validate() has nothing to fix
# that the input did not already have) or is refused with the expected message
# (tests/hostile/outcomes.py) and leaves the mesh bit for bit as it was. Then every parameter of
# every operation at its limits through hedge.run (tests/hostile/limits.py): accepted at the
# limit, refused just beyond with the parameter's name, the mesh unchanged.
import os
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
sys.path.insert(0, os.path.join(HERE, "..", "hostile"))
import bpy  # noqa: E402
import numpy as np  # noqa: E402
import unittest  # noqa: E402
from blender_test import (ARGS, clear_scene, install_addon, mesh_arrays, object_from_pydata, problems,  # noqa: E402
                          run_tests)
import hostile_meshes  # noqa: E402
import limits  # noqa: E402
import outcomes  # noqa: E402

hedge = install_addon()


def object_from(case):
    return object_from_pydata(case.name, case.vertices, case.faces)


def same(before, after):
    """The keys whose arrays differ (NaN equal to NaN)."""
    if before.keys() != after.keys():
        return sorted(set(before) ^ set(after))
    return [k for k in before if before[k].shape != after[k].shape
            or not np.array_equal(before[k], after[k], equal_nan=before[k].dtype.kind == "f")]


def run_operator(op_id, **params):
    try:
        return getattr(bpy.ops.mesh, f"hedge_{op_id}")(**params), None
    except RuntimeError as e:
        return {'CANCELLED'}, str(e)


def run_api(obj, op_id, **params):
    try:
        hedge.run(obj, op_id, **params)
        return {'FINISHED'}, None
    except hedge.Error as e:
        return {'CANCELLED'}, str(e)


class HostileTest(unittest.TestCase):
    def test_every_case_every_operation(self):
        cases = [c for c in hostile_meshes.all_cases() if c.in_blender]
        ops = hedge.catalogue()
        table = outcomes.Table([c.name for c in cases], [op["id"] for op in ops])
        failures = []
        start = time.monotonic()
        for case in cases:
            for op in ops:
                cells = []
                for path in ("operator", "api"):
                    clear_scene()
                    obj = object_from(case)
                    me = obj.data
                    before = mesh_arrays(me)
                    invalid_before = problems(me)
                    if path == "operator":
                        result, error = run_operator(op["id"])
                    else:
                        result, error = run_api(obj, op["id"])
                    label = f"{case.name} / {op['id']} / {path}"
                    expected = outcomes.expected_refusal(case, op["id"])
                    if error is not None:
                        if expected is None or expected not in error:
                            failures.append(f"{label}: refused, expected {expected!r}: {error}")
                        changed = same(before, mesh_arrays(obj.data))
                        if changed:
                            failures.append(f"{label}: refused but changed {changed}")
                        cells.append(outcomes.short(error.removeprefix("Error: ").removeprefix(f"Hedge {op['title']}: ")))
                    else:
                        if result != {'FINISHED'}:
                            failures.append(f"{label}: {result}")
                        if expected is not None:
                            failures.append(f"{label}: succeeded, expected a refusal with {expected!r}")
                        invalid_after = problems(obj.data)
                        if invalid_after and not invalid_before:
                            failures.append(f"{label}: Mesh.validate() finds problems in the result")
                        note = " (validate() fixes the input too)" if invalid_after else ""
                        cells.append(f"ok, {len(obj.data.polygons)} faces{note}")
                table.set(case.name, op["id"], cells[0] if cells[0] == cells[1] else " / ".join(cells))
        print(f"\n{len(cases)} cases x {len(ops)} operations x 2 paths in {time.monotonic() - start:.1f} s\n")
        print(table.markdown())
        if ARGS.out:
            with open(os.path.join(ARGS.out, "hostile_table.md"), "w") as f:
                f.write(table.markdown())
        self.assertEqual(failures, [])

    def test_parameter_limits(self):
        case = hostile_meshes.small_open_cube()
        failures, runs = [], 0
        for op in hedge.catalogue():
            for p in op["params"]:
                for value, accepted in limits.cases(p):
                    clear_scene()
                    obj = object_from(case)
                    before = mesh_arrays(obj.data)
                    result, error = run_api(obj, op["id"], **{p["id"]: value})
                    runs += 1
                    label = f"hedge.run({op['id']}, {p['id']}={value!r})"
                    if accepted and error is not None:
                        failures.append(f"{label}: refused: {error}")
                    elif not accepted:
                        if error is None or not limits.refusal_names_parameter(error, op["id"], p):
                            failures.append(f"{label}: not refused naming the parameter: {error}")
                        elif same(before, mesh_arrays(obj.data)):
                            failures.append(f"{label}: refused but the mesh changed")
        print(f"\n{runs} parameter values through hedge.run")
        self.assertEqual(failures, [])


run_tests(HostileTest)
