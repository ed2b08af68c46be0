"""Identical results in both hosts: the same PLY through the same Hedge operation with the same
parameters in MeshLab (the runner of tests/meshlab: meshlabserver 2020.09, or hedge-mlx) and in
Blender (`blender -b`, the operator; blender_side.py) gives the same surface: the same vertex and
face counts, the same vertices as a multiset of float triples (bit for bit), and the same faces as
a multiset of position cycles (each turned to start at its smallest corner, orientation kept). The
inputs are written as binary float PLY first, so both hosts read the very floats the other does,
and Blender builds the mesh with from_pydata from the file's soup; "none" (no operation) checks
that the two hosts received the same soup.

  test_identical.py MESHLAB-RUNNER-ARGUMENTS --blender BLENDER --addon-zip Z --extension-zip Z
                    --hedge HEDGE --meshes DIR --out DIR
"""
import json
import os
import re
import subprocess
import sys
import time
from collections import Counter

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "meshlab"))
import mesh_files  # noqa: E402
import meshlab_test as mt  # noqa: E402
from meshlab_test import defects  # noqa: E402
import hostile_meshes  # noqa: E402  (on the path through meshlab_test)
import outcomes  # noqa: E402

# With the bunny (holes punched) and the non-manifold dragon_res4 (duplicate faces, 3 or more faces
# on edges): two small meshes made to have defects, one with a bow-tie border.
MADE = ("fin_and_duplicate", "holes_sharing_vertex")
OPERATIONS = [(None, {}), ("decimate", {"target_ratio": 0.25}), ("remesh", {"iterations": 3}), ("fill_holes", {})]


def as_binary_ply(source, target):
    """The mesh of `source` as binary float PLY (its values rounded to float once, here)."""
    vertices, faces = defects.read_mesh(source)
    hostile_meshes.write_ply(target, hostile_meshes.Case("input", "", vertices, faces))
    return target


def surface(path):
    """(vertex multiset, face multiset) of a mesh file: faces as position cycles turned to start
    at their smallest position, so vertex order and face order do not matter."""
    vertices, faces = defects.read_mesh(path)
    cycles = Counter()
    for f in faces:
        points = [vertices[i] for i in f]
        k = points.index(min(points))
        cycles[tuple(points[k:] + points[:k])] += 1
    return Counter(vertices), cycles, len(vertices), len(faces)


def compare(checks, label, meshlab_out, blender_out):
    """Checks the two results are the same surface; returns a table cell."""
    mv, mf, nmv, nmf = surface(meshlab_out)
    bv, bf, nbv, nbf = surface(blender_out)
    same_counts = checks.check((nmv, nmf) == (nbv, nbf),
                               f"{label}: vertices and faces MeshLab {nmv}, {nmf} / Blender {nbv}, {nbf}")
    only = {"vertices only in MeshLab's": mv - bv, "vertices only in Blender's": bv - mv,
            "faces only in MeshLab's": mf - bf, "faces only in Blender's": bf - mf}
    differing = {k: sum(v.values()) for k, v in only.items() if v}
    same_surface = checks.check(not differing, f"{label}: the same vertices and faces, bit for bit {differing or ''}")
    if not same_surface:
        for what, items in only.items():
            for item in list(items)[:3]:
                print(f"    e.g. {what}: {item}")
    if same_counts and same_surface:
        return f"same, {nmv} v {nmf} f"
    return f"DIFFER: MeshLab {nmv} v {nmf} f, Blender {nbv} v {nbf} f, {differing}"


