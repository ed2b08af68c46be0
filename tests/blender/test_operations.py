# Every operator on Blender's own primitives (cube, UV sphere, Suzanne) and on real meshes,
# with the results checked: face counts, holes, edge lengths, UV layers and their continuity,
# attributes kept; Edit Mode; undo; batch API errors.
import gc
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import bmesh  # noqa: E402
import bpy  # noqa: E402
import numpy as np  # noqa: E402
import unittest  # noqa: E402
from blender_test import (FREESTYLE_MARKS, LAYERS, add_primitive, boundary_loops, clear_scene, counts,  # noqa: E402
                          edge_lengths, import_mesh, install_addon, mesh_arrays, mesh_path, run_tests, select_only,
                          set_layer)

hedge = install_addon()


def uv_seam_edges(me, layer):
    """Edges with two faces whose UVs differ at either end (UV seams), counted with numpy."""
    nl = len(me.loops)
    uv = np.empty(nl * 2, np.float32)
    me.uv_layers[layer].data.foreach_get("uv", uv)
    uv = uv.reshape(-1, 2)
    v = np.empty(nl, np.int32)
    e = np.empty(nl, np.int32)
    me.loops.foreach_get("vertex_index", v)
    me.loops.foreach_get("edge_index", e)
    total = np.empty(len(me.polygons), np.int32)
    start = np.empty(len(me.polygons), np.int32)
    me.polygons.foreach_get("loop_total", total)
    me.polygons.foreach_get("loop_start", start)
    face = np.repeat(np.arange(len(total)), total)
    nxt = np.arange(nl) + 1
    last = start + total - 1
    nxt[last] = start
    # Per loop: its edge, and the UVs at the edge's lower and higher vertex from this face.
    lo_first = v < v[nxt]
    uv_lo = np.where(lo_first[:, None], uv, uv[nxt])
    uv_hi = np.where(lo_first[:, None], uv[nxt], uv)
    order = np.argsort(e, kind="stable")
    es, lo, hi = e[order], uv_lo[order], uv_hi[order]
    pair = es[1:] == es[:-1]
    differ = pair & (np.any(lo[1:] != lo[:-1], axis=1) | np.any(hi[1:] != hi[:-1], axis=1))
    del face
    return int(differ.sum())


def add_uv_sphere():
    obj = add_primitive("uv_sphere", segments=48, ring_count=24)
    return obj


def punch_holes(obj, centres, radius):
    """Deletes the faces whose centre lies near each of `centres` (one hole each)."""
    select_only(obj)
    me = obj.data
    c = np.empty(len(me.polygons) * 3, np.float32)
    me.polygons.foreach_get("center", c)
    c = c.reshape(-1, 3)
    near = np.zeros(len(c), bool)
    for p in centres:
        near |= np.linalg.norm(c - np.asarray(p, np.float32), axis=1) < radius
    bpy.ops.object.mode_set(mode='EDIT')
    bm = bmesh.from_edit_mesh(obj.data)
    bm.faces.ensure_lookup_table()
    bmesh.ops.delete(bm, geom=[bm.faces[i] for i in np.flatnonzero(near)], context='FACES_ONLY')
    bmesh.update_edit_mesh(obj.data)
    bpy.ops.object.mode_set(mode='OBJECT')
    return obj


def add_attributes(obj):
    me = obj.data
    nv, nf, nl = len(me.vertices), len(me.polygons), len(me.loops)
    a = me.attributes.new("temperature", 'FLOAT', 'POINT')
    a.data.foreach_set("value", np.linspace(0, 1, nv, dtype=np.float32))
    b = me.attributes.new("face_id", 'INT', 'FACE')
    b.data.foreach_set("value", np.arange(nf, dtype=np.int32) % 7)
    c = me.color_attributes.new("paint", 'BYTE_COLOR', 'CORNER')
    c.data.foreach_set("color_srgb", np.tile(np.array([1, 0.5, 0.25, 1], np.float32), nl))
    me.polygons.foreach_set("material_index", (np.arange(nf) % 2).astype(np.int32))


# Operations that need triangles get a triangulated primitive (they refuse polygons, tested
# in test_bad_input); remesh gets a target that keeps it quick.
NEEDS_TRIANGLES = {"make_delaunay", "subdivide"}
PARAMS = {"remesh": {"target_edge_length": 0.15, "iterations": 3}}


