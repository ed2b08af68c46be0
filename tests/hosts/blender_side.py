# The Blender half of test_identical.py, run as `blender -b --factory-startup --python-exit-code 1
# --python blender_side.py -- --addon-zip Z --extension-zip Z --jobs JOBS.json`: for each job
# {"input", "op" (null: none), "params", "output"} the input PLY built with from_pydata (the soup
# exactly as the file holds it: Blender's importers may merge or validate), the operation run by its
# operator with the job's parameters, and the mesh written as binary PLY by hand (Blender's
# exporters split vertices by normals and UVs).
import json
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "blender"))
sys.path.insert(0, os.path.join(HERE, "..", "hostile"))
import bpy  # noqa: E402
from blender_test import ARGS, clear_scene, faces_of, get, install_addon, object_from_pydata  # noqa: E402
import defects  # noqa: E402
import hostile_meshes  # noqa: E402

install_addon()


def main():
    jobs_file = ARGS.rest[ARGS.rest.index("--jobs") + 1]
    with open(jobs_file) as f:
        jobs = json.load(f)
    for job in jobs:
        clear_scene()
        vertices, faces = defects.read_mesh(job["input"])
        obj = object_from_pydata("input", vertices, faces)
        if job["op"]:
            result = getattr(bpy.ops.mesh, f"hedge_{job['op']}")(**job["params"])
            if result != {'FINISHED'}:
                raise RuntimeError(f"{job['op']} on {job['input']}: {result}")
        me = obj.data
        co = get(me.vertices, "co", len(me.vertices), "float32", 3).reshape(-1, 3).tolist()
        case = hostile_meshes.Case("result", "", co, faces_of(me))
        hostile_meshes.write_ply(job["output"], case)
        print(f"blender_side: {job['output']}: {len(co)} vertices, {len(case.faces)} faces", flush=True)


main()
