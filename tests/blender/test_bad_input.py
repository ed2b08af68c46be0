# Bad input through every operator: non-manifold edges (three faces on one edge), wire edges,
# loose vertices, an empty mesh, non-manifold scans; no crash, a clear report, and on refusal
# the mesh exactly as before. Out-of-range properties are clamped or refused by Blender.
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import bpy  # noqa: E402
import numpy as np  # noqa: E402
import unittest  # noqa: E402
from blender_test import clear_scene, import_mesh, install_addon, mesh_arrays, mesh_path, run_tests, select_only  # noqa: E402

hedge = install_addon()


def object_from(name, vertices, edges, faces):
    me = bpy.data.meshes.new(name)
    me.from_pydata(vertices, edges, faces)
    obj = bpy.data.objects.new(name, me)
    bpy.context.collection.objects.link(obj)
    select_only(obj)
    return obj


def nasty():
    """Three faces on one edge, a bow-tie vertex, a wire edge, loose vertices, a quad."""
    v = [(0, 0, 0), (1, 0, 0), (0.5, 1, 0), (0.5, -1, 0), (0.5, 0, 1),  # fin: 3 faces on 0-1
         (2, 0, 0), (3, 1, 0), (3, -1, 0), (4, 0, 0), (4, 1, 0),       # bow-tie at 5? (shared by two fans)
         (6, 6, 6), (7, 7, 7),                                         # wire edge
         (9, 9, 9),                                                    # loose vertex
         (0, 3, 0), (1, 3, 0), (1, 4, 0), (0, 4, 0)]                   # a quad
    e = [(10, 11)]
    f = [(0, 1, 2), (1, 0, 3), (0, 1, 4), (1, 5, 6), (5, 7, 8), (5, 8, 9), (13, 14, 15, 16)]
    return object_from("nasty", v, e, f)


def call(op, **params):
    """Runs an operator; returns (result, error text)."""
    try:
        return getattr(bpy.ops.mesh, f"hedge_{op}")(**params), None
    except RuntimeError as e:
        return {'CANCELLED'}, str(e)


class BadInputTest(unittest.TestCase):
    def setUp(self):
        clear_scene()

    def every_operator(self, make, params=None):
        """Every operator on a fresh make(): success, or a refusal that names Hedge and leaves
        the mesh as it was; returns the outcome of each."""
        outcomes = {}
        for op in hedge.catalogue():
            clear_scene()
            obj = make()
            before = mesh_arrays(obj.data)
            result, error = call(op["id"], **(params or {}).get(op["id"], {}))
            if error:
                self.assertIn("Hedge", error)
                after = mesh_arrays(obj.data)
                for key in before:
                    self.assertTrue(np.array_equal(before[key], after[key]), f"{op['id']} changed {key} on refusal")
            else:
                self.assertEqual(result, {'FINISHED'})
            outcomes[op["id"]] = error or "ok"
        print("\n" + "\n".join(f"  {k}: {v}" for k, v in outcomes.items()))
        return outcomes

    def test_nasty_mesh(self):
        outcomes = self.every_operator(nasty)
        self.assertEqual(outcomes["report"], "ok")
        report = hedge.run(nasty(), "report")
        self.assertTrue(any("non-manifold" in m for m in report["messages"]), report["messages"])

    def test_empty_mesh(self):
        self.every_operator(lambda: object_from("empty", [], [], []))

    def test_only_loose_geometry(self):
        self.every_operator(lambda: object_from("loose", [(0, 0, 0), (1, 0, 0), (2, 2, 2)], [(0, 1)], []))

    def test_nan_refused_unchanged(self):
        obj = nasty()
        co = np.empty(len(obj.data.vertices) * 3, np.float32)
        obj.data.vertices.foreach_get("co", co)
        co[3] = np.nan
        obj.data.vertices.foreach_set("co", co)
        before = mesh_arrays(obj.data)
        result, error = call("decimate")
        self.assertIsNotNone(error)
        self.assertIn("NaN", error)
        after = mesh_arrays(obj.data)
        self.assertTrue(np.array_equal(before["loop_vertex"], after["loop_vertex"]))
        self.assertTrue(np.array_equal(before["co"], after["co"], equal_nan=True))
        with self.assertRaises(hedge.Error):
            hedge.run(obj, "smooth")

    def test_broken_shape_keys_refused(self):
        # Keys follow every operation (test_shape_keys); keys with a NaN are refused, unchanged.
        obj = object_from("keyed", [(0, 0, 0), (1, 0, 0), (0, 1, 0), (1, 1, 0)], [], [(0, 1, 3, 2)])
        obj.shape_key_add(name="Basis")
        key = obj.shape_key_add(name="Key 1")
        co = np.array([0, 0, 0, 1, 0, 0, 0, np.inf, 0, 1, 1, 0], np.float32)
        key.data.foreach_set("co", co)  # not clamped to the property's range, as data[2].co = ... is
        before = mesh_arrays(obj.data)
        result, error = call("subdivide", scheme='midpoint')
        self.assertIn("shape key 'Key 1'", error)
        self.assertIn("NaN or infinite", error)
        after = mesh_arrays(obj.data)
        for k in before:
            self.assertTrue(np.array_equal(before[k], after[k]), k)
        self.assertEqual(len(obj.data.shape_keys.key_blocks["Key 1"].data), 4)
        co[7] = 1
        key.data.foreach_set("co", co)
        self.assertEqual(call("subdivide", scheme='midpoint')[0], {'FINISHED'})
        self.assertEqual(len(obj.data.shape_keys.key_blocks["Key 1"].data), len(obj.data.vertices))

    def test_out_of_range_properties(self):
        obj = nasty()
        bpy.ops.mesh.hedge_decimate(target_ratio=5.0)  # clamped by the property's hard maximum
        self.assertEqual(hedge.api.last_params["decimate"]["target_ratio"], 1.0)
        with self.assertRaises(TypeError):
            bpy.ops.mesh.hedge_subdivide(scheme='no_such_scheme')
        with self.assertRaises(TypeError):
            bpy.ops.mesh.hedge_smooth(no_such_property=1)
        bpy.ops.mesh.hedge_smooth(iterations=-5)
        self.assertEqual(hedge.api.last_params["smooth"]["iterations"], 1)
        with self.assertRaises(hedge.Error) as ctx:
            hedge.run(obj, "smooth", iterations=0)
        self.assertIn("iterations", str(ctx.exception))

    def test_non_manifold_scans(self):
        params = {"subdivide": {"scheme": 'midpoint'}, "remesh": {"iterations": 1}}
        for name in ("dragon_res3.ply", "dragon_res4.ply"):
            path = mesh_path(self, name)
            outcomes = self.every_operator(lambda: import_mesh(path), params)
            self.assertEqual(outcomes["report"], "ok", name)


run_tests(BadInputTest)