class PrimitivesTest(unittest.TestCase):
    def setUp(self):
        clear_scene()

    def test_every_operator_on_every_primitive(self):
        for kind in ("cube", "uv_sphere", "monkey"):
            for op in hedge.catalogue():
                clear_scene()
                obj = add_primitive(kind)
                if op["id"] in NEEDS_TRIANGLES:
                    bpy.ops.mesh.hedge_triangulate()
                result = getattr(bpy.ops.mesh, f"hedge_{op['id']}")(**PARAMS.get(op["id"], {}))
                self.assertEqual(result, {'FINISHED'}, f"{op['id']} on {kind}")
                me = obj.data
                self.assertFalse(me.validate(), f"{op['id']} on {kind} left an invalid mesh")
                self.assertGreater(len(me.polygons), 0)
                self.assertIn("UVMap", me.uv_layers, f"{op['id']} on {kind}")

    def test_decimate_keeps_uvs_and_attributes(self):
        obj = add_uv_sphere()
        add_attributes(obj)
        bpy.ops.mesh.hedge_triangulate()
        me = obj.data
        faces = len(me.polygons)
        seams = uv_seam_edges(me, "UVMap")
        bpy.ops.mesh.hedge_decimate(target_ratio=0.2)
        self.assertAlmostEqual(len(me.polygons), faces * 0.2, delta=faces * 0.02)
        self.assertIn("UVMap", me.uv_layers)
        self.assertLessEqual(uv_seam_edges(me, "UVMap"), seams, "decimate made new UV seams")
        self.assertIn("temperature", me.attributes)
        self.assertEqual(me.attributes["temperature"].domain, 'POINT')
        self.assertEqual(me.attributes["face_id"].data_type, 'INT')
        self.assertIn("paint", me.color_attributes)
        arr = mesh_arrays(me)
        # Byte colours hold n/255: 0.5 -> 128/255.
        self.assertTrue(np.all(np.abs(arr["attr:paint:CORNER"].reshape(-1, 4) - [1, 0.5, 0.25, 1]) <= 1 / 255))
        self.assertTrue(set(np.unique(arr["material"])) <= {0, 1})
        t = arr["attr:temperature:POINT"]
        self.assertTrue(np.all((t >= 0) & (t <= 1)))
        self.assertEqual(boundary_loops(me), 0)

    def test_subdivide_cube_and_suzanne(self):
        cube = add_primitive("cube")
        bpy.ops.mesh.hedge_subdivide(scheme='catmull_clark', iterations=2)
        self.assertEqual(len(cube.data.polygons), 6 * 16)
        self.assertTrue(np.all(mesh_arrays(cube.data)["loop_total"] == 4))
        self.assertIn("UVMap", cube.data.uv_layers)
        monkey = add_primitive("monkey")
        bpy.ops.mesh.hedge_triangulate(method='ear_clipping')
        n = len(monkey.data.polygons)
        self.assertTrue(np.all(mesh_arrays(monkey.data)["loop_total"] == 3))
        bpy.ops.mesh.hedge_subdivide(scheme='loop', iterations=1)
        self.assertEqual(len(monkey.data.polygons), 4 * n)

    def test_subdivide_creases_keep_the_cube(self):
        # crease_angle reaches the operator: at 60 degrees the cube's 12 edges are creases, so
        # loop and sqrt3 (Kobbelt's boundary rule on them) keep it a cube of side 2; at 180 it rounds off.
        for scheme, iterations, faces in (('loop', 2, 12 * 16), ('sqrt3', 2, 12 * 9 + 4 * 12)):
            for angle in (60.0, 180.0):
                cube = add_primitive("cube")
                bpy.ops.mesh.hedge_triangulate(method='min_area')
                result = bpy.ops.mesh.hedge_subdivide(scheme=scheme, iterations=iterations, crease_angle=angle)
                self.assertEqual(result, {'FINISHED'})
                self.assertEqual(len(cube.data.polygons), faces if angle < 180 else 12 * (16 if scheme == 'loop' else 9))
                p = mesh_arrays(cube.data)["co"].reshape(-1, 3)
                on_side = np.isclose(np.abs(p), 1, atol=1e-5).any(axis=1)
                if angle < 180:
                    self.assertTrue(np.all(on_side), f"{scheme}: a vertex left the cube's surface")
                    self.assertTrue(np.all(np.abs(p) <= 1 + 1e-5))
                else:
                    self.assertFalse(np.all(on_side), f"{scheme}: the uncreased cube did not round off")
                bpy.data.objects.remove(cube)

    def test_triangulate_polygons(self):
        obj = add_primitive("cylinder", vertices=32)  # two 32-gons and quads
        bpy.ops.mesh.hedge_triangulate(method='min_area')
        arr = mesh_arrays(obj.data)
        self.assertTrue(np.all(arr["loop_total"] == 3))
        self.assertEqual(len(obj.data.polygons), 2 * 30 + 2 * 32)

    def test_fill_holes(self):
        obj = punch_holes(add_uv_sphere(), [(1, 0, 0), (0, 1, 0), (0, -0.6, 0.8)], 0.25)
        self.assertEqual(boundary_loops(obj.data), 3)
        self.assertEqual(hedge.run(obj, "report")["boundary_loops"], 3)
        faces = len(obj.data.polygons)
        report = hedge.run(obj, "fill_holes")
        self.assertEqual(report["holes_filled"], 3)
        self.assertEqual(boundary_loops(obj.data), 0, report)
        self.assertGreater(len(obj.data.polygons), faces)
        self.assertIn("UVMap", obj.data.uv_layers)

    def test_remesh_edge_lengths(self):
        obj = add_uv_sphere()
        bpy.ops.mesh.hedge_remesh(target_edge_length=0.1, iterations=5)
        lengths = edge_lengths(obj.data)
        self.assertTrue(np.all(mesh_arrays(obj.data)["loop_total"] == 3))
        self.assertAlmostEqual(float(np.mean(lengths)), 0.1, delta=0.02)
        self.assertLess(float(np.std(lengths) / np.mean(lengths)), 0.3)

    def test_edge_data_follows_a_rebuild(self):
        # Triangulating the cube rebuilds the mesh: its 12 edges keep seams, sharpness, freestyle
        # marks, creases and bevel weights (properties in 3.x, attributes from 4.0), the 6 new
        # diagonals have none, and every datum exists once (no sharp_edge.001).
        me = add_primitive("cube").data
        for prop in ("use_seam", "use_edge_sharp") + (("use_freestyle_mark",) if FREESTYLE_MARKS else ()):
            me.edges.foreach_set(prop, np.ones(12, bool))
        for key, (collection, _, _, _) in LAYERS.items():
            set_layer(me, key, np.full(len(getattr(me, collection)), 0.5, np.float32))
        names = sorted(a.name for a in me.attributes if not a.name.startswith("."))
        self.assertEqual(bpy.ops.mesh.hedge_triangulate(), {'FINISHED'})
        self.assertEqual(len(me.edges), 18)
        arr = mesh_arrays(me)
        self.assertEqual(sorted(a.name for a in me.attributes if not a.name.startswith(".")), names)
        self.assertFalse(arr["smooth"].any(), "the flat cube came back smooth")
        per_edge = [k for k in arr if k.startswith("edge:") or k.endswith(":EDGE")]
        self.assertGreaterEqual(len(per_edge), 4 + FREESTYLE_MARKS, per_edge)
        for key in per_edge:
            self.assertEqual(np.count_nonzero(arr[key]), 12, key)
        self.assertTrue(np.all(arr["vertex:bevel_weight" if "vertex:bevel_weight" in arr
                                   else "attr:bevel_weight_vert:POINT"] == 0.5))

    def test_smooth_in_place_keeps_everything(self):
        obj = add_primitive("monkey")
        vg = obj.vertex_groups.new(name="left")
        vg.add(list(range(0, 200)), 0.75, 'REPLACE')
        obj.data.edges.foreach_set("use_seam", np.arange(len(obj.data.edges)) % 5 == 0)
        before = mesh_arrays(obj.data)
        bpy.ops.mesh.hedge_smooth(method='taubin', iterations=5)
        after = mesh_arrays(obj.data)
        self.assertFalse(np.array_equal(before["co"], after["co"]))
        for key in ("loop_vertex", "loop_total", "edges", "edge:seam", "material", "uv:UVMap"):
            self.assertTrue(np.array_equal(before[key], after[key]), key)
        self.assertEqual(obj.vertex_groups["left"].weight(150), 0.75)

    def test_vertex_groups_follow(self):
        obj = add_primitive("monkey")
        co = mesh_arrays(obj.data)["co"].reshape(-1, 3)
        left = obj.vertex_groups.new(name="left")
        left.add([int(i) for i in np.flatnonzero(co[:, 0] > 0.1)], 1.0, 'REPLACE')
        ramp = obj.vertex_groups.new(name="ramp")
        ramp.add(list(range(len(co))), 0.5, 'REPLACE')
        obj.vertex_groups.active_index = 0
        for mode in ('OBJECT', 'EDIT'):
            bpy.ops.object.mode_set(mode=mode)
            bpy.ops.mesh.hedge_subdivide(scheme='catmull_clark')
            bpy.ops.object.mode_set(mode='OBJECT')
            me = obj.data
            self.assertEqual([g.name for g in obj.vertex_groups], ["left", "ramp"], mode)
            self.assertEqual(obj.vertex_groups.active_index, 0)
            co = mesh_arrays(me)["co"].reshape(-1, 3)
            # Every vertex of the ramp group keeps weight 0.5; "left" holds the x > 0.1 side.
            self.assertAlmostEqual(obj.vertex_groups["ramp"].weight(len(co) - 1), 0.5, places=5)
            right = int(np.flatnonzero(co[:, 0] > 0.5)[0])
            self.assertAlmostEqual(obj.vertex_groups["left"].weight(right), 1.0, places=5)
            far_left = int(np.flatnonzero(co[:, 0] < -0.5)[0])
            with self.assertRaises(RuntimeError):
                obj.vertex_groups["left"].weight(far_left)

    def test_make_delaunay_and_repair(self):
        obj = add_uv_sphere()
        bpy.ops.mesh.hedge_triangulate()
        n = len(obj.data.polygons)
        bpy.ops.mesh.hedge_make_delaunay()
        self.assertEqual(len(obj.data.polygons), n)
        bpy.ops.mesh.hedge_repair(weld_distance=1e-5)
        self.assertEqual(len(obj.data.polygons), n)

    def test_report(self):
        obj = add_primitive("monkey")
        bpy.ops.mesh.hedge_report()
        report = hedge.api.last_reports["report:" + obj.name]
        self.assertEqual(report["faces"], 500)
        report2 = hedge.run(obj, "report")
        self.assertEqual(report2["faces"], 500)

    def test_several_objects_and_shared_mesh(self):
        a = add_primitive("uv_sphere")
        b = add_primitive("monkey", location=(3, 0, 0))
        c = bpy.data.objects.new("linked", b.data)
        bpy.context.collection.objects.link(c)
        for o in (a, b, c):
            o.select_set(True)
        fa, fb = len(a.data.polygons), len(b.data.polygons)
        bpy.ops.mesh.hedge_subdivide(scheme='midpoint')
        self.assertEqual(len(a.data.polygons), 4 * fa)
        self.assertGreater(len(b.data.polygons), 3 * fb)  # once, though two objects use it

    def test_edit_mode(self):
        obj = add_primitive("monkey")
        bpy.ops.object.mode_set(mode='EDIT')
        held = bmesh.from_edit_mesh(obj.data)  # a script's wrapper, held across the run
        bpy.ops.mesh.hedge_triangulate()
        bpy.ops.mesh.hedge_decimate(target_faces=300)
        bm = bmesh.from_edit_mesh(obj.data)
        self.assertEqual(len(bm.faces), 300)
        # The edit mesh was reloaded under it: the old wrapper raises (once it outlived the
        # edit mesh unknowing and crashed Blender when collected).
        with self.assertRaises(ReferenceError):
            len(held.verts)
        bpy.ops.object.mode_set(mode='OBJECT')
        del held, bm
        gc.collect()
        self.assertEqual(len(obj.data.polygons), 300)

    def test_undo_restores(self):
        # In -b, operators called from a script push no undo step themselves and ed.undo
        # needs a window: steps are pushed around the call, in the startup file's window.
        name = add_primitive("monkey").name
        with bpy.context.temp_override(window=bpy.context.window_manager.windows[0]):
            before = mesh_arrays(bpy.data.objects[name].data)
            bpy.ops.ed.undo_push(message="before")
            bpy.ops.mesh.hedge_decimate(target_ratio=0.3)
            bpy.ops.ed.undo_push(message="Decimate")
            after_op = mesh_arrays(bpy.data.objects[name].data)
            self.assertLess(len(after_op["loop_total"]), 500)
            bpy.ops.ed.undo()
            after = mesh_arrays(bpy.data.objects[name].data)  # undo reloads the data: look up by name
            for key in before:
                self.assertTrue(np.array_equal(before[key], after[key]), key)
            bpy.ops.ed.redo()
            self.assertTrue(np.array_equal(after_op["co"], mesh_arrays(bpy.data.objects[name].data)["co"]))
            # Edit Mode: the edit mesh's own undo steps.
            select_only(bpy.data.objects[name])
            bpy.ops.object.mode_set(mode='EDIT')
            bpy.ops.ed.undo_push(message="edit before")
            faces = len(bmesh.from_edit_mesh(bpy.data.objects[name].data).faces)
            bpy.ops.mesh.hedge_subdivide(scheme='midpoint')
            bpy.ops.ed.undo_push(message="Subdivide")
            self.assertGreater(len(bmesh.from_edit_mesh(bpy.data.objects[name].data).faces), faces)
            bpy.ops.ed.undo()
            self.assertEqual(len(bmesh.from_edit_mesh(bpy.data.objects[name].data).faces), faces)
            bpy.ops.object.mode_set(mode='OBJECT')

    def test_out_of_range_refused(self):
        add_primitive("cube")
        with self.assertRaises((TypeError, ValueError)):
            bpy.ops.mesh.hedge_decimate(target_ratio="much")
        # Blender clamps to the property's hard limits: the operator never sees 5.
        op = bpy.ops.mesh.hedge_decimate.get_rna_type().properties["target_ratio"]
        self.assertEqual(op.hard_max, 1.0)
        with self.assertRaises(hedge.Error):
            hedge.run(bpy.context.active_object, "decimate", target_ratio=5.0)
        with self.assertRaises(hedge.Error):
            hedge.run(bpy.context.active_object, "decimate", no_such_parameter=1)
        with self.assertRaises(hedge.Error):
            hedge.run(bpy.context.active_object, "no_such_operation")


