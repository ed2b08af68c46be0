# selection_only in Blender: the operators in Edit Mode follow its selection, hedge.run() the
# mesh's stored one. Faces outside the selection come back as they were (decimate, remesh,
# subdivide, triangulate, make_delaunay); smoothing moves only the selected vertices; nothing selected changes nothing.
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import bmesh  # noqa: E402
import bpy  # noqa: E402
import numpy as np  # noqa: E402
import unittest  # noqa: E402
from blender_test import (boundary_loops, clear_scene, get, install_addon, mesh_path, problems, run_tests,  # noqa: E402
                          select_only)

hedge = install_addon()


def corner_positions(me):
    """Per face, its corner positions from the smallest on (renumbering does not matter), and
    whether it is selected."""
    co = get(me.vertices, "co", len(me.vertices), np.float32, 3).reshape(-1, 3)
    corners = get(me.loops, "vertex_index", len(me.loops), np.int32).tolist()
    starts = get(me.polygons, "loop_start", len(me.polygons), np.int32).tolist()
    totals = get(me.polygons, "loop_total", len(me.polygons), np.int32).tolist()
    selected = get(me.polygons, "select", len(me.polygons), np.bool_).tolist()
    out = []
    for s, t, sel in zip(starts, totals, selected):
        points = [tuple(co[v].tolist()) for v in corners[s:s + t]]
        first = points.index(min(points))
        out.append((tuple(points[first:] + points[:first]), sel))
    return out


def faces_where(me, want):
    return sorted(points for points, sel in corner_positions(me) if sel == want)


def select_left_half(obj, quads=False):
    """In Edit Mode: selects the faces whose first corner lies left of the median x."""
    bpy.ops.object.mode_set(mode='EDIT')
    bpy.ops.mesh.select_mode(type='FACE')
    bm = bmesh.from_edit_mesh(obj.data)
    if quads:
        # A quad per pair of triangles where it can, so triangulate has work in the selection.
        bmesh.ops.join_triangles(bm, faces=bm.faces[:], angle_face_threshold=3.14, angle_shape_threshold=3.14)
    xs = sorted(f.loops[0].vert.co.x for f in bm.faces)
    median = xs[len(xs) // 2]
    for f in bm.faces:
        f.select_set(False)
    for f in bm.faces:
        if f.loops[0].vert.co.x < median:
            f.select_set(True)
    bm.select_flush_mode()
    bmesh.update_edit_mesh(obj.data)
    obj.update_from_editmode()


class SelectionTest(unittest.TestCase):
    def setUp(self):
        clear_scene()
        self.obj = hedge.api.import_file(mesh_path(self, "bunny.off"))
        select_only(self.obj)

    def tearDown(self):
        if bpy.context.object is not None and bpy.context.object.mode != 'OBJECT':
            bpy.ops.object.mode_set(mode='OBJECT')

    def check_outside_kept(self, op_id, quads=False, **params):
        select_left_half(self.obj, quads)
        me = self.obj.data
        outside, inside = faces_where(me, False), faces_where(me, True)
        self.assertGreater(len(inside), 1000)
        result = getattr(bpy.ops.mesh, f"hedge_{op_id}")(selection_only=True, **params)
        self.assertEqual(result, {'FINISHED'})
        bpy.ops.object.mode_set(mode='OBJECT')
        self.assertEqual(faces_where(me, False), outside, f"{op_id} changed faces outside the selection")
        self.assertNotEqual(faces_where(me, True), inside, f"{op_id} did nothing inside the selection")
        return outside, inside

    def test_decimate_in_edit_mode(self):
        outside, inside = self.check_outside_kept("decimate", target_ratio=0.25)
        faces = len(self.obj.data.polygons)
        target = len(outside) + round(0.25 * len(inside))
        self.assertLessEqual(abs(faces - target), 1)

    def test_triangulate_in_edit_mode(self):
        self.check_outside_kept("triangulate", quads=True)
        # Quads outside the selection are still quads.
        self.assertTrue(any(len(points) == 4 for points in faces_where(self.obj.data, False)))

    def test_make_delaunay_in_edit_mode(self):
        self.check_outside_kept("make_delaunay")

    def test_subdivide_in_edit_mode(self):
        # Loop refines the selected triangles; those along the border close up without splitting it.
        outside, inside = self.check_outside_kept("subdivide")
        self.assertGreater(len(faces_where(self.obj.data, True)), 3 * len(inside))
        self.assertFalse(problems(self.obj.data))

    def test_remesh_in_edit_mode(self):
        self.check_outside_kept("remesh", iterations=3)
        self.assertFalse(problems(self.obj.data))

    def test_fill_holes_with_a_selected_border(self):
        # Two holes cut in the bunny; the border of the left one selected, vertex by vertex.
        me = self.obj.data
        bpy.ops.object.mode_set(mode='EDIT')
        bpy.ops.mesh.select_mode(type='VERT')
        bm = bmesh.from_edit_mesh(me)
        left = min(bm.verts, key=lambda v: v.co.x).co.copy()
        right = max(bm.verts, key=lambda v: v.co.x).co.copy()
        doomed = [f for f in bm.faces
                  if any((v.co - left).length < 0.5 or (v.co - right).length < 0.5 for v in f.verts)]
        bmesh.ops.delete(bm, geom=doomed, context='FACES_ONLY')
        for element in list(bm.verts) + list(bm.edges) + list(bm.faces):
            element.select_set(False)
        for v in bm.verts:
            if v.is_boundary and (v.co - left).length < 2:
                v.select_set(True)
        bm.select_flush_mode()
        bmesh.update_edit_mesh(me)
        self.obj.update_from_editmode()
        self.assertEqual(boundary_loops(me), 2)
        faces = len(me.polygons)
        self.assertEqual(bpy.ops.mesh.hedge_fill_holes(selection_only=True), {'FINISHED'})
        bpy.ops.object.mode_set(mode='OBJECT')
        report = hedge.api.last_reports["fill_holes"]
        self.assertEqual((report["holes_filled"], report["holes_not_selected"]), (1, 1))
        self.assertEqual(boundary_loops(me), 1)
        self.assertGreater(len(me.polygons), faces)

    def test_smooth_moves_only_selected_vertices(self):
        me = self.obj.data
        n = len(me.vertices)
        chosen = np.arange(n) % 3 == 0
        me.vertices.foreach_set("select", chosen)
        before = get(me.vertices, "co", n, np.float32, 3).reshape(-1, 3)
        report = hedge.run(self.obj, "smooth", selection_only=True, iterations=5)
        after = get(me.vertices, "co", n, np.float32, 3).reshape(-1, 3)
        moved = np.any(after != before, axis=1)
        self.assertFalse(np.any(moved & ~chosen), "an unselected vertex moved")
        self.assertGreater(int(moved.sum()), n // 4)
        # Free to move: the selected vertices off the boundary (which stays by default).
        self.assertGreaterEqual(report["moved_vertices"], int(moved.sum()))
        self.assertLess(report["moved_vertices"], n // 2)

    def test_nothing_selected_changes_nothing(self):
        me = self.obj.data
        me.polygons.foreach_set("select", np.zeros(len(me.polygons), np.bool_))
        me.vertices.foreach_set("select", np.zeros(len(me.vertices), np.bool_))
        before = corner_positions(me)
        report = hedge.run(self.obj, "decimate", selection_only=True, target_ratio=0.1)
        self.assertEqual(corner_positions(me), before)
        self.assertIn("selection_only: nothing is selected, so the mesh is unchanged", report.get("messages", []))


run_tests(SelectionTest)
