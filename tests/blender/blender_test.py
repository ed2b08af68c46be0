# Shared by the Blender tests (run inside `blender -b --factory-startup --python X.py -- ARGS`):
# arguments, installing and enabling the add-on zip in the private HOME, scene helpers, and a
# unittest runner that makes blender exit non-zero (with --python-exit-code) on failure.
import argparse
import os
import sys
import unittest

import addon_utils
import bpy
import numpy as np


def arguments():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    parser = argparse.ArgumentParser()
    parser.add_argument("--zip", required=True, help="build/hedge_blender_addon.zip")
    parser.add_argument("--meshes", default="", help="folder with bunny.off, dragon*.ply")
    parser.add_argument("--out", default="", help="folder for outputs (screenshots, renders)")
    parser.add_argument("--full", action="store_true", help="also the full 871k-face dragon")
    args, rest = parser.parse_known_args(argv)
    args.rest = rest
    return args


ARGS = arguments()


def install_addon():
    """Installs the zip as a user would (Preferences > Add-ons > Install) and enables it."""
    bpy.ops.preferences.addon_install(filepath=os.path.abspath(ARGS.zip), overwrite=True)
    addon_utils.modules_refresh()
    module = addon_utils.enable("hedge", default_set=True, handle_error=None)
    if module is None:
        raise RuntimeError("the hedge add-on did not enable")
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


def import_mesh(path):
    """Imports PLY/OBJ/STL with Blender's own importers; returns the new object."""
    bpy.ops.object.select_all(action='DESELECT')
    ext = os.path.splitext(path)[1].lower()
    if ext == ".ply":
        bpy.ops.import_mesh.ply(filepath=path)
    elif ext == ".obj":
        bpy.ops.import_scene.obj(filepath=path)
    elif ext == ".stl":
        bpy.ops.import_mesh.stl(filepath=path)
    else:
        raise ValueError(f"no Blender importer for {path}")
    obj = bpy.context.selected_objects[0]
    select_only(obj)
    return obj


def mesh_arrays(me):
    """Everything the tests compare, as numpy arrays."""
    def get(coll, prop, n, dtype, comps=1):
        a = np.empty(n * comps, dtype)
        if n:
            coll.foreach_get(prop, a)
        return a
    nv, nl, nf, ne = len(me.vertices), len(me.loops), len(me.polygons), len(me.edges)
    out = {
        "co": get(me.vertices, "co", nv, np.float32, 3),
        "loop_vertex": get(me.loops, "vertex_index", nl, np.int32),
        "loop_total": get(me.polygons, "loop_total", nf, np.int32),
        "loop_start": get(me.polygons, "loop_start", nf, np.int32),
        "material": get(me.polygons, "material_index", nf, np.int32),
        "smooth": get(me.polygons, "use_smooth", nf, np.bool_),
        "edges": get(me.edges, "vertices", ne, np.int32, 2),
        "seam": get(me.edges, "use_seam", ne, np.bool_),
        "sharp": get(me.edges, "use_edge_sharp", ne, np.bool_),
    }
    for layer in me.uv_layers:
        out["uv:" + layer.name] = get(layer.data, "uv", nl, np.float32, 2)
    for attr in me.attributes:
        if attr.name.startswith("."):
            continue
        prop = {"FLOAT": "value", "INT": "value", "FLOAT_VECTOR": "vector", "FLOAT2": "vector",
                "FLOAT_COLOR": "color", "BYTE_COLOR": "color_srgb", "BOOLEAN": "value", "INT8": "value"}.get(attr.data_type)
        if prop is None:
            continue
        n = len(attr.data)
        comps = {"FLOAT_VECTOR": 3, "FLOAT2": 2, "FLOAT_COLOR": 4, "BYTE_COLOR": 4}.get(attr.data_type, 1)
        dtype = {"INT": np.int32, "BOOLEAN": np.bool_, "INT8": np.int8}.get(attr.data_type, np.float32)
        out[f"attr:{attr.name}:{attr.domain}"] = get(attr.data, prop, n, dtype, comps)
    return out


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


def run_tests(*cases):
    suite = unittest.TestSuite()
    for case in cases:
        suite.addTests(unittest.defaultTestLoader.loadTestsFromTestCase(case))
    result = unittest.TextTestRunner(verbosity=2, stream=sys.stdout).run(suite)
    sys.stdout.flush()
    if not result.wasSuccessful():
        raise SystemExit(1)
