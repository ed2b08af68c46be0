"""No Hedge filter leaves the mesh worse than it found it: every filter that changes the mesh, with
its defaults, on real meshes (the bunny, the non-manifold dragon_res4 and dragon_res3) and on the
small meshes made to have defects (tests/hostile/defects.py: bow-tie vertices and borders, 3 and 6
faces on an edge, duplicate faces). The saved result has no more non-manifold edges, non-manifold
vertices, duplicate faces or faces repeating a vertex than the input file, category by category,
counted by defects.py (not by hedge). MeshLab's reader is checked first by a load and save with
no filter, so what it does is not counted against a filter. Prints the counts as a Markdown
table."""
import concurrent.futures
import os

import mesh_files
import meshlab_test as mt
from meshlab_test import defects
import hostile_meshes  # noqa: E402  (on the path through meshlab_test)
import outcomes  # noqa: E402

REAL = ("bunny.off", "dragon_res4.ply", "dragon_res3.ply")
TIMEOUT = 300


def main():
    args = mt.parse_args()
    checks = outcomes.Checks()
    ml = mt.MeshLab(args)
    try:
        meshes = [ml.mesh(name) for name in REAL]
        folder = ml.path("cases")
        os.makedirs(folder)
        meshes += [hostile_meshes.write(case, folder) for case in defects.cases()]
        ops = [op for op in ml.catalogue["operations"] if op["changes_mesh"]]
        names = [os.path.basename(m) for m in meshes]
        table = outcomes.Table(names, ["input", "no filter"] + [op["id"] for op in ops])

        def one(mesh, op):
            stem = os.path.splitext(os.path.basename(mesh))[0]
            name = f"{stem}.{op['id'] if op else 'no_filter'}"
            out = ml.path(name + ".ply")
            if op is None:
                code, output, seconds = ml.convert(mesh, out, timeout=TIMEOUT)
            else:
                code, output, seconds = ml.apply(mesh, out, [mt.hedge_filter(ml, op["id"])], name,
                                                         timeout=TIMEOUT)
            return mesh, op, out, code, output, seconds

        with concurrent.futures.ThreadPoolExecutor(2) as pool:
            futures = [pool.submit(one, mesh, op) for mesh in meshes for op in [None] + ops]
            for future in futures:
                mesh, op, out, code, output, seconds = future.result()
                name = os.path.basename(mesh)
                column = op["id"] if op else "no filter"
                label = f"{op['id'] if op else 'no filter (MeshLab load and save)'} on {name}"
                table.set(name, "input", defects.cell(mt.count_defects(mesh)))
                if not checks.check(code == 0 and mesh_files.nonempty(out),
                                    f"{label}: {ml.runner} exits 0 and saves (exit {code}, {seconds:.1f} s)"):
                    print(output[-2000:])
                    table.set(name, column, f"exit {code}")
                    continue
                steps = int(op is not None and op["id"] == "subdivide")  # its default: one step
                before, after = mt.check_defects(checks, label, mesh, out, steps)
                worse = defects.increases(before, after, steps)
                table.set(name, column, defects.cell(after) + (" WORSE" if worse else ""))
        print(f"\n{defects.CELL_KEY}\n")
        mt.write_table(ml, table, "defects_table.md")
    finally:
        ml.close()
    checks.finish()


if __name__ == "__main__":
    main()