class RealMeshesTest(unittest.TestCase):
    def setUp(self):
        clear_scene()

    def path(self, name):
        return mesh_path(self, name)

    def test_dragon_res2_every_operator(self):
        for op in hedge.catalogue():
            clear_scene()
            obj = import_mesh(self.path("dragon_res2.ply"))
            faces = len(obj.data.polygons)
            params = {"subdivide": {"scheme": 'midpoint'}, "remesh": {"iterations": 2}}.get(op["id"], {})
            result = getattr(bpy.ops.mesh, f"hedge_{op['id']}")(**params)
            self.assertEqual(result, {'FINISHED'}, op["id"])
            if op["id"] == "decimate":
                self.assertAlmostEqual(len(obj.data.polygons), faces // 2, delta=faces * 0.01)

    def test_bunny_through_hedge_reader(self):
        obj = hedge.api.import_file(self.path("bunny.off"))  # Blender has no OFF importer
        select_only(obj)
        report = hedge.run(obj, "report")
        self.assertEqual(report["faces"], len(obj.data.polygons))
        self.assertEqual(report["boundary_loops"], boundary_loops(obj.data))
        bpy.ops.mesh.hedge_decimate(target_faces=1000)
        self.assertEqual(len(obj.data.polygons), 1000)
        bpy.ops.mesh.hedge_remesh(iterations=3)
        lengths = edge_lengths(obj.data)
        self.assertLess(float(np.std(lengths) / np.mean(lengths)), 0.35)

    def test_dragon_holes(self):
        # hedge counts loops that touch at a vertex separately; the numpy count joins them.
        obj = import_mesh(self.path("dragon_res2.ply"))
        holes = boundary_loops(obj.data)
        loops = hedge.run(obj, "report")["boundary_loops"]
        self.assertGreaterEqual(loops, holes)
        self.assertGreater(holes, 0)
        report = hedge.run(obj, "fill_holes")
        self.assertGreater(report["holes_filled"], 0)
        self.assertLess(boundary_loops(obj.data), holes)
        print("\ndragon_res2 fill_holes:", report["holes_filled"], "filled;", report["messages"])


run_tests(PrimitivesTest, RealMeshesTest)
