# The batch API and the work shared with the operators: which meshes to process, reading
# them (Object Mode data or the edit mesh), running an operation, writing the results back
# only once every mesh succeeded.
#
#   import hedge
#   report = hedge.run(bpy.data.objects["dragon"], "decimate", target_ratio=0.1)
import bmesh
import bpy

from . import exchange
from .native import native, Error, Cancelled, require_native

# The last report of each operation and of each object's Mesh Report, for the panel, and
# the parameters of each operation's last run (after Blender's property limits).
last_reports = {}
last_params = {}
last_errors = {}  # operation id -> the message of its last failure or cancellation


def catalogue():
    """Every operation as a dict (id, title, category, help, changes_mesh, params)."""
    return require_native().catalogue()


def operation(op_id):
    for op in catalogue():
        if op["id"] == op_id:
            return op
    raise Error(f"unknown operation '{op_id}'; the operations are: " + ", ".join(o["id"] for o in catalogue()))


class Target:
    """One mesh to process: an object in Object Mode, or one in Edit Mode (its edit mesh)."""

    def __init__(self, obj):
        if obj is None or obj.type != 'MESH':
            raise Error(f"{getattr(obj, 'name', obj)!r} is not a mesh object")
        self.obj = obj
        self.edit = obj.mode == 'EDIT'
        self.scratch = None
        self.read_from = None  # the mesh read: the object's, or the edit mesh's scratch copy
        self.data = None
        self.result = None
        self.report = None

    def read(self, op=None):
        """Reads the mesh into a soup for `op` (its shape keys too when `op` changes the mesh)."""
        me = self.obj.data
        carry_keys = me.shape_keys is not None and (op is None or op["changes_mesh"])
        if self.edit:
            # The edit mesh is the truth in Edit Mode: work on a copy, load it back after.
            # Loading it into the object's mesh first also writes its shape layers into the
            # key blocks, which are read from there.
            self.obj.update_from_editmode()  # the weights are read from the object's mesh
            if carry_keys:
                # A copy keeps the key blocks (with the ids that tie them to the edit mesh's
                # shape layers), for the result to be loaded back with them.
                self.scratch = me.copy()
                self.scratch.name = "hedge scratch"
            else:
                self.scratch = bpy.data.meshes.new("hedge scratch")
                bmesh.from_edit_mesh(me).to_mesh(self.scratch)
            me = self.scratch
        self.read_from = me
        self.data = exchange.read_mesh(me, edges=False, buffers=require_native().SoupBuffers)
        exchange.read_vertex_groups(self.obj, self.obj.data, self.data)
        if carry_keys:
            exchange.read_shape_keys(me, self.data)
        return self.data.soup

    def read_rest(self):
        """What only writing the result back needs (read while the operation runs)."""
        if self.data is not None and not self.data.edges_read:
            exchange.read_edges(self.read_from, self.data)

    def check_writable(self, op):
        """Refuses, before anything is written, what the exchange cannot keep consistent."""
        if self.result is None:
            return
        # Keys added, removed or renamed since the read (an interactive run leaves the UI
        # free) would be left the old size or written to the wrong key.
        problem = exchange.missing_shape_keys(self.obj.data, self.data, self.result)
        if problem:
            raise Error(f"{self.obj.name}: {problem}; nothing was written")

    def write(self):
        if self.result is not None:
            self.read_rest()
            if self.edit:
                # A stand-in object lets the vertex groups be rebuilt on the scratch mesh, in
                # the object's order, before the edit mesh loads it (a copy of the object's
                # mesh names its groups already).
                stand_in = bpy.data.objects.new("hedge scratch", self.scratch)
                bpy.context.scene.collection.objects.link(stand_in)
                try:
                    for name in self.data.vertex_groups:
                        if name not in stand_in.vertex_groups:
                            stand_in.vertex_groups.new(name=name)
                    messages = exchange.write_mesh(self.scratch, self.data, self.result, obj=stand_in)
                finally:
                    bpy.data.objects.remove(stand_in)
                bm = bmesh.from_edit_mesh(self.obj.data)
                bm.clear()
                if self.data.shape_keys:
                    # As entering Edit Mode does: a shape layer per key block, the vertices at
                    # the active key's shape.
                    bm.from_mesh(self.scratch, use_shape_key=True, shape_key_index=self.obj.active_shape_key_index)
                else:
                    bm.from_mesh(self.scratch)
                bmesh.update_edit_mesh(self.obj.data, loop_triangles=True, destructive=True)
                # clear() unlinks the edit mesh from its Python wrapper, which a script may
                # hold (from_edit_mesh hands out one wrapper): left so, it would outlive the
                # edit mesh and crash Blender when collected. Invalidated, it raises instead.
                bm.free()
            else:
                messages = exchange.write_mesh(self.obj.data, self.data, self.result, obj=self.obj)
                self.obj.data.update()
            if self.report is not None:
                self.report.setdefault("messages", []).extend(messages)
        self.release()

    def release(self):
        if self.scratch is not None:
            bpy.data.meshes.remove(self.scratch)
            self.scratch = None


