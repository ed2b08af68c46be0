# What the Blender demo jobs share: their command line, loading hedge, and the before/after
# picture (two objects side by side under an orthographic camera, each with a label, rendered
# with Workbench, whose flat shading shows the facets, and a small copy for the README).
import argparse
import os
import sys

import bpy
from mathutils import Vector

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tools"))
import hedge_install  # noqa: E402


def arguments(add_options):
    """The job's arguments after `--`: --mesh, --out, --picture, --zip, and what
    add_options(parser) adds. Makes --out."""
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    parser = argparse.ArgumentParser()
    parser.add_argument("--mesh", required=True)
    parser.add_argument("--out", required=True)
    parser.add_argument("--picture", default="", help="also write a small copy of the picture here")
    parser.add_argument("--zip", default="", help="install this package first if hedge is not installed")
    add_options(parser)
    args = parser.parse_args(argv)
    os.makedirs(args.out, exist_ok=True)
    return args


def load_hedge(zip_path):
    """The hedge package installed from `zip_path` (so the demo shows the build it was given,
    never an older install), or the installed one when no zip is given; an empty scene."""
    if zip_path:
        hedge_install.install(zip_path)
    else:
        try:
            hedge_install.enable(quiet=True)
        except RuntimeError:
            sys.exit("the hedge add-on is not installed (./run install, or pass --zip)")
    import hedge
    for obj in list(bpy.data.objects):
        bpy.data.objects.remove(obj)
    return hedge


def render_before_after(before, after, labels, path, picture="", color=None, label_size=0.07):
    """Renders `before` (left) and `after` (right) into `path`; `labels` are their captions.
    `color`: one RGB for both, or None to draw each face in its material's colour."""
    scale = 1.15 / max(before.dimensions)
    for obj, x in ((before, -0.6), (after, 0.6)):
        obj.data.polygons.foreach_set("use_smooth", [False] * len(obj.data.polygons))
        obj.rotation_euler = (1.5708, 0, 0.5)
        obj.location = (0, 0, 0)
        obj.scale = (scale, scale, scale)
        bpy.context.view_layer.update()
        centre = sum((obj.matrix_world @ Vector(c) for c in obj.bound_box), Vector()) / 8
        obj.location = Vector((x, 0, 0)) - centre
    for text, x in zip(labels, (-0.6, 0.6)):
        curve = bpy.data.curves.new("label", 'FONT')
        curve.body = text
        curve.size = label_size
        curve.align_x = 'CENTER'
        label = bpy.data.objects.new("label", curve)
        label.location = (x, 0, -0.5)
        label.rotation_euler = (1.5708, 0, 0)
        bpy.context.collection.objects.link(label)
    camera_data = bpy.data.cameras.new("camera")
    camera_data.type = 'ORTHO'
    camera_data.ortho_scale = 2.5
    camera = bpy.data.objects.new("camera", camera_data)
    camera.location = (0, -4, 0)
    camera.rotation_euler = (1.5708, 0, 0)
    bpy.context.collection.objects.link(camera)
    scene = bpy.context.scene
    scene.camera = camera
    scene.render.engine = 'BLENDER_WORKBENCH'
    scene.display.shading.light = 'STUDIO'
    if color is None:
        scene.display.shading.color_type = 'MATERIAL'
    else:
        scene.display.shading.color_type = 'SINGLE'
        scene.display.shading.single_color = color
    scene.display.shading.show_cavity = True
    scene.render.resolution_x = 1400
    scene.render.resolution_y = 700
    scene.render.resolution_percentage = 100
    scene.render.film_transparent = False
    scene.world = bpy.data.worlds.new("world") if scene.world is None else scene.world
    scene.world.color = (1, 1, 1)
    scene.view_settings.view_transform = 'Standard'  # a white background (4.x's default AgX greys it)
    scene.render.image_settings.file_format = 'PNG'
    scene.render.filepath = path
    bpy.ops.render.render(write_still=True)
    print(f"  rendered {path}")
    if picture:
        image = bpy.data.images.load(path)
        image.scale(700, 350)
        image.filepath_raw = os.path.abspath(picture)
        image.file_format = 'PNG'
        image.save()
        print(f"  small copy {picture} ({os.path.getsize(picture) // 1024} KB)")
