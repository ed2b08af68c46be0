# The exchange bpy.types.Mesh <-> hedge: a no-op round trip (read, build, extract, write the
# geometry anew) leaves positions, loops, polygons, UVs, attributes of every type this Blender
# has, flags, bevel weights, creases and edge data identical, adds no attribute (no
# sharp_edge.001); figures for the exchange on the full dragon.
import os
import re
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import bpy  # noqa: E402
import numpy as np  # noqa: E402
import unittest  # noqa: E402
from blender_test import (FREESTYLE_MARKS, LAYERS, add_primitive, clear_scene, faces_of, get,  # noqa: E402
                          install_addon, is_edge_key, mesh_arrays, mesh_path, object_from_pydata, run_tests,
                          set_layer)

hedge = install_addon()
from hedge import exchange  # noqa: E402
from hedge.native import native  # noqa: E402

# One attribute of each type this Blender has that the exchange carries, domains in turn.
DATA_TYPES = [t.identifier for t in bpy.types.Attribute.bl_rna.properties["data_type"].enum_items
              if t.identifier in exchange.ATTRIBUTE_TYPES and "COLOR" not in t.identifier]
DOMAIN_CYCLE = ('POINT', 'FACE', 'CORNER', 'EDGE')


def decorate(obj):
    """Every kind of data the exchange carries, with values that are not all equal."""
    me = obj.data
    nv, ne, nf, nl = len(me.vertices), len(me.edges), len(me.polygons), len(me.loops)
    rng = np.random.default_rng(7)
    me.uv_layers.new(name="second")
    me.uv_layers["second"].data.foreach_set("uv", rng.random(nl * 2, np.float32))
    sizes = {'POINT': nv, 'FACE': nf, 'CORNER': nl, 'EDGE': ne}
    for i, data_type in enumerate(DATA_TYPES):
        domain = DOMAIN_CYCLE[i % len(DOMAIN_CYCLE)]
        prop, dtype, comps = exchange.ATTRIBUTE_TYPES[data_type]
        n = sizes[domain] * comps
        if dtype == np.bool_:
            values = rng.random(n) < 0.5
        elif np.issubdtype(dtype, np.integer):
            values = rng.integers(-100, 100, n).astype(dtype)
        else:
            values = rng.random(n, np.float32)
        me.attributes.new(f"{data_type.lower()}_{domain.lower()}", data_type, domain).data.foreach_set(prop, values)
    me.attributes.new("f_edge", 'FLOAT', 'EDGE').data.foreach_set("value", rng.random(ne, np.float32))
    col = me.color_attributes.new("vcol", 'FLOAT_COLOR', 'POINT')
    col.data.foreach_set("color", rng.random(nv * 4, np.float32))
    byte = me.color_attributes.new("bcol", 'BYTE_COLOR', 'CORNER')
    byte.data.foreach_set("color_srgb", rng.integers(0, 256, nl * 4).astype(np.float32) / 255)
    me.polygons.foreach_set("material_index", rng.integers(0, 3, nf).astype(np.int32))
    me.polygons.foreach_set("use_smooth", rng.random(nf) < 0.5)
    for collection, n in ((me.vertices, nv), (me.polygons, nf)):
        collection.foreach_set("select", rng.random(n) < 0.5)
        collection.foreach_set("hide", rng.random(n) < 0.2)
    me.edges.foreach_set("use_seam", rng.random(ne) < 0.2)
    me.edges.foreach_set("use_edge_sharp", rng.random(ne) < 0.2)
    if FREESTYLE_MARKS:
        me.edges.foreach_set("use_freestyle_mark", rng.random(ne) < 0.2)
    for key, (collection, _, _, _) in LAYERS.items():
        set_layer(me, key, rng.random(len(getattr(me, collection)), np.float32))
    me.update()


def edge_table(arrays):
    """Edges as a sorted (min, max) table with their data, independent of edge order."""
    e = np.sort(arrays["edges"].reshape(-1, 2), axis=1)
    order = np.lexsort((e[:, 1], e[:, 0]))
    n = len(e)
    return {key: values.reshape(n, -1)[order] if key != "edges" else e[order]
            for key, values in arrays.items() if is_edge_key(key)}


def attribute_names(me):
    """The visible attributes (Blender adds internal ".name" ones as it likes, e.g. 5.x's UV
    selection), and none made twice (".001")."""
    names = sorted(a.name for a in me.attributes)
    assert not [n for n in names if re.search(r"\.\d\d\d$", n)], names
    return [n for n in names if not n.startswith(".")]