def targets(context):
    """The meshes an operator works on: every selected mesh object in Object Mode (each
    mesh once, even when objects share it), the objects in Edit Mode otherwise."""
    if context.mode == 'EDIT_MESH':
        objects = list(getattr(context, "objects_in_mode", None) or [context.edit_object])
    else:
        objects = [o for o in (context.selected_objects or []) if o.type == 'MESH']
    seen, out = set(), []
    for obj in objects:
        if obj is not None and obj.type == 'MESH' and obj.data.name_full not in seen:
            seen.add(obj.data.name_full)
            out.append(obj)
    return out


# How often a synchronous run reports progress.
PROGRESS_SECONDS = 0.1
# How many of an operation's results (catalogue order) the one-line summary shows.
SUMMARY_RESULTS = 4


def summary(op, report):
    """One line for the info area: the operation's first results and the time."""
    keys = [k for k in op["results"] if k in report][:SUMMARY_RESULTS] + ["seconds"]
    parts = []
    for key in keys:
        if key in report:
            value = report[key]
            parts.append(f"{key.replace('_', ' ')} {value:.3g}" if isinstance(value, float) else f"{key.replace('_', ' ')} {value}")
    return f"Hedge {op['title']}: " + (", ".join(parts) if parts else "done")


class Batch:
    """One run of an operation over several meshes, the one path of the batch API and of the
    operators (synchronous or on a worker thread): each mesh is read and run in turn, and
    nothing is written unless every run succeeded and every result can be written."""

    def __init__(self, op_id, target_list, params):
        self.op = operation(op_id)
        self.targets = target_list
        self.params = dict(params)
        self.index = 0
        last_params[op_id] = dict(params)

    def finished(self):
        return self.index >= len(self.targets)

    def read_next(self):
        """The soup of the next mesh to run, and the parameters for it: a vertex attribute
        named by a parameter may be a vertex group of that mesh."""
        t = self.targets[self.index]
        soup = t.read(self.op)
        params = dict(self.params)
        for p in self.op["params"]:
            if p["type"] == "vertex_channel" and p["id"] in params:
                channel = exchange.vertex_attribute_channel(t.data, params[p["id"]])
                if channel is None:
                    known = exchange.vertex_attribute_names(t.data.vertex_groups, t.data.attributes)
                    raise Error(f"{self.op['id']}: {p['id']}: {t.obj.name} has no vertex group or point attribute "
                                f"'{params[p['id']]}'" + (f"; it has: {', '.join(known)}" if known else ""))
                params[p["id"]] = channel
        return soup, params

    def read_rest(self):
        """The write-back data of the mesh read_next() read, while its operation runs."""
        self.targets[self.index].read_rest()

    def record(self, result, report):
        """Keeps the next mesh's result (from native.run or a Job)."""
        t = self.targets[self.index]
        t.result, t.report = result, report
        report["object"] = t.obj.name
        self.index += 1

    def commit(self):
        """Checks every result, then writes them all; returns the reports."""
        for t in self.targets:
            t.check_writable(self.op)
        for t in self.targets:
            t.write()
            remember(self.op, t.obj, t.report)
        return [t.report for t in self.targets]

    def release(self):
        for t in self.targets:
            t.release()


def run_targets(op_id, target_list, params, progress=None):
    """Runs one operation on several targets, synchronously; writes nothing unless every one
    succeeded. `progress(fraction, stage)` is called every PROGRESS_SECONDS; False cancels."""
    batch = Batch(op_id, target_list, params)
    native_module = require_native()
    n = len(target_list)
    try:
        while not batch.finished():
            job = native_module.Job(op_id, *batch.read_next())
            batch.read_rest()  # on this thread, while the job runs on its own
            while not job.wait(PROGRESS_SECONDS):
                fraction, stage = job.progress()
                if progress is not None and not progress((batch.index + fraction) / n, stage):
                    job.cancel()  # result() then raises Cancelled
            batch.record(*job.result())
        return batch.commit()
    except BaseException:
        batch.release()
        raise


def remember(op, obj, report):
    last_reports[op["id"]] = report
    if not op["changes_mesh"]:
        last_reports["report:" + obj.name] = report


def run(obj, op_id, progress=None, **params):
    """Runs operation `op_id` on a mesh object (its edit mesh in Edit Mode) with the given
    parameters (catalogue ids; others take their defaults) and returns the report dict.
    Raises hedge.Error with a message for people; the mesh is then unchanged."""
    return run_targets(op_id, [Target(obj)], params, progress)[0]


def import_file(path, name=None):
    """Reads a mesh file (OFF, OBJ, PLY, STL) with hedge's reader into a new object linked to
    the active collection, and returns the object."""
    import os
    soup = require_native().read_mesh(path)
    name = name or os.path.splitext(os.path.basename(path))[0]
    me = bpy.data.meshes.new(name)
    exchange.write_new(me, soup)
    obj = bpy.data.objects.new(name, me)
    bpy.context.collection.objects.link(obj)
    return obj
