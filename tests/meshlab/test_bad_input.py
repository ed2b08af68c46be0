"""Bad input through the runner (meshlabserver, hedge-mlx): non-manifold meshes (a real scan with
non-manifold edges and vertices, and a small mesh made of every kind of trouble) go through every
Hedge filter without a crash; parameter values out of range are refused with the catalogue's
message (the CLI's), in MeshLab's log, with the runner's failure exit (255, 1) and no output
written. hedge-mlx also refuses, with a clear message and its own exit code, an unknown filter or
parameter, a value of the wrong type, a script that is not one, an input it cannot load and an
output it cannot save."""
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
    if p["type"] == "vertex_channel":
        return "no_such_attribute"
    if p["max"] is not None and p["max"] < 2147483647:
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
                crashed = code not in (0, ml.filter_failed)
                checks.check(not crashed, f"{name}: no crash (exit {code} {CRASHES.get(code, '')})")
                if code == 0:
                    checks.check(mesh_files.nonempty(out), f"{name}: result saved")
                elif code == ml.filter_failed:
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
                checks.check(code == ml.filter_failed and not os.path.exists(out),
                             f"{name}={value}: refused, exit {code}, nothing saved")
                if p["type"] != "enum":
                    flag = "--" + p["id"].replace("_", "-")
                    cli = subprocess.run([args.hedge, op["id"], bunny, ml.path("cli.ply"), flag, mt_text(value)],
                                         capture_output=True, text=True).stderr.strip()
                    message = cli.removeprefix("hedge: ")
                    if p["type"] == "vertex_channel":
                        # The attributes the message lists are those each reader carries.
                        message = message.split(" (it has")[0].split("; its vertex")[0]
                    checks.check(message and f"{op['filter']} failed: {message}" in output,
                                 f"{name}: the log says what the CLI says: {message!r}")
                else:
                    checks.check(f"parameter {p['id']} must be one of" in output, f"{name}: the log names the choices")
        if ml.runner == "hedge-mlx":
            runner_refusals(ml, checks, bunny)
    finally:
        ml.close()
    checks.finish()


USAGE, IO = 2, 3  # hedge-mlx's exit codes


def runner_refusals(ml, checks, bunny):
    """What hedge-mlx refuses before or around the filters, each with a message naming the cause."""
    decimate = ml.operations["decimate"]
    cases = [
        ("unknown_filter", bunny, [("Hedge: Decimater", [])], USAGE, "no filter named 'Hedge: Decimater' is loaded"),
        ("unknown_parameter", bunny, [(decimate["filter"], [{"name": "target_ration", "type": "RichFloat",
                                                             "value": "0.1", "description": "", "tooltip": ""}])],
         USAGE, "has no parameter 'target_ration'"),
        ("wrong_type", bunny, [(decimate["filter"], [{"name": "target_faces", "type": "RichFloat", "value": "100",
                                                      "description": "", "tooltip": ""}])],
         USAGE, "parameter 'target_faces' holds a"),
        ("missing_input", ml.path("no_such_mesh.ply"), [mt.hedge_filter(ml, "report")], IO, "cannot load"),
    ]
    garbage = ml.path("garbage.ply")
    with open(garbage, "wb") as f:
        f.write(b"ply\nformat binary_little_endian 1.0\nelement vertex 99999999\nend_header\n\x01\x02")
    cases.append(("garbage_input", garbage, [mt.hedge_filter(ml, "report")], IO, "cannot load " + garbage))
    for name, mesh_in, filters, expected, phrase in cases:
        out = ml.path(name + ".ply")
        code, output, _ = ml.apply(mesh_in, out, filters, name)
        checks.check(code == expected and phrase in output and not os.path.exists(out),
                     f"{name}: exit {expected} with '{phrase}' (exit {code}: {output.strip().splitlines()[-1:]})")
    # Saving where it cannot: an unknown format, a folder that does not exist.
    for name, out, phrase in (("save_unknown_format", ml.path("out.nosuchformat"), "cannot save"),
                              ("save_no_folder", ml.path("no/such/folder/out.ply"), "cannot save")):
        code, output, _ = ml.apply(bunny, out, [mt.hedge_filter(ml, "report")], name)
        checks.check(code == IO and phrase in output and not os.path.exists(out),
                     f"{name}: exit {IO} with '{phrase}' (exit {code}: {output.strip().splitlines()[-1:]})")
    script = ml.path("not_a_script.mlx")
    with open(script, "w") as f:
        f.write("this is not XML\n")
    code, output, _ = ml.run_server([bunny, "-", script])
    checks.check(code == USAGE and "is not a MeshLab filter script" in output, f"not_a_script: exit {USAGE} ({code})")


def mt_text(value):
    """The value as the CLI and hedge's messages write it (-1, 1.5, a name as it is)."""
    if isinstance(value, str):
        return value
    text = repr(value)
    return text[:-2] if text.endswith(".0") else text


if __name__ == "__main__":
    main()
