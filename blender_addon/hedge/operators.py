# One operator per catalogue operation, generated from the catalogue: mesh.hedge_<id> with
# properties named as the parameter ids (defaults, ranges, enums, help as tooltips), REGISTER
# and UNDO so the redo panel adjusts the last run. Interactive runs work on a thread with
# the progress bar and Esc to cancel; execute() (redo, scripts) runs synchronously.
import bpy

from . import api, exchange
from .native import Error, Cancelled, require_native

INT_LIMIT = 2**31 - 1
FLOAT_LIMIT = 3.0e38
# Operation ids of the interactive runs in progress (for tests and scripts that wait).
running = set()
# Jobs cancelled by Esc: control returns to the user at once, and the worker thread stops at
# the operation's next progress checkpoint; kept here until then.
abandoned = []


def reap_abandoned():
    abandoned[:] = [job for job in abandoned if not job.done()]

# What the Blender exchange carries and does not, said in every tooltip of a changing operation.
EXCHANGE_NOTE = ("Shape keys follow: each key is carried as its offset from the basis (the reference key), "
                 "interpolated like an attribute (decimation measures its error in every key too), and "
                 "rebuilt as the new basis plus that offset, so keys relative to other keys and absolute "
                 "keys deform as before; the same keys stay, with their names, order, settings, drivers "
                 "and animation. Not carried when the connectivity changes: "
                 "custom split normals, loose edges. Vertex group weights are interpolated (weight 0 leaves "
                 "the group); seams, sharp edges and creases follow edges whose ends both come from the "
                 "vertices of such an edge")


def first_paragraph(text):
    return text.strip().split("\n\n")[0].replace("\n", " ")


def make_property(p):
    help_text = f"{p['help']} [{p['id']}: {p['range_text']}]"
    if p["type"] == "bool":
        return bpy.props.BoolProperty(name=p["label"], description=help_text, default=bool(p["default"]))
    if p["type"] == "int":
        lo, hi = max(int(p["min"]), -INT_LIMIT), INT_LIMIT if p["max"] is None else min(int(p["max"]), INT_LIMIT)
        return bpy.props.IntProperty(name=p["label"], description=help_text, default=int(p["default"]),
                                     min=lo, max=hi, soft_min=lo, soft_max=hi)
    if p["type"] == "float":
        lo, hi = max(p["min"], -FLOAT_LIMIT), FLOAT_LIMIT if p["max"] is None else min(p["max"], FLOAT_LIMIT)
        return bpy.props.FloatProperty(name=p["label"], description=help_text, default=p["default"],
                                       min=lo, max=hi, soft_min=lo, soft_max=hi, precision=4)
    if p["type"] == "enum":
        items = [(c, c.replace("_", " ").title(), f"{p['help']} ({c})") for c in p["choices"]]
        return bpy.props.EnumProperty(name=p["label"], description=help_text, items=items, default=p["default"])
    if p["type"] == "vertex_channel":
        return bpy.props.StringProperty(name=p["label"], description=help_text, default=p["default"],
                                        search=vertex_attribute_names, search_options={'SUGGESTION', 'SORT'})
    raise Error(f"parameter {p['id']}: unknown type {p['type']}")


def vertex_attribute_names(self, context, edit_text):
    """What a vertex-attribute field suggests: the active object's vertex groups and its
    one-number point attributes (typing another name stays allowed)."""
    obj = context.active_object
    if obj is None or obj.type != 'MESH':
        return []
    generic = [(a.name, a.data_type, a.domain) for a in obj.data.attributes
               if not a.name.startswith(".") and a.name not in exchange.RESERVED]
    names = exchange.vertex_attribute_names([g.name for g in obj.vertex_groups], generic)
    return [n for n in names if edit_text.lower() in n.lower()]


