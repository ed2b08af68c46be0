# Shared by the Blender tests (run inside `blender -b --factory-startup --python X.py -- ARGS`):
# arguments, installing and enabling the package a user of the running Blender installs (the
# legacy add-on zip before 4.2, the extension after) in the private HOME, scene helpers, and a
# unittest runner that makes blender exit non-zero (with --python-exit-code) on failure.
import argparse
import os
import sys
import unittest

import bpy
import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "blender_addon", "tools"))
import hedge_install  # noqa: E402


def arguments():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    parser = argparse.ArgumentParser()
    parser.add_argument("--addon-zip", required=True, help="build/hedge_blender_addon.zip (Blender 3.4-4.1)")
    parser.add_argument("--extension-zip", default="", help="build/hedge_blender_extension.zip (Blender 4.2+)")
    parser.add_argument("--meshes", default="", help="folder with bunny.off, dragon*.ply")
    parser.add_argument("--out", default="", help="folder for outputs (screenshots, renders)")
    parser.add_argument("--full", action="store_true", help="also the full 871k-face dragon")
    args, rest = parser.parse_known_args(argv)
    args.rest = rest
    args.zip = hedge_install.package_for_this_blender(args.addon_zip, args.extension_zip)
    return args


ARGS = arguments()


def install_addon(zip_path=None):
    """Installs the zip as a user of this Blender would and enables it; returns the package,
    which a script then also reaches as `import hedge` (as an extension too)."""
    hedge_install.install(zip_path or ARGS.zip)
    import hedge
    return hedge


def clear_scene():
    if bpy.context.object is not None and bpy.context.object.mode != 'OBJECT':
        bpy.ops.object.mode_set(mode='OBJECT')
    bpy.ops.object.select_all(action='SELECT')
    bpy.ops.object.delete()
    for me in list(bpy.data.meshes):
        bpy.data.meshes.remove(me)


def add_primitive(kind, **kwargs):
    if bpy.context.object and bpy.context.object.mode != 'OBJECT':
        bpy.ops.object.mode_set(mode='OBJECT')
    bpy.ops.object.select_all(action='DESELECT')
    getattr(bpy.ops.mesh, f"primitive_{kind}_add")(**kwargs)
    return bpy.context.active_object


def select_only(obj):
    bpy.ops.object.select_all(action='DESELECT')
    obj.select_set(True)
    bpy.context.view_layer.objects.active = obj


# Blender's own importers: the C++ ones where this Blender has them (PLY and STL from 3.6,
# the only ones in 4.0+), the Python add-ons before.
IMPORTERS = {".ply": ("wm.ply_import", "import_mesh.ply"), ".obj": ("wm.obj_import", "import_scene.obj"),
             ".stl": ("wm.stl_import", "import_mesh.stl")}


def import_mesh(path):
    """Imports PLY/OBJ/STL with Blender's own importers; returns the new object."""
    bpy.ops.object.select_all(action='DESELECT')
    ext = os.path.splitext(path)[1].lower()
    if ext not in IMPORTERS:
        raise ValueError(f"no Blender importer for {path}")
    for name in IMPORTERS[ext]:
        group, op = name.split(".")
        if op in dir(getattr(bpy.ops, group)):
            getattr(getattr(bpy.ops, group), op)(filepath=path)
            break
    obj = bpy.context.selected_objects[0]
    select_only(obj)
    return obj


# Data that 3.x keeps as properties and 4.0+ as generic attributes:
#   key -> (collection, property, attribute, domain)
LAYERS = {"edge:crease": ("edges", "crease", "crease_edge", 'EDGE'),
          "edge:bevel_weight": ("edges", "bevel_weight", "bevel_weight_edge", 'EDGE'),
          "vertex:bevel_weight": ("vertices", "bevel_weight", "bevel_weight_vert", 'POINT')}
LEGACY_LAYERS = "crease" in bpy.types.MeshEdge.bl_rna.properties
FREESTYLE_MARKS = "use_freestyle_mark" in bpy.types.MeshEdge.bl_rna.properties


def set_layer(me, key, values):
    """Sets a bevel weight or crease layer (LAYERS) where this Blender keeps it."""
    collection, prop, attribute, domain = LAYERS[key]
    if LEGACY_LAYERS:
        getattr(me, collection).foreach_set(prop, values)
    else:
        me.attributes.new(attribute, 'FLOAT', domain).data.foreach_set("value", values)


def get(coll, prop, n, dtype, comps=1):
    a = np.empty(n * comps, dtype)
    if n:
        coll.foreach_get(prop, a)
    return a


def is_edge_key(key):
    """The mesh_arrays entries in edge order (which a rebuild may change)."""
    return key == "edges" or key.startswith("edge:") or key.endswith(":EDGE")


