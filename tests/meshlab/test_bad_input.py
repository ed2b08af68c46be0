"""Bad input through meshlabserver: non-manifold meshes (a real scan with non-manifold edges
and vertices, and a small mesh made of every kind of trouble) go through every Hedge filter
without a crash; parameter values out of range are refused with the catalogue's message (the
CLI's), in MeshLab's log, with exit 255 and no output written."""
import os
import subprocess

import mesh_files
import meshlab_test as mt

CRASHES = {134: "abort", 139: "segmentation fault", -6: "abort", -11: "segmentation fault"}


def troubled_mesh(path):
    """A fin (three triangles on one edge), two tetrahedra touching at one vertex, a face
    flipped against its neighbours, an isolated vertex and a duplicate face."""
    vertices = [(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1),  # tetrahedron A: 0..3
                (-1, 0, 0), (0, -1, 0), (0, 0, -1),  # tetrahedron B shares vertex 0
                (3, 0, 0), (4, 0, 0), (3.5, 1, 0), (3.5, -1, 0), (3.5, 0, 1),  # fin on edge 7-8
                (6, 0, 0), (7, 0, 0), (6, 1, 0), (7, 1, 0),  # two triangles, one flipped
                (9, 9, 9)]  # isolated
    faces = [(0, 2, 1), (0, 1, 3), (0, 3, 2), (1, 2, 3),
             (0, 4, 5), (0, 6, 4), (0, 5, 6), (4, 6, 5),
             (7, 8, 9), (8, 7, 10), (7, 8, 11),
             (12, 13, 14), (13, 14, 15),
             (1, 2, 3)]
    mesh_files.write_off(path, vertices, faces)


def out_of_range(p):
    """A value outside the parameter's range, or None when every value of its type is allowed."""
    if p["type"] == "enum":
        return len(p["choices"]) + 3
    if p["type"] == "bool":
        return None
    if p["max"] < 2147483647 and p["max"] < 1e29:
        return p["max"] + (1 if p["type"] == "int" else 0.5)
    if p["min"] > -2147483648:
        return p["min"] - 1
    return None


def main():
    args = mt.parse_args()
    checks = mt.Checks()
    ml = mt.MeshLab(args)
    try:
        troubled = ml.path("troubled.off")
        troubled_mesh(troubled)
        for source in (ml.mesh("dragon_res4.ply"), troubled):
            repairs = ml.info(source)["repairs"]
            checks.check(repairs["non_manifold_edges"] > 0 and repairs["non_manifold_vertices"] > 0,
                         f"{os.path.basename(source)} is non-manifold ({repairs})")
            for op in ml.catalogue["operations"]:
                name = f"{os.path.basename(source).split('.')[0]}_{op['id']}"
                out = ml.path(name + ".ply")
                code, output, _ = ml.apply(source, out, [mt.hedge_filter(ml, op["id"])], name)
                crashed = code not in (0, 255)
                checks.check(not crashed, f"{name}: no crash (exit {code} {CRASHES.get(code, '')})")
                if code == 0:
                    checks.check(mesh_files.nonempty(out), f"{name}: result saved")
                elif code == 255:
                    checks.check(f"{op['filter']} failed: " in output and not os.path.exists(out),
                                 f"{name}: refused with a message in the log, nothing saved")
                if crashed:
                    print(output[-2000:])

        bunny = ml.mesh("bunny.off")
        for op in ml.catalogue["operations"]:
            for p in op["params"]:
                value = out_of_range(p)
                if value is None:
                    continue
                name = f"range_{op['id']}_{p['id']}"
                out = ml.path(name + ".ply")
                if p["type"] == "enum":
                    params = mt.hedge_filter(ml, op["id"])
                    for attributes in params[1]:
                        if attributes["name"] == p["id"]:
                            attributes["value"] = str(value)
                    filters = [params]
                else:
                    filters = [mt.hedge_filter(ml, op["id"], **{p["id"]: value})]
                code, output, _ = ml.apply(bunny, out, filters, name)
                checks.check(code == 255 and not os.path.exists(out), f"{name}={value}: refused, exit 255, nothing saved")
                if p["type"] != "enum":
                    flag = "--" + p["id"].replace("_", "-")
                    cli = subprocess.run([args.hedge, op["id"], bunny, ml.path("cli.ply"), flag, mt_text(value)],
                                         capture_output=True, text=True).stderr.strip()
                    message = cli.removeprefix("hedge: ")
                    checks.check(message and f"{op['filter']} failed: {message}" in output,
                                 f"{name}: the log says what the CLI says: {message!r}")
                else:
                    checks.check(f"parameter {p['id']} must be one of" in output, f"{name}: the log names the choices")
    finally:
        ml.close()
    checks.finish()


def mt_text(value):
    """The value as the CLI and hedge's messages write it (-1, 1.5)."""
    text = repr(value)
    return text[:-2] if text.endswith(".0") else text


if __name__ == "__main__":
    main()
