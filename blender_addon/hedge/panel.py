# The "Hedge" tab of the 3D View sidebar, and the Hedge submenu in the Object and Mesh menus.
import bpy

from . import api
from .native import native, load_error

def grouped_operations():
    ops = native.catalogue() if native else []
    groups = {}
    for op in ops:
        groups.setdefault(op["category"], []).append(op)
    return [(c, groups[c]) for c in native.categories() if c in groups] if native else []


def format_value(value):
    if isinstance(value, float):
        return f"{value:.4g}"
    return str(value)


def draw_report(layout, title, report):
    box = layout.box()
    box.label(text=title, icon='INFO')
    col = box.column(align=True)
    for key, value in report.items():
        if key == "messages":
            continue
        row = col.split(factor=0.64)
        row.label(text=key.replace("_", " "))
        row.label(text=format_value(value))
    for message in report.get("messages", []):
        col.label(text=message, icon='ERROR' if message.startswith("input:") else 'DOT')


class VIEW3D_PT_hedge(bpy.types.Panel):
    bl_space_type = 'VIEW_3D'
    bl_region_type = 'UI'
    bl_category = "Hedge"
    bl_label = "Hedge"

    def draw(self, context):
        layout = self.layout
        if native is None:
            col = layout.column()
            col.alert = True
            col.label(text="Native module not loaded", icon='ERROR')
            for i in range(0, len(load_error), 40):
                col.label(text=load_error[i:i + 40])
            return
        targets = api.targets(context)
        layout.label(text=f"{len(targets)} mesh{'es' if len(targets) != 1 else ''} to process"
                     + (" (Edit Mode: whole mesh)" if context.mode == 'EDIT_MESH' else ""))
        for category, ops in grouped_operations():
            col = layout.column(align=True)
            col.label(text=category)
            for op in ops:
                col.operator(f"mesh.hedge_{op['id']}", text=op["title"])
        obj = context.active_object
        report = api.last_reports.get("report:" + obj.name) if obj else None
        if report:
            draw_report(layout, f"Mesh Report: {obj.name}", report)
        last = [api.last_reports[op["id"]] for _, ops in grouped_operations() for op in ops
                if op["changes_mesh"] and op["id"] in api.last_reports]
        if last:
            draw_report(layout, "Last run", last[-1])


class VIEW3D_MT_hedge(bpy.types.Menu):
    bl_label = "Hedge"
    bl_idname = "VIEW3D_MT_hedge"

    def draw(self, context):
        layout = self.layout
        if native is None:
            layout.label(text="Hedge: native module not loaded", icon='ERROR')
            return
        for i, (category, ops) in enumerate(grouped_operations()):
            if i:
                layout.separator()
            for op in ops:
                layout.operator(f"mesh.hedge_{op['id']}", text=op["title"])


def menu_entry(self, context):
    self.layout.separator()
    self.layout.menu(VIEW3D_MT_hedge.bl_idname)


MENUS = ("VIEW3D_MT_object", "VIEW3D_MT_edit_mesh")
