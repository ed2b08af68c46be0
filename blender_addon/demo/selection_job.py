# Selection only, as a Blender user runs it: in Edit Mode, half of a dragon selected (the faces
# behind its middle, drawn blue), the Hedge Decimate operator with Selection only; the other
# half (orange) and the border come back as they were. Prints the counts and renders a
# before/after picture with Workbench (flat shading shows the facets).
#   xvfb-run -a blender -b --factory-startup --python-exit-code 1 --python selection_job.py -- \
#       --mesh dragon_res2.ply --out DIR [--zip PACKAGE] [--picture docs/blender_selection.png]
import os
import sys

import bmesh
import bpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from demo_common import arguments, load_hedge, render_before_after  # noqa: E402


def options(parser):
    parser.add_argument("--ratio", type=float, default=0.05)


args = arguments(options)
hedge = load_hedge(args.zip)

dragon = hedge.api.import_file(args.mesh, "dragon")
me = dragon.data
for name, colour in (("kept", (0.8, 0.55, 0.3, 1)), ("selected", (0.3, 0.5, 0.85, 1))):
    material = bpy.data.materials.new(name)
    material.diffuse_color = colour
    me.materials.append(material)

# Edit Mode: the faces past the middle of the longest axis selected and given the blue material.
bpy.context.view_layer.objects.active = dragon
dragon.select_set(True)
bpy.ops.object.mode_set(mode='EDIT')
bpy.ops.mesh.select_mode(type='FACE')
bm = bmesh.from_edit_mesh(me)
axis = max(range(3), key=lambda k: dragon.dimensions[k])
middle = sorted(f.calc_center_median()[axis] for f in bm.faces)[len(bm.faces) // 2]
for f in bm.faces:
    inside = f.calc_center_median()[axis] > middle
    f.select_set(inside)
    f.material_index = 1 if inside else 0
bm.select_flush_mode()
bmesh.update_edit_mesh(me)
dragon.update_from_editmode()
faces_before, selected_before = len(me.polygons), sum(p.select for p in me.polygons)

before = dragon.copy()
before.data = me.copy()
before.name = "before"
bpy.context.collection.objects.link(before)

result = bpy.ops.mesh.hedge_decimate(selection_only=True, target_ratio=args.ratio)
bpy.ops.object.mode_set(mode='OBJECT')
if result != {'FINISHED'}:
    sys.exit(f"the operator did not finish: {result}")
selected_after = sum(p.select for p in me.polygons)
print(f"  selection-only decimate to {args.ratio:.0%}: {faces_before:,} -> {len(me.polygons):,} faces; "
      f"selected {selected_before:,} -> {selected_after:,}, the other {faces_before - selected_before:,} kept")

render_before_after(before, dragon, (f"before: {faces_before:,} faces, {selected_before:,} selected",
                                     f"after: {len(me.polygons):,} faces, {selected_after:,} selected"),
                    os.path.join(args.out, "blender_selection.png"), args.picture, label_size=0.06)
