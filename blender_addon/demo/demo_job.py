# The demo's Blender part, run by scripts/demo in `blender -b`: the main job on the Stanford
# dragon through the add-on's batch API (decimate to 10 %, remesh, fill holes), timed, next to
# Blender's own Decimate modifier; then a before/after picture rendered with Workbench. The
# same script in every Blender from 3.4 on (5.2 in the sid root).
#   blender -b --factory-startup --python-exit-code 1 --python demo_job.py -- \
#       --mesh dragon.ply --out DIR [--zip PACKAGE] [--picture docs/blender_demo.png] [--no-modifier] [--no-render]
# --zip: installed first when hedge is not installed yet: the legacy add-on zip for Blender
# 3.4-4.1, the extension zip (build/hedge_blender_extension.zip) for 4.2 and later.
import json
import os
import sys
import time

import bpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from demo_common import arguments, load_hedge, render_before_after  # noqa: E402


def options(parser):
    parser.add_argument("--no-modifier", action="store_true", help="skip Blender's Decimate modifier")
    parser.add_argument("--no-render", action="store_true")


args = arguments(options)
hedge = load_hedge(args.zip)


def faces(obj):
    return len(obj.data.polygons)


def timed(label, fn):
    start = time.perf_counter()
    value = fn()
    seconds = time.perf_counter() - start
    return value, seconds


summary = {}
dragon, t = timed("import", lambda: hedge.api.import_file(args.mesh, "dragon"))
print(f"  {'import with hedge reader':34s} {t:6.2f} s   -> {faces(dragon):,} faces")
summary["input_faces"] = faces(dragon)
before = dragon.copy()
before.data = dragon.data.copy()
before.name = "before"
bpy.context.collection.objects.link(before)

# The main job: three operations through the batch API (each reads the Blender mesh, runs,
# writes it back).
for label, op, params in (("Hedge decimate to 10 %", "decimate", {"target_ratio": 0.1}),
                          ("Hedge remesh, 3 iterations", "remesh", {"iterations": 3}),
                          ("Hedge fill holes", "fill_holes", {})):
    report, t = timed(label, lambda: hedge.run(dragon, op, **params))
    print(f"  {label:34s} {t:6.2f} s   -> {faces(dragon):,} faces "
          f"(in hedge {report['seconds']:.2f} s, Blender exchange {t - report['seconds']:.2f} s)")
    summary[op] = {"seconds": t, "hedge_seconds": report["seconds"], "faces": faces(dragon)}
report = hedge.run(dragon, "report")
print(f"  result: {report['faces']:,} faces, {report['boundary_loops']} holes, "
      f"edge length mean {report['edge_length_mean']:.4g} (stddev {report['edge_length_stddev']:.2g}), "
      f"min angle mean {report['mean_min_angle_degrees']:.1f} deg")

# Decimation alone: hedge vs Blender's Decimate modifier (collapse), each on a fresh copy.
copy = before.copy()
copy.data = before.data.copy()
bpy.context.collection.objects.link(copy)
report, t = timed("hedge", lambda: hedge.run(copy, "decimate", target_ratio=0.1))
print("\n== decimating the dragon to 10 % in Blender ==")
label = 'hedge.run(obj, "decimate")'
print(f"  {label:34s} {t:6.2f} s   -> {faces(copy):,} faces")
summary["hedge_decimate_seconds"] = t
bpy.data.objects.remove(copy)
if not args.no_modifier:
    copy = before.copy()
    copy.data = before.data.copy()
    bpy.context.collection.objects.link(copy)
    bpy.context.view_layer.objects.active = copy
    mod = copy.modifiers.new("Decimate", 'DECIMATE')
    mod.decimate_type = 'COLLAPSE'
    mod.ratio = 0.1
    mod.show_viewport = False  # evaluated once, on apply (hosts.md)
    with bpy.context.temp_override(object=copy, active_object=copy):
        _, t = timed("modifier", lambda: bpy.ops.object.modifier_apply(modifier="Decimate"))
    print(f"  {'Blender Decimate modifier, applied':34s} {t:6.2f} s   -> {faces(copy):,} faces")
    summary["blender_decimate_seconds"] = t
    bpy.data.objects.remove(copy)

with open(os.path.join(args.out, "blender_demo.json"), "w") as f:
    json.dump(summary, f, indent=1)

if args.no_render:
    sys.exit(0)

# The picture: before (left) and after (right).
_, t = timed("render", lambda: render_before_after(
    before, dragon, (f"before: {faces(before):,} faces", f"after: {faces(dragon):,} faces"),
    os.path.join(args.out, "blender_before_after.png"), args.picture, color=(0.8, 0.55, 0.3)))
print(f"  render took {t:.1f} s")
