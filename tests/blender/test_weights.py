# Decimate's weights and locks in Blender: weight_attribute and lock_attribute name a vertex
# group (or a one-number point attribute). A weighted half of the bunny keeps more of the
# triangles than without weights; locked vertices come back where they were; the operator's
# field suggests the object's groups; a name the mesh lacks is refused and changes nothing.
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import bpy  # noqa: E402
import numpy as np  # noqa: E402
import unittest  # noqa: E402
from blender_test import clear_scene, get, install_addon, mesh_path, run_tests, select_only  # noqa: E402

hedge = install_addon()


def coordinates(me):
    return get(me.vertices, "co", len(me.vertices), np.float32, 3).reshape(-1, 3)


def faces_right_of(me, x):
    """Faces whose centroid lies right of x."""
    co = coordinates(me)
    corners = np.array(get(me.loops, "vertex_index", len(me.loops), np.int32))
    starts = get(me.polygons, "loop_start", len(me.polygons), np.int32)
    totals = get(me.polygons, "loop_total", len(me.polygons), np.int32)
    return sum(co[corners[s:s + t], 0].mean() > x for s, t in zip(starts, totals))


class WeightsTest(unittest.TestCase):
    def setUp(self):
        clear_scene()
        self.obj = hedge.api.import_file(mesh_path(self, "bunny.off"))
        select_only(self.obj)
        co = coordinates(self.obj.data)
        self.median = float(np.median(co[:, 0]))
        self.right = [i for i in range(len(co)) if co[i, 0] > self.median]
        self.pinned = list(range(0, len(co), 50))

    def add_group(self, name, indices, weight=1.0):
        group = self.obj.vertex_groups.new(name=name)
        group.add(indices, weight, 'REPLACE')
        return group

    def plain_copy(self):
        copy = self.obj.copy()
        copy.data = self.obj.data.copy()
        bpy.context.scene.collection.objects.link(copy)
        return copy

    def test_a_weighted_vertex_group_keeps_more_triangles(self):
        self.add_group("detail", self.right)
        plain = self.plain_copy()
        hedge.run(plain, "decimate", target_ratio=0.1)
        report = hedge.run(self.obj, "decimate", target_ratio=0.1, weight_attribute="detail")
        self.assertLessEqual(len(self.obj.data.polygons), report["target_faces"] + 1)
        weighted, unweighted = faces_right_of(self.obj.data, self.median), faces_right_of(plain.data, self.median)
        print(f"faces right of the median: {weighted} weighted, {unweighted} without weights")
        self.assertGreater(weighted, unweighted * 1.25)
        self.assertIn("detail", self.obj.vertex_groups)  # the group itself is carried

    def test_a_point_attribute_weighs_too(self):
        attribute = self.obj.data.attributes.new("density", 'FLOAT', 'POINT')
        values = np.zeros(len(self.obj.data.vertices), np.float32)
        values[self.right] = 1
        attribute.data.foreach_set("value", values)
        plain = self.plain_copy()
        hedge.run(plain, "decimate", target_ratio=0.1)
        hedge.run(self.obj, "decimate", target_ratio=0.1, weight_attribute="density")
        self.assertGreater(faces_right_of(self.obj.data, self.median), faces_right_of(plain.data, self.median) * 1.25)

    def test_locked_vertex_group_stays(self):
        pinned = {tuple(p) for p in coordinates(self.obj.data)[self.pinned].tolist()}
        self.add_group("pin", self.pinned)
        bpy.context.view_layer.objects.active = self.obj
        result = bpy.ops.mesh.hedge_decimate(target_ratio=0.1, lock_attribute="pin")
        self.assertEqual(result, {'FINISHED'})
        report = hedge.api.last_reports["decimate"]
        self.assertEqual(report["locked_vertices"], len(self.pinned))
        after = {tuple(p) for p in coordinates(self.obj.data).tolist()}
        self.assertEqual(pinned - after, set(), "locked vertices moved or went")
        self.assertLess(len(self.obj.data.polygons), 1000)

    def test_the_field_suggests_groups_and_attributes(self):
        from hedge import operators
        self.add_group("detail", self.right)
        self.obj.data.attributes.new("density", 'FLOAT', 'POINT')
        bpy.context.view_layer.objects.active = self.obj
        names = operators.vertex_attribute_names(None, bpy.context, "")
        self.assertIn("detail", names)
        self.assertIn("density", names)
        self.assertNotIn("position", names)
        self.assertEqual(operators.vertex_attribute_names(None, bpy.context, "DET"), ["detail"])

    def test_a_name_the_mesh_lacks_is_refused(self):
        faces = len(self.obj.data.polygons)
        self.add_group("detail", self.right)
        with self.assertRaises(hedge.Error) as caught:
            hedge.run(self.obj, "decimate", target_ratio=0.1, weight_attribute="nope")
        message = str(caught.exception)
        self.assertIn(f"weight_attribute: {self.obj.name} has no vertex group or point attribute 'nope'; it has: "
                      "detail", message)
        self.assertNotIn("vgroup:", message)  # Blender's names, not the exchange's
        self.assertEqual(len(self.obj.data.polygons), faces)


if __name__ == "__main__":
    run_tests(WeightsTest)