def run_blender(args, jobs):
    """All jobs in one Blender with a private HOME and TMPDIR; returns (exit code, output, seconds)."""
    home = os.path.join(args.out, "blender_home")
    tmp = os.path.join(args.out, "blender_tmp")
    os.makedirs(home, exist_ok=True)
    os.makedirs(tmp, exist_ok=True)
    jobs_file = os.path.join(args.out, "blender_jobs.json")
    with open(jobs_file, "w") as f:
        json.dump(jobs, f, indent=1)
    # A Blender embedding the system's Python finds its prefix through the first python3 on PATH;
    # a pyenv or venv interpreter running this script puts its own folder first, and that Blender
    # then misses the system's numpy.
    own = os.path.dirname(sys.executable)
    path = [p for p in os.environ.get("PATH", "").split(os.pathsep) if p != own or own in ("/usr/bin", "/bin")]
    env = dict(os.environ, HOME=home, TMPDIR=tmp, PYTHONDONTWRITEBYTECODE="1", PATH=os.pathsep.join(path))
    command = [args.blender, "-b", "--factory-startup", "--python-exit-code", "1", "--python-use-system-env",
               "--python", os.path.join(HERE, "blender_side.py"), "--", "--addon-zip", args.addon_zip,
               "--extension-zip", args.extension_zip, "--meshes", args.meshes, "--out", args.out, "--jobs", jobs_file]
    start = time.monotonic()
    done = subprocess.run(command, env=env, capture_output=True, text=True, errors="replace", timeout=1200)
    output = done.stdout + done.stderr
    with open(os.path.join(args.out, "blender.log"), "w") as f:
        f.write(output)
    return done.returncode, output, time.monotonic() - start


def main():
    args = mt.parse_args({"--blender": {"required": True, "help": "the Blender to compare with"},
                          "--addon-zip": {"required": True, "help": "build/hedge_blender_addon.zip (Blender < 4.2)"},
                          "--extension-zip": {"default": "", "help": "build/hedge_blender_extension.zip (4.2+)"}})
    checks = outcomes.Checks(quiet_passes=False)
    ml = mt.MeshLab(args)
    try:
        # The bunny is closed: holes for fill_holes to fill.
        holed = ml.path("bunny_holes.off")
        mesh_files.punch_holes(ml.mesh("bunny.off"), holed, 6)
        inputs = {"bunny_holes": as_binary_ply(holed, ml.path("bunny_holes.input.ply")),
                  "dragon_res4": as_binary_ply(ml.mesh("dragon_res4.ply"), ml.path("dragon_res4.input.ply"))}
        for case in defects.cases():
            if case.name in MADE:
                inputs[case.name] = ml.path(case.name + ".input.ply")
                hostile_meshes.write_ply(inputs[case.name], case)
        jobs, meshlab_outs = [], {}
        for stem, path in inputs.items():
            for op, params in OPERATIONS:
                name = f"{stem}.{op or 'none'}"
                meshlab_out = ml.path(name + ".meshlab.ply")
                if op:
                    code, output, seconds = ml.apply(path, meshlab_out, [mt.hedge_filter(ml, op, **params)], name)
                else:
                    code, output, seconds = ml.convert(path, meshlab_out)
                if checks.check(code == 0 and os.path.exists(meshlab_out),
                                f"{name}: MeshLab {ml.version} exits 0 and saves (exit {code}, {seconds:.1f} s)"):
                    meshlab_outs[name] = meshlab_out
                else:
                    print(output[-2000:])
                jobs.append({"input": path, "op": op, "params": params, "output": ml.path(name + ".blender.ply")})
        code, output, seconds = run_blender(args, jobs)
        if not checks.check(code == 0, f"Blender runs all {len(jobs)} jobs (exit {code}, {seconds:.1f} s)"):
            print(output[-3000:])
        found = re.search(r"^Blender (\S+)", output, re.M)
        hosts = f"MeshLab {ml.version} / Blender {found.group(1) if found else '?'}"
        table = outcomes.Table(list(inputs), [op or "none" for op, _ in OPERATIONS])
        for job in jobs:
            name = os.path.basename(job["output"]).removesuffix(".blender.ply")
            stem, op = name.rsplit(".", 1)
            if name in meshlab_outs and os.path.exists(job["output"]):
                table.set(stem, op, compare(checks, f"{name} ({hosts})", meshlab_outs[name], job["output"]))
            else:
                table.set(stem, op, "not run")
        mt.write_table(ml, table, "identical_table.md")
    finally:
        ml.close()
    checks.finish()


if __name__ == "__main__":
    main()
