# The exchange bpy.types.Mesh <-> hedge: a no-op round trip (read, build, extract, write the
# geometry anew) leaves positions, loops, polygons, UVs, attributes, flags and edge data
# identical; figures for the exchange on the full dragon.
import os
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import bpy  # noqa: E402
import numpy as np  # noqa: E402
import unittest  # noqa: E402
from blender_test import ARGS, add_primitive, clear_scene, install_addon, mesh_arrays, run_tests  # noqa: E402

hedge = install_addon()
from hedge import exchange  # noqa: E402
from hedge.native import native  # noqa: E402


def decorate(obj):
    """Every kind of data the exchange carries, with values that are not all equal."""
    me = obj.data
    nv, ne, nf, nl = len(me.vertices), len(me.edges), len(me.polygons), len(me.loops)
    rng = np.random.default_rng(7)
    me.uv_layers.new(name="second")
    me.uv_layers["second"].data.foreach_set("uv", rng.random(nl * 2, np.float32))
    specs = [("f_point", 'FLOAT', 'POINT', "value", 1), ("i_face", 'INT', 'FACE', "value", 1),
             ("v_corner", 'FLOAT_VECTOR', 'CORNER', "vector", 3), ("uv2_point", 'FLOAT2', 'POINT', "vector", 2),
             ("b_face", 'BOOLEAN', 'FACE', "value", 1), ("i8_point", 'INT8', 'POINT', "value", 1),
             ("f_edge", 'FLOAT', 'EDGE', "value", 1)]
    sizes = {'POINT': nv, 'FACE': nf, 'CORNER': nl, 'EDGE': ne}
    for name, data_type, domain, prop, comps in specs:
        attr = me.attributes.new(name, data_type, domain)
        n = sizes[domain] * comps
        values = {'INT': rng.integers(-1000, 1000, n).astype(np.int32), 'BOOLEAN': rng.random(n) < 0.5,
                  'INT8': rng.integers(-100, 100, n).astype(np.int8)}.get(data_type, rng.random(n, np.float32))
        attr.data.foreach_set(prop, values)
    col = me.color_attributes.new("vcol", 'FLOAT_COLOR', 'POINT')
    col.data.foreach_set("color", rng.random(nv * 4, np.float32))
    byte = me.color_attributes.new("bcol", 'BYTE_COLOR', 'CORNER')
    byte.data.foreach_set("color_srgb", rng.integers(0, 256, nl * 4).astype(np.float32) / 255)
    me.polygons.foreach_set("material_index", rng.integers(0, 3, nf).astype(np.int32))
    me.polygons.foreach_set("use_smooth", rng.random(nf) < 0.5)
    me.edges.foreach_set("use_seam", rng.random(ne) < 0.2)
    me.edges.foreach_set("use_edge_sharp", rng.random(ne) < 0.2)
    me.edges.foreach_set("crease", rng.random(ne, np.float32))
    me.update()


def edge_table(me, arrays):
    """Edges as a sorted (min, max) table with their data, independent of edge order."""
    e = np.sort(arrays["edges"].reshape(-1, 2), axis=1)
    order = np.lexsort((e[:, 1], e[:, 0]))
    crease = np.empty(len(me.edges), np.float32)
    me.edges.foreach_get("crease", crease)
    return e[order], arrays["seam"][order], arrays["sharp"][order], crease[order], arrays["attr:f_edge:EDGE"][order]


class RoundTripTest(unittest.TestCase):
    def setUp(self):
        clear_scene()

    def check_round_trip(self, obj):
        me = obj.data
        before = mesh_arrays(me)
        edges_before = edge_table(me, before)
        data = exchange.read_mesh(me)
        result = native.build_extract(data.soup)
        self.assertTrue(exchange.same_topology(data.soup, result))
        exchange.write_mesh(me, data, result, rebuild=True)
        after = mesh_arrays(me)
        self.assertEqual(sorted(before), sorted(after))
        for key in before:
            if key in ("edges", "seam", "sharp", "attr:f_edge:EDGE"):
                continue
            self.assertEqual(before[key].dtype, after[key].dtype, key)
            self.assertTrue(np.array_equal(before[key], after[key]), key)
        for a, b in zip(edges_before, edge_table(me, after)):
            self.assertTrue(np.array_equal(a, b))
        self.assertEqual([l.name for l in me.uv_layers], ["UVMap", "second"])
        self.assertEqual(me.uv_layers.active.name, "UVMap")

    def test_suzanne(self):
        obj = add_primitive("monkey")
        decorate(obj)
        self.check_round_trip(obj)

    def test_polygons_and_cylinder(self):
        obj = add_primitive("cylinder", vertices=40)
        decorate(obj)
        self.check_round_trip(obj)

    def test_operator_no_change_keeps_vertex_groups(self):
        obj = add_primitive("monkey")
        decorate(obj)
        bpy.ops.mesh.hedge_triangulate()
        vg = obj.vertex_groups.new(name="g")
        vg.add([1, 2, 3], 0.5, 'REPLACE')
        # triangulate on triangles: the topology stays, so the mesh is written in place.
        bpy.ops.mesh.hedge_triangulate()
        before = mesh_arrays(obj.data)
        bpy.ops.mesh.hedge_triangulate()
        after = mesh_arrays(obj.data)
        for key in before:
            self.assertTrue(np.array_equal(before[key], after[key]), key)
        self.assertEqual(obj.vertex_groups["g"].weight(2), 0.5)

    def test_full_dragon_exchange_time(self):
        path = os.path.join(ARGS.meshes, "dragon.ply")
        if not os.path.exists(path):
            self.skipTest("no dragon.ply")
        start = time.perf_counter()
        obj = hedge.api.import_file(path)
        t_import = time.perf_counter() - start
        me = obj.data
        start = time.perf_counter()
        data = exchange.read_mesh(me)
        t_read = time.perf_counter() - start
        start = time.perf_counter()
        result = native.build_extract(data.soup)
        t_native = time.perf_counter() - start
        start = time.perf_counter()
        exchange.write_mesh(me, data, result, rebuild=True)
        t_write = time.perf_counter() - start
        print(f"\nexchange on the dragon ({len(me.polygons)} triangles): import with hedge's reader {t_import:.2f} s, "
              f"Mesh -> arrays {t_read:.2f} s, build+extract {t_native:.2f} s, arrays -> Mesh {t_write:.2f} s")
        self.assertEqual(len(me.polygons), 871414)


run_tests(RoundTripTest)
