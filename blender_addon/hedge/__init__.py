# hedge: half-edge mesh processing for Blender. Every operation of hedge's catalogue as an
# undoable operator (mesh.hedge_<id>), a "Hedge" sidebar panel, menu entries, and a batch
# API: `import hedge; hedge.run(obj, "decimate", target_ratio=0.1)`.
#
# One package, two ways in: the legacy add-on (bl_info; Blender 3.4 and later, imported as
# `hedge`) and the extension (blender_manifest.toml; 4.2 and later, imported as
# bl_ext.<repository>.hedge). Inside, imports are relative. An enabled extension also answers
# to `import hedge`, so one batch script serves every version (see _alias).
bl_info = {
    "name": "Hedge",
    "author": "hedge authors",
    "version": (0, 1, 0),
    "blender": (3, 4, 0),
    "location": "View3D > Sidebar > Hedge; Object and Mesh menus > Hedge",
    "description": "Half-edge mesh processing: decimate, remesh, subdivide, fill holes, smooth, repair, report",
    "category": "Mesh",
}

import sys

import bpy

from . import api, exchange, native, operators, panel
from .api import run, catalogue, operation
from .native import Error, Cancelled

_classes = []


def _alias(on):
    """As an extension, makes `import hedge` (and hedge.api, ...) this package while it is
    enabled, unless another package already has that name (a legacy hedge add-on)."""
    if __name__ == "hedge":
        return
    names = {name: "hedge" + name[len(__name__):] for name in list(sys.modules)
             if name == __name__ or name.startswith(__name__ + ".")}
    me = sys.modules[__name__]
    if on and sys.modules.get("hedge", me) is me:
        for name, alias in names.items():
            sys.modules[alias] = sys.modules[name]
    elif not on and sys.modules.get("hedge") is me:
        for name, alias in names.items():
            sys.modules.pop(alias, None)


def register():
    _alias(True)
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
    _alias(False)