def mesh_arrays(me):
    """Everything the tests compare, as numpy arrays: what the exchange carries, under one key
    each in every version (3.x properties under their own key, 4.0+ attributes as attr:...)."""
    from hedge.exchange import ATTRIBUTE_TYPES
    nv, nl, nf, ne = len(me.vertices), len(me.loops), len(me.polygons), len(me.edges)
    out = {
        "co": get(me.vertices, "co", nv, np.float32, 3),
        "loop_vertex": get(me.loops, "vertex_index", nl, np.int32),
        "loop_total": get(me.polygons, "loop_total", nf, np.int32),
        "loop_start": get(me.polygons, "loop_start", nf, np.int32),
        "material": get(me.polygons, "material_index", nf, np.int32),
        "smooth": get(me.polygons, "use_smooth", nf, np.bool_),
        "vertex:select": get(me.vertices, "select", nv, np.bool_),
        "vertex:hide": get(me.vertices, "hide", nv, np.bool_),
        "face:select": get(me.polygons, "select", nf, np.bool_),
        "face:hide": get(me.polygons, "hide", nf, np.bool_),
        "edges": get(me.edges, "vertices", ne, np.int32, 2),
        "edge:seam": get(me.edges, "use_seam", ne, np.bool_),
        "edge:sharp": get(me.edges, "use_edge_sharp", ne, np.bool_),
    }
    if FREESTYLE_MARKS:
        out["edge:freestyle"] = get(me.edges, "use_freestyle_mark", ne, np.bool_)
    if LEGACY_LAYERS:
        for key, (collection, prop, _, _) in LAYERS.items():
            out[key] = get(getattr(me, collection), prop, ne if collection == "edges" else nv, np.float32)
    for layer in me.uv_layers:
        out["uv:" + layer.name] = get(layer.data, "uv", nl, np.float32, 2)
    for attr in me.attributes:
        if attr.name.startswith(".") or attr.data_type not in ATTRIBUTE_TYPES:
            continue
        prop, dtype, comps = ATTRIBUTE_TYPES[attr.data_type]
        out[f"attr:{attr.name}:{attr.domain}"] = get(attr.data, prop, len(attr.data), dtype, comps)
    return out


def object_from_pydata(name, vertices, faces):
    """A new, selected and active object of a mesh built with from_pydata (which keeps every face
    as given: duplicates, non-manifold edges)."""
    me = bpy.data.meshes.new(name)
    me.from_pydata(vertices, [], faces)
    obj = bpy.data.objects.new(name, me)
    bpy.context.collection.objects.link(obj)
    select_only(obj)
    return obj


def faces_of(me):
    """The polygons as tuples of vertex indices."""
    nl, nf = len(me.loops), len(me.polygons)
    corners = get(me.loops, "vertex_index", nl, np.int32).tolist()
    starts = get(me.polygons, "loop_start", nf, np.int32).tolist()
    totals = get(me.polygons, "loop_total", nf, np.int32).tolist()
    return [tuple(corners[s:s + t]) for s, t in zip(starts, totals)]


def problems(me):
    """Whether Mesh.validate() would change anything, asked of a copy. The copy's arrays are its
    own first (each written back): Blender 4.3.2's validate() of a copy writes through to the
    original's implicitly shared arrays (a NaN position in the original became 0.0; the corners of
    a mesh with duplicate faces were rewired)."""
    copy = me.copy()
    try:
        for collection, prop, dtype, comps in ((copy.vertices, "co", np.float32, 3), (copy.edges, "vertices", np.int32, 2),
                                               (copy.loops, "vertex_index", np.int32, 1),
                                               (copy.loops, "edge_index", np.int32, 1),
                                               (copy.polygons, "loop_start", np.int32, 1)):
            values = get(collection, prop, len(collection), dtype, comps)
            if len(values):
                collection.foreach_set(prop, values)
        return bool(copy.validate(verbose=False))
    finally:
        bpy.data.meshes.remove(copy)


def counts(me):
    return len(me.vertices), len(me.edges), len(me.polygons)


def boundary_loops(me):
    """Number of holes (closed chains of edges with one face), computed with numpy."""
    nl = len(me.loops)
    edge_index = np.empty(nl, np.int32)
    me.loops.foreach_get("edge_index", edge_index)
    uses = np.bincount(edge_index, minlength=len(me.edges))
    edges = np.empty(len(me.edges) * 2, np.int32)
    me.edges.foreach_get("vertices", edges)
    boundary = edges.reshape(-1, 2)[uses == 1]
    if len(boundary) == 0:
        return 0
    # Connected components of the boundary graph: min-label hooking with pointer jumping.
    a, b = boundary[:, 0], boundary[:, 1]
    labels = np.arange(len(me.vertices))
    while True:
        low = np.minimum(labels[a], labels[b])
        new = labels.copy()
        np.minimum.at(new, a, low)
        np.minimum.at(new, b, low)
        np.minimum.at(new, labels, new)
        new = new[new]
        if np.array_equal(new, labels):
            break
        labels = new
    return len(np.unique(labels[np.unique(boundary.ravel())]))


def edge_lengths(me):
    co = np.empty(len(me.vertices) * 3, np.float32)
    me.vertices.foreach_get("co", co)
    edges = np.empty(len(me.edges) * 2, np.int32)
    me.edges.foreach_get("vertices", edges)
    co = co.reshape(-1, 3)
    edges = edges.reshape(-1, 2)
    return np.linalg.norm(co[edges[:, 0]] - co[edges[:, 1]], axis=1)


# The exit code of a run where nothing failed but a case was skipped (e.g. the meshes were not
# fetched): ctest reports the test as skipped (SKIP_RETURN_CODE), not as passed.
SKIPPED = 77


def run_tests(*cases):
    suite = unittest.TestSuite()
    for case in cases:
        suite.addTests(unittest.defaultTestLoader.loadTestsFromTestCase(case))
    result = unittest.TextTestRunner(verbosity=2, stream=sys.stdout).run(suite)
    sys.stdout.flush()
    if not result.wasSuccessful():
        raise SystemExit(1)
    if result.skipped:
        print(f"{len(result.skipped)} of {result.testsRun} cases skipped: the test counts as skipped", flush=True)
        raise SystemExit(SKIPPED)


def mesh_path(test, name):
    """The path of a fetched real mesh, or the case is skipped (and so the whole test)."""
    path = os.path.join(ARGS.meshes, name)
    if not ARGS.meshes or not os.path.exists(path):
        test.skipTest(f"{name} is not in --meshes {ARGS.meshes!r} (./run fetch)")
    return path
