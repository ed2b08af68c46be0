# hedge: half-edge mesh processing for Blender. Every operation of hedge's catalogue as an
# undoable operator (mesh.hedge_<id>), a "Hedge" sidebar panel, menu entries, and a batch
# API: `import hedge; hedge.run(obj, "decimate", target_ratio=0.1)`.
bl_info = {
    "name": "Hedge",
    "author": "hedge authors",
    "version": (0, 1, 0),
    "blender": (3, 4, 0),
    "location": "View3D > Sidebar > Hedge; Object and Mesh menus > Hedge",
    "description": "Half-edge mesh processing: decimate, remesh, subdivide, fill holes, smooth, repair, report",
    "category": "Mesh",
}

import bpy

from . import api, exchange, native, operators, panel
from .api import run, catalogue, operation
from .native import Error, Cancelled

_classes = []


def register():
    _classes.clear()
    if native.native is not None:
        _classes.extend(operators.make_operators())
    _classes.extend([panel.VIEW3D_MT_hedge, panel.VIEW3D_PT_hedge])
    for cls in _classes:
        bpy.utils.register_class(cls)
    for name in panel.MENUS:
        getattr(bpy.types, name).append(panel.menu_entry)


def unregister():
    for name in panel.MENUS:
        getattr(bpy.types, name).remove(panel.menu_entry)
    for cls in reversed(_classes):
        bpy.utils.unregister_class(cls)
    _classes.clear()
