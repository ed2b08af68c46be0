# What the Blender add-on costs outside the native call, beside the bare exchange floor
# measured in the same process (issue 13's target: at most 1.5x the floor). A benchmark, not a
# test: it prints the figures and asserts nothing.
#
#   blender -b --factory-startup --python tests/bench/blender_overhead.py -- \
#       --addon-zip build/hedge_blender_addon.zip --extension-zip build/hedge_blender_extension.zip \
#       --meshes build/meshes [--input dragon.ply] [--op decimate] [--ratio 0.1] [--runs 3]
#
# Per run, on a fresh import of the mesh:
#   total     hedge.run(obj, op, ...) as a script calls it
#   native    the native call's own time (the report's "seconds")
#   add-on    total - native: reading, checking and writing, in Python and Blender
#   floor     the least any add-on must do with the same data: foreach_get of positions and
#             loops, then clear_geometry + add + foreach_set + update of a mesh of the result's size
import os
import sys
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "blender"))
import bpy  # noqa: E402
import numpy as np  # noqa: E402
from blender_test import ARGS, clear_scene, import_mesh, install_addon  # noqa: E402


def option(name, default):
    rest = ARGS.rest
    return type(default)(rest[rest.index(name) + 1]) if name in rest else default


def places(me):
    """3.5+ keeps the vertices' places as the "position" attribute, copied in one go."""
    position = me.attributes.get("position")
    return (position.data, "vector") if position is not None else (me.vertices, "co")


def read_floor(me):
    """Positions and loops out of Blender by the fastest way the running Blender has: 4.0+
    keeps the corners' vertices as the ".corner_vert" attribute, read in one copy, and the
    polygons' loops in order; 3.x reads the loops' property. The mesh's own index properties
    (loop starts and totals, loop vertices) are unsigned: foreach copies them whole only into
    uint32 buffers."""
    nv, nl, nf = len(me.vertices), len(me.loops), len(me.polygons)
    positions = np.empty(nv * 3, np.float32)
    collection, prop = places(me)
    collection.foreach_get(prop, positions)
    corners = np.empty(nl, np.int32)
    corner_vert = me.attributes.get(".corner_vert")
    if corner_vert is not None:
        starts = np.empty(nf, np.uint32)
        me.polygons.foreach_get("loop_start", starts)
        sizes = np.diff(np.append(starts, np.int32(nl))).astype(np.int32)
        corner_vert.data.foreach_get("value", corners)
    else:
        sizes = np.empty(nf, np.uint32)
        me.polygons.foreach_get("loop_total", sizes)
        me.loops.foreach_get("vertex_index", corners.view(np.uint32))
    return positions, sizes.view(np.int32), corners


def write_floor(me, positions, sizes, corners):
    """A mesh of that data written into Blender, as the exchange writes a result."""
    me.clear_geometry()
    me.vertices.add(len(positions) // 3)
    me.loops.add(len(corners))
    me.polygons.add(len(sizes))
    collection, prop = places(me)
    collection.foreach_set(prop, positions)
    corner_vert = me.attributes.get(".corner_vert")
    if corner_vert is not None:
        corner_vert.data.foreach_set("value", corners)
    else:
        me.loops.foreach_set("vertex_index", corners.view(np.uint32))
    starts = np.zeros(len(sizes), np.uint32)
    np.cumsum(sizes[:-1], out=starts[1:])
    me.polygons.foreach_set("loop_start", starts)
    if "loop_total" in bpy.types.MeshPolygon.bl_rna.properties and not bpy.types.MeshPolygon.bl_rna.properties[
            "loop_total"].is_readonly:
        me.polygons.foreach_set("loop_total", sizes.view(np.uint32))
    me.update(calc_edges=True)


def main():
    hedge = install_addon()
    path = os.path.join(ARGS.meshes, option("--input", "dragon.ply"))
    op, ratio, runs = option("--op", "decimate"), option("--ratio", 0.1), option("--runs", 3)
    params = {"target_ratio": ratio} if op == "decimate" else {}
    print(f"Blender {bpy.app.version_string}, {os.path.basename(path)}, {op} {params}, {runs} runs")
    print(f"{'run':>3} {'faces in':>9} {'faces out':>9} {'total s':>8} {'native s':>8} {'add-on s':>8} "
          f"{'floor s':>8} {'add-on/floor':>12}")
    addons, floors = [], []
    for run in range(runs):
        clear_scene()
        obj = import_mesh(path)
        faces_in = len(obj.data.polygons)
        t0 = time.perf_counter()
        report = hedge.run(obj, op, **params)
        total = time.perf_counter() - t0
        native = float(report["seconds"])
        result = read_floor(obj.data)  # the result's own data, for the write half of the floor

        clear_scene()
        obj = import_mesh(path)
        t0 = time.perf_counter()
        read_floor(obj.data)
        write_floor(obj.data, *result)
        floor = time.perf_counter() - t0

        addon = total - native
        addons.append(addon)
        floors.append(floor)
        print(f"{run + 1:>3} {faces_in:>9} {len(result[1]):>9} {total:>8.3f} {native:>8.3f} {addon:>8.3f} "
              f"{floor:>8.3f} {addon / floor:>12.2f}")
    # The ratio of the medians: a run whose floor alone was slowed does not decide it.
    addon, floor = sorted(addons)[runs // 2], sorted(floors)[runs // 2]
    print(f"median add-on {addon:.3f} s / median floor {floor:.3f} s: {addon / floor:.2f} (target: at most 1.5)")


main()