class HedgeOperator:
    """Shared by the generated operators; `operation` is the catalogue entry."""
    operation = None
    full_description = ""

    @classmethod
    def description(cls, context, properties):
        # The whole text for the tooltip: Blender cuts bl_description (to 239 characters in
        # 3.4, 1023 later), and an operation's help with the exchange note is longer.
        return cls.full_description

    @classmethod
    def poll(cls, context):
        return bool(api.targets(context))

    def params(self):
        return {p["id"]: getattr(self, p["id"]) for p in self.operation["params"]}

    def done(self, context, reports):
        op = self.operation
        for report in reports:
            self.report({'INFO'}, api.summary(op, report))
            if not op["changes_mesh"]:
                for key, value in report.items():
                    if key != "messages":
                        self.report({'INFO'}, f"  {key}: {value}")
            for message in report.get("messages", []):
                self.report({'WARNING'} if message.startswith("input:") else {'INFO'}, message)
        if context.area:
            context.area.tag_redraw()
        return {'FINISHED'}

    def fail(self, error):
        api.last_errors[self.operation["id"]] = str(error)
        if isinstance(error, Cancelled):
            self.report({'WARNING'}, f"Hedge {self.operation['title']}: cancelled; the mesh is unchanged")
        else:
            self.report({'ERROR'}, f"Hedge {self.operation['title']}: {error}")
        return {'CANCELLED'}

    def execute(self, context):
        targets = [api.Target(obj) for obj in api.targets(context)]
        wm = context.window_manager
        wm.progress_begin(0, 1000)
        try:
            reports = api.run_targets(self.operation["id"], targets, self.params(),
                                      lambda f, stage: wm.progress_update(int(f * 1000)) or True)
        except Error as e:
            return self.fail(e)
        finally:
            wm.progress_end()
        return self.done(context, reports)

    # Interactive: a worker thread per mesh, polled by a timer; Esc cancels; the results are
    # written only when every mesh is done.
    def invoke(self, context, event):
        if bpy.app.background or context.window is None:
            return self.execute(context)
        self._batch = api.Batch(self.operation["id"], [api.Target(obj) for obj in api.targets(context)],
                                self.params())
        self._job = None
        try:
            self._next()
        except Error as e:
            self._release()
            return self.fail(e)
        wm = context.window_manager
        self._timer = wm.event_timer_add(0.1, window=context.window)
        wm.progress_begin(0, 1000)
        wm.modal_handler_add(self)
        running.add(self.operation["id"])
        return {'RUNNING_MODAL'}

    def _next(self):
        if not self._batch.finished():
            self._job = require_native().Job(self.operation["id"], *self._batch.read_next())
            self._batch.read_rest()

    def _release(self):
        self._batch.release()
        self._job = None

    def _stop(self, context):
        running.discard(self.operation["id"])
        wm = context.window_manager
        wm.event_timer_remove(self._timer)
        wm.progress_end()
        if context.workspace:
            context.workspace.status_text_set(None)

    def modal(self, context, event):
        reap_abandoned()
        if event.type == 'ESC' and event.value == 'PRESS' and self._job is not None:
            self._job.cancel()
            abandoned.append(self._job)
            self._stop(context)
            self._release()
            return self.fail(Cancelled("cancelled by the user"))
        if event.type != 'TIMER':
            return {'RUNNING_MODAL'}
        n = len(self._batch.targets)
        fraction, stage = self._job.progress()
        context.window_manager.progress_update(int((self._batch.index + fraction) / n * 1000))
        if context.workspace:
            context.workspace.status_text_set(f"Hedge {self.operation['title']}: {stage} "
                                              f"({100 * fraction:.0f} %) - Esc to cancel")
        if not self._job.done():
            return {'RUNNING_MODAL'}
        try:
            self._batch.record(*self._job.result())
            self._next()
        except Error as e:
            self._stop(context)
            self._release()
            return self.fail(e)
        if not self._batch.finished():
            return {'RUNNING_MODAL'}
        self._stop(context)
        try:
            reports = self._batch.commit()
        except Error as e:
            self._release()
            return self.fail(e)
        return self.done(context, reports)


def make_operator(op):
    annotations = {p["id"]: make_property(p) for p in op["params"]}
    description = first_paragraph(op["help"])
    if op["changes_mesh"]:
        description = description.rstrip(".") + ". " + EXCHANGE_NOTE
    return type(f"MESH_OT_hedge_{op['id']}", (HedgeOperator, bpy.types.Operator), {
        "bl_idname": f"mesh.hedge_{op['id']}",
        "bl_label": op["title"],
        "bl_description": description,
        "full_description": description,
        "bl_options": {'REGISTER', 'UNDO'},
        "__annotations__": annotations,
        "operation": op,
    })


def make_operators():
    return [make_operator(op) for op in require_native().catalogue()]