class RoundTripTest(unittest.TestCase):
    def setUp(self):
        clear_scene()

    def check_round_trip(self, obj):
        me = obj.data
        before = mesh_arrays(me)
        names_before = attribute_names(me)
        data = exchange.read_mesh(me)
        # Each edge datum is read once: as a property (3.x; 4.x's hidden .uv_seam; freestyle
        # marks until 5.0) or as the generic attribute that holds it, never both.
        as_attribute = {name for name, _ in data.edge_attributes}
        self.assertEqual([p for p, a in exchange.EDGE_FLAGS if p in data.edge_data and a in as_attribute], [])
        result = native.build_extract(data.soup)
        self.assertTrue(exchange.same_topology(data.soup, result))
        exchange.write_mesh(me, data, result, rebuild=True)
        after = mesh_arrays(me)
        self.assertEqual(sorted(before), sorted(after))
        self.assertEqual(attribute_names(me), names_before)
        for key in before:
            if is_edge_key(key):
                continue
            self.assertEqual(before[key].dtype, after[key].dtype, key)
            self.assertTrue(np.array_equal(before[key], after[key]), key)
        edges_before, edges_after = edge_table(before), edge_table(after)
        for key in edges_before:
            self.assertEqual(edges_before[key].dtype, edges_after[key].dtype, key)
            self.assertTrue(np.array_equal(edges_before[key], edges_after[key]), key)
        self.assertEqual([l.name for l in me.uv_layers], ["UVMap", "second"])
        self.assertEqual(me.uv_layers.active.name, "UVMap")
        return before

    def test_suzanne(self):
        obj = add_primitive("monkey")
        decorate(obj)
        before = self.check_round_trip(obj)
        # What was decorated is there to compare (not all zeros or all False).
        keys = ["edge:seam", "edge:sharp", "vertex:select", "face:hide"] + (["edge:freestyle"] if FREESTYLE_MARKS else [])
        keys += list(LAYERS) if "edge:crease" in before else [f"attr:{a}:{d}" for _, _, a, d in LAYERS.values()]
        for key in keys:
            self.assertTrue(before[key].any(), key)

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

    def test_booleans_read_from_blenders_arrays(self):
        """Where Blender copies booleans element by element (3.x), the flags and boolean
        attributes are read from its own arrays, bit for bit what foreach_get reads; elsewhere
        foreach_get reads them."""
        obj = add_primitive("monkey")
        decorate(obj)
        me = obj.data
        attribute = next(a for a in me.attributes if a.data_type == 'BOOLEAN' and not a.name.startswith("."))
        read = [(me.polygons, "use_smooth"), (me.edges, "use_seam"), (me.edges, "use_edge_sharp"),
                (attribute.data, "value")]
        for collection, prop in read:
            expected = np.zeros(len(collection), np.bool_)
            collection.foreach_get(prop, expected)
            self.assertTrue(expected.any() and not expected.all(), prop)
            values = np.zeros(len(collection), np.bool_)
            taken = exchange._read_bits(collection, prop, values)
            self.assertEqual(taken, exchange.BOOLEANS_ELEMENT_BY_ELEMENT and not (
                prop == "use_smooth" and ("polygons", "use_smooth") in exchange.builtin_attributes()), prop)
            if taken:
                self.assertTrue(np.array_equal(values, expected), prop)

    def test_loops_out_of_polygon_order(self):
        """Loops stored in another order than their polygons (Blender before 4.0 lets a script
        write the starts and totals; later ones keep them in order) are read in polygon order,
        into the buffers too."""
        obj = object_from_pydata("shuffled", [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0), (2, 0, 0)],
                                 [(0, 1, 2, 3), (1, 4, 2)])
        me = obj.data
        if exchange.LOOP_TOTAL_WRITABLE:
            me.polygons.foreach_set("loop_start", np.array([3, 0], np.uint32))
            me.polygons.foreach_set("loop_total", np.array([4, 3], np.uint32))
            me.loops.foreach_set("vertex_index", np.array([1, 4, 2, 0, 1, 2, 3], np.uint32))
            self.assertEqual(get(me.polygons, "loop_start", 2, np.int32).tolist(), [3, 0])
        self.assertEqual(faces_of(me), [(0, 1, 2, 3), (1, 4, 2)])
        for buffers in (None, native.SoupBuffers):
            soup = exchange.read_mesh(me, buffers=buffers).soup
            self.assertEqual(soup["face_sizes"].tolist(), [4, 3])
            self.assertEqual(soup["corners"].tolist(), [0, 1, 2, 3, 1, 4, 2])

    def test_flags_cross_only_when_held(self):
        """Materials, selection and hiding that the mesh does not hold as attributes (every
        element has the default) stay out of the soup, and an operation's result holds the
        defaults; a mesh holding only its faces' selection sends both selections."""
        obj = object_from_pydata("plain", [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0), (2, 0, 0), (2, 1, 0)],
                                 [(0, 1, 2, 3), (1, 4, 5, 2)])
        me = obj.data
        held = exchange.builtin_attributes()
        flags = {("material", "face"): ("polygons", "material_index"), ("hidden", "vertex"): ("vertices", "hide"),
                 ("hidden", "face"): ("polygons", "hide"), ("selected", "vertex"): ("vertices", "select"),
                 ("selected", "face"): ("polygons", "select")}
        for name in [held[f] for f in flags.values() if f in held]:
            if name in me.attributes:
                me.attributes.remove(me.attributes[name])

        def crossing():
            return {(n, d) for n, d, _ in exchange.read_mesh(me).soup["channels"]}

        # Only what this Blender keeps as element properties, not attributes, still crosses.
        self.assertEqual(crossing() & set(flags), {key for key, f in flags.items() if f not in held})
        self.assertIn(("smooth", "face"), crossing())
        hedge.run(obj, "triangulate")
        self.assertEqual(len(me.polygons), 4)
        for collection, prop in flags.values():
            values = get(getattr(me, collection), prop, len(getattr(me, collection)), np.int32)
            self.assertFalse(values.any(), prop)
        if ("polygons", "select") in held:
            me.polygons[0].select = True
            if held[("vertices", "select")] in me.attributes:
                me.attributes.remove(me.attributes[held[("vertices", "select")]])
            self.assertLessEqual({("selected", "vertex"), ("selected", "face")}, crossing())

    def test_vertex_indices_in_runs(self):
        """The source vertex indices are made a run at a time, across runs and in part of one."""
        for n in (0, 1, 7, 1 << 16, (1 << 16) + 1, 200_001):
            self.assertTrue(np.array_equal(exchange._indices(n, np.zeros), np.arange(n, dtype=np.int32)), n)

    def test_read_into_buffers(self):
        """Read into the native module's buffers, the soup is the same as read into numpy's
        arrays; its big arrays lie in the buffers (an operation reads them without a copy), the
        same operation gives the same result either way, and the buffers are refused to a
        second operation while one runs."""
        obj = add_primitive("monkey")
        decorate(obj)
        plain = exchange.read_mesh(obj.data, edges=False)
        data = exchange.read_mesh(obj.data, edges=False, buffers=native.SoupBuffers)
        soup, buffers = data.soup, data.soup["buffers"]
        for key in ("positions", "face_sizes", "corners"):
            self.assertTrue(np.array_equal(soup[key], plain.soup[key]), key)
            self.assertTrue(np.shares_memory(soup[key], getattr(buffers, key)), key)
        self.assertEqual([(n, d) for n, d, _ in soup["channels"]], [(n, d) for n, d, _ in plain.soup["channels"]])
        for (name, domain, values), (_, _, expected) in zip(soup["channels"], plain.soup["channels"]):
            self.assertTrue(np.array_equal(values, expected), f"{name} ({domain})")
            if name in ("uv:UVMap", "material", "selected", "blender:vertex"):
                owner = values
                while isinstance(owner, np.ndarray):
                    owner = owner.base
                self.assertIs(owner, buffers, name)
        params = {"target_ratio": 0.5}
        in_place, report = native.run("decimate", soup, params)
        copied, _ = native.run("decimate", plain.soup, params)
        self.assertGreater(report["collapses"], 0)
        for key in ("positions", "face_sizes", "corners"):
            self.assertTrue(np.array_equal(in_place[key], copied[key]), key)
        job = native.Job("decimate", soup, params)
        with self.assertRaisesRegex(native.Error, "in use by a running operation"):
            native.run("decimate", soup, params)
        job.result()

    def test_full_dragon_exchange_time(self):
        path = mesh_path(self, "dragon.ply")
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
