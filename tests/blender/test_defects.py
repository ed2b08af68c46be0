# No operator leaves the mesh worse than it found it: every operator that changes the mesh, with
# its defaults, on real meshes (the bunny, the non-manifold dragon_res4 and dragon_res3) and on the
# small meshes made to have defects (tests/hostile/defects.py), each built with from_pydata from
# the file's or the case's own faces. The result has no more non-manifold edges, non-manifold
# vertices, duplicate faces or faces repeating a vertex than the input, category by category
# (counted by defects.py, not by hedge), and where Mesh.validate() finds nothing to fix in (a copy
# of) the input it finds nothing in (a copy of) the result either.
import os
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
sys.path.insert(0, os.path.join(HERE, "..", "hostile"))
import bpy  # noqa: E402
import unittest  # noqa: E402
from blender_test import (ARGS, clear_scene, faces_of, install_addon, mesh_path, object_from_pydata,  # noqa: E402
                          problems, run_tests)
import defects  # noqa: E402
import outcomes  # noqa: E402

hedge = install_addon()
REAL = ("bunny.off", "dragon_res4.ply", "dragon_res3.ply")


class DefectsTest(unittest.TestCase):
    def test_no_operator_adds_defects(self):
        meshes = [(name, defects.read_mesh(mesh_path(self, name))) for name in REAL]
        meshes += [(case.name, (case.vertices, case.faces)) for case in defects.cases()]
        ops = [op for op in hedge.catalogue() if op["changes_mesh"]]
        table = outcomes.Table([name for name, _ in meshes], ["input"] + [op["id"] for op in ops])
        failures = []
        start = time.monotonic()
        for name, (vertices, faces) in meshes:
            for op in ops:
                clear_scene()
                obj = object_from_pydata(name, vertices, faces)
                given = faces_of(obj.data)
                before, invalid_before = defects.count(given), problems(obj.data)
                if faces_of(obj.data) != given:
                    failures.append(f"{name}: validate() of a copy changed the mesh itself")
                table.set(name, "input", defects.cell(before) + (" (validate() fixes it)" if invalid_before else ""))
                label = f"{op['id']} on {name}"
                try:
                    result = getattr(bpy.ops.mesh, f"hedge_{op['id']}")()
                except RuntimeError as e:
                    failures.append(f"{label}: refused: {e}")
                    table.set(name, op["id"], "refused")
                    continue
                if result != {'FINISHED'}:
                    failures.append(f"{label}: {result}")
                after = defects.count(faces_of(obj.data))
                steps = int(op["id"] == "subdivide")  # its default: one step
                failures += [message for passed, message in defects.verdicts(label, before, after, steps) if not passed]
                invalid_after = problems(obj.data)
                if invalid_after and not invalid_before:
                    failures.append(f"{label}: Mesh.validate() finds problems in the result, none in the input")
                worse = defects.increases(before, after, steps) or (invalid_after and not invalid_before)
                table.set(name, op["id"], defects.cell(after) + (" (validate() fixes it)" if invalid_after else "")
                          + (" WORSE" if worse else ""))
        print(f"\n{len(meshes)} meshes x {len(ops)} operators in {time.monotonic() - start:.1f} s")
        print(defects.CELL_KEY + "\n")
        print(table.markdown())
        if ARGS.out:
            with open(os.path.join(ARGS.out, "defects_table.md"), "w") as f:
                f.write(table.markdown())
        self.assertEqual(failures, [], "\n".join(failures))


run_tests(DefectsTest)
