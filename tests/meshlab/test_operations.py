"""Every catalogue operation as a Hedge filter in a meshlabserver .mlx script, on real meshes,
with the result read back from the saved file (hedge info/report) and from MeshLab's log, and no
more defects in it than in the input (tests/hostile/defects.py); and a script chaining three
Hedge filters with MeshLab's own filters."""
import filecmp
import os

import mesh_files
import meshlab_test as mt


def run(ml, checks, name, mesh_in, filters, save_flags=None):
    out = ml.path(name + ".ply")
    code, output, seconds = ml.apply(mesh_in, out, filters, name, save_flags)
    ok = checks.check(code == 0, f"{name}: {ml.runner} exits 0 (got {code}, {seconds:.1f} s)")
    ok = checks.check(mesh_files.nonempty(out), f"{name}: wrote {out}") and ok
    if not ok:
        print(output[-2000:])
    elif ml.runner == "hedge-mlx":
        check_returned(ml, checks, name, output, filters)
    if ok and all(f.startswith("Hedge: ") for f, _ in filters):  # MeshLab's own filters promise nothing
        mt.check_defects(checks, f"{name} on {os.path.basename(mesh_in)}", mesh_in, out, mt.subdivision_steps(ml, filters))
    return out if ok else None, output


def same_value(text, value):
    if isinstance(value, bool):
        return text == str(value).lower()
    if isinstance(value, (int, float)):
        try:
            return abs(float(text) - value) <= 1e-12 * max(1.0, abs(value))
        except ValueError:
            return False
    return text == str(value)


def check_returned(ml, checks, name, output, filters):
    """2021.05+: what each Hedge filter's applyFilter returned (pymeshlab's return value, printed by
    hedge-mlx) is its report, entry for entry what it logged."""
    for filter_name in dict.fromkeys(f for f, _ in filters if f.startswith("Hedge: ")):
        returned = mt.result_of(output, filter_name)
        logged = mt.logged(output, filter_name)
        if not checks.check(returned is not None and "seconds" in returned,
                            f"{name}: {filter_name} returns its report ({sorted(returned or {})[:4]}...)"):
            continue
        differing = {k: (v, returned.get(k)) for k, v in logged.items() if not same_value(v, returned.get(k))}
        checks.check(not differing and set(logged) <= set(returned),
                     f"{name}: {filter_name}'s returned map is its logged report ({len(logged)} entries) {differing or ''}")


def close(a, b, tolerance):
    return abs(a - b) <= tolerance * max(abs(a), abs(b), 1e-12)


def test_report(ml, checks, bunny):
    _, output = run(ml, checks, "report", bunny, [mt.hedge_filter(ml, "report")])
    logged = mt.logged(output, "Hedge: Mesh Report")
    expected = ml.report(bunny)
    for key in ("vertices", "faces", "edges", "boundary_loops", "components", "genus"):
        checks.check(logged.get(key) == str(expected[key]), f"report: logs {key} = {expected[key]} (got {logged.get(key)})")
    checks.check(close(float(logged.get("area", "nan")), expected["area"], 1e-5), "report: logs the area")


def test_decimate(ml, checks, bunny, dragon):
    out, output = run(ml, checks, "decimate_ratio", bunny, [mt.hedge_filter(ml, "decimate", target_ratio=0.1)])
    if out:
        faces = ml.info(out)["faces"]
        checks.check(abs(faces - 367) <= 1, f"decimate: bunny 3674 -> 10 % = {faces} faces")
        checks.check(mt.logged(output, "Hedge: Decimate").get("faces_after") == str(faces), "decimate: log agrees with the file")
    out, output = run(ml, checks, "decimate_faces", dragon, [mt.hedge_filter(ml, "decimate", target_faces=20000)])
    if out:
        # Counted in the file: a non-manifold input's copies are welded back on the way out.
        faces = mesh_files.ply_count(out, "face")
        checks.check(faces is not None and abs(faces - 20000) <= 1, f"decimate: non-manifold dragon to 20000 faces = {faces}")


def test_subdivide(ml, checks, bunny):
    n = 3674
    out, _ = run(ml, checks, "subdivide_loop", bunny, [mt.hedge_filter(ml, "subdivide", scheme="loop", iterations=1)])
    if out:
        checks.check(ml.info(out)["faces"] == 4 * n, f"subdivide loop: {n} -> {4 * n} faces")
    out, output = run(ml, checks, "subdivide_catmull_clark", bunny,
                      [mt.hedge_filter(ml, "subdivide", scheme="catmull_clark")])
    if out:
        # 3n quads, each held by MeshLab as two triangles joined by a faux edge.
        checks.check(ml.info(out)["faces"] == 6 * n, f"subdivide catmull_clark: {3 * n} quads as {6 * n} triangles")
        checks.check(f"{3 * n} polygons stored as triangle fans" in output, "subdivide catmull_clark: logs the quads")


def test_smooth(ml, checks, bunny):
    before = ml.report(bunny)
    out, _ = run(ml, checks, "smooth", bunny, [mt.hedge_filter(ml, "smooth", method="uniform", iterations=20)])
    if out:
        after = ml.report(out)
        checks.check(after["faces"] == before["faces"] and after["vertices"] == before["vertices"],
                     "smooth: same vertices and faces")
        checks.check(after["area"] < 0.98 * before["area"], f"smooth: uniform smoothing shrinks the area "
                                                            f"{before['area']:.2f} -> {after['area']:.2f}")
    out, _ = run(ml, checks, "smooth_taubin", bunny, [mt.hedge_filter(ml, "smooth", method="taubin", iterations=20)])
    if out:
        after = ml.report(out)
        checks.check(close(after["volume"], before["volume"], 0.03),
                     f"smooth taubin: volume kept {before['volume']:.2f} -> {after['volume']:.2f}")


def test_remesh(ml, checks, bunny):
    target = 0.5
    out, _ = run(ml, checks, "remesh", bunny, [mt.hedge_filter(ml, "remesh", target_edge_length=target, iterations=5)])
    if out:
        stats = ml.report(out)
        checks.check(close(stats["edge_length_mean"], target, 0.15),
                     f"remesh: mean edge length {stats['edge_length_mean']:.3f} near {target}")
        checks.check(stats["edge_length_stddev"] < 0.25 * target, f"remesh: edge length spread {stats['edge_length_stddev']:.3f}")
        checks.check(stats["boundary_loops"] == 0 and stats["components"] == 1, "remesh: still one closed surface")


def test_fill_holes(ml, checks, bunny):
    holed = ml.path("bunny_holes.off")
    holes = mesh_files.punch_holes(bunny, holed, 6)
    checks.check(ml.info(holed)["boundary_loops"] == holes, f"fill_holes: input has {holes} holes")
    out, output = run(ml, checks, "fill_holes", holed, [mt.hedge_filter(ml, "fill_holes")])
    if out:
        info = ml.info(out)
        checks.check(info["boundary_loops"] == 0, f"fill_holes: no hole left ({info['boundary_loops']})")
        checks.check(info["faces"] > ml.info(holed)["faces"], "fill_holes: faces added")
    out, _ = run(ml, checks, "fill_holes_limited", holed, [mt.hedge_filter(ml, "fill_holes", max_hole_edges=3)])
    if out:
        checks.check(ml.info(out)["boundary_loops"] == holes, "fill_holes: holes above max_hole_edges stay open")


def test_repair(ml, checks, non_manifold):
    before = ml.info(non_manifold)["repairs"]
    checks.check(before["non_manifold_edges"] > 0, f"repair: input has {before['non_manifold_edges']} non-manifold edges")
    out, _ = run(ml, checks, "repair", non_manifold, [mt.hedge_filter(ml, "repair")])
    if out:
        after = ml.info(out)["repairs"]
        checks.check(after["non_manifold_edges"] == 0 and after["non_manifold_vertices"] == 0 and after["flipped_faces"] == 0,
                     f"repair: the saved mesh builds without repairs ({after})")


def test_make_delaunay(ml, checks, bunny):
    before = ml.report(bunny)
    out, output = run(ml, checks, "make_delaunay", bunny, [mt.hedge_filter(ml, "make_delaunay")])
    if out:
        after = ml.report(out)
        checks.check(after["faces"] == before["faces"] and after["vertices"] == before["vertices"],
                     "make_delaunay: same vertices and faces")
        checks.check(after["mean_min_angle_degrees"] >= before["mean_min_angle_degrees"] - 1e-6,
                     f"make_delaunay: mean smallest angle {before['mean_min_angle_degrees']:.2f} -> "
                     f"{after['mean_min_angle_degrees']:.2f}")


def test_polygons(ml, checks):
    """MeshLab holds a quad mesh as triangles joined by faux edges; Hedge filters see the quads
    and give polygons back the same way, so Catmull-Clark twice in a row stays all quads."""
    cube = ml.path("quad_cube.off")
    quads = mesh_files.write_quad_cube(cube, 4)
    _, output = run(ml, checks, "polygons_report", cube, [mt.hedge_filter(ml, "report")])
    checks.check(mt.logged(output, "Hedge: Mesh Report").get("quads") == str(quads),
                 f"polygons: Hedge sees MeshLab's {quads} faux-edge quads as quads")
    twice = [mt.hedge_filter(ml, "subdivide", scheme="catmull_clark"), mt.hedge_filter(ml, "subdivide", scheme="catmull_clark"),
             mt.hedge_filter(ml, "report")]
    out, output = run(ml, checks, "polygons_catmull_clark_twice", cube, twice)
    if out:
        checks.check(mt.logged(output, "Hedge: Mesh Report").get("quads") == str(16 * quads),
                     f"polygons: Catmull-Clark twice makes {16 * quads} quads")
        checks.check(mesh_files.ply_count(out, "face") == 32 * quads, f"polygons: saved as {32 * quads} triangles")
    if "triangulate" in ml.operations:
        out, output = run(ml, checks, "polygons_triangulate", cube, [mt.hedge_filter(ml, "triangulate"), mt.hedge_filter(ml, "report")])
        if out:
            checks.check(mt.logged(output, "Hedge: Mesh Report").get("triangles") == str(2 * quads),
                         f"polygons: Triangulate turns the {quads} quads into {2 * quads} triangles")


def test_any(ml, checks, op, bunny):
    """An operation this test has no specific check for yet: it runs with its defaults and
    gives a mesh back."""
    out, output = run(ml, checks, op["id"], bunny, [mt.hedge_filter(ml, op["id"])])
    if out:
        checks.check(ml.info(out)["faces"] > 0, f"{op['id']}: a mesh with faces came back")
    checks.check(f"{op['filter']}: seconds = " in output, f"{op['id']}: its report is in MeshLab's log")


def test_chain(ml, checks, bunny):
    """Three Hedge filters and three of MeshLab's own in one script."""
    holed = ml.path("bunny_holes_chain.off")
    mesh_files.punch_holes(bunny, holed, 4)
    filters = [
        mt.hedge_filter(ml, "remesh", target_edge_length=0.3, iterations=3),
        mt.meshlab_filter("Remove Duplicate Vertices"),
        mt.quadric_edge_collapse(5000),
        mt.hedge_filter(ml, "fill_holes"),
        mt.meshlab_filter("Invert Faces Orientation", ("RichBool", "forceFlip", True), ("RichBool", "onlySelected", False)),
        mt.hedge_filter(ml, "smooth", method="taubin", iterations=5),
        mt.meshlab_filter("Remove Unreferenced Vertices"),
    ]
    out, output = run(ml, checks, "chain", holed, filters)
    if not out:
        return
    remeshed = int(mt.logged(output, "Hedge: Isotropic Remesh").get("faces", "0"))
    checks.check(remeshed > 5000, f"chain: remesh refined the holed bunny ({remeshed} faces)")
    fill = mt.logged(output, "Hedge: Fill Holes")
    checks.check(fill.get("holes_filled") == fill.get("holes_found") and int(fill.get("holes_found", "0")) >= 4,
                 f"chain: Fill Holes filled every hole left by MeshLab's decimation ({fill.get('holes_filled')})")
    info = ml.info(out)
    checks.check(info["boundary_loops"] == 0, "chain: no hole in the saved mesh")
    added = int(fill.get("triangles_added", "0"))
    checks.check(abs(info["faces"] - added - 5000) <= 2,  # MeshLab's collapses stop within a face or two of the target
                 f"chain: Quadric Edge Collapse's ~5000 faces plus {added} filled = {info['faces']}")
    checks.check(info["components"] == 1, "chain: one component")
    # The smoothing ran on the flipped mesh; Hedge gives the orientation it was handed back.
    checks.check(ml.report(out)["volume"] < 0, "chain: MeshLab's Invert Faces survived the Hedge filter after it")
    checks.check("Hedge: Smooth: seconds = " in output, "chain: the last Hedge filter ran")


def test_defaults(ml, checks, bunny):
    """2021.05+: parameters a script leaves out take the filter's defaults."""
    out, _ = run(ml, checks, "defaults_decimate", bunny, [mt.hedge_filter_given(ml, "decimate", target_ratio=0.1)])
    if out:
        faces = ml.info(out)["faces"]
        checks.check(abs(faces - 367) <= 1, f"defaults: Decimate given only target_ratio=0.1 gives {faces} faces")
    full, _ = run(ml, checks, "defaults_smooth_full", bunny, [mt.hedge_filter(ml, "smooth")])
    bare, _ = run(ml, checks, "defaults_smooth_bare", bunny, [mt.hedge_filter_given(ml, "smooth")])
    if full and bare:
        checks.check(filecmp.cmp(full, bare, shallow=False),
                     "defaults: Smooth with no parameter saves the same file as with every default written out")


def main():
    args = mt.parse_args()
    checks = mt.Checks()
    ml = mt.MeshLab(args)
    bunny, dragon = ml.mesh("bunny.off"), ml.mesh("dragon_res2.ply")
    specific = {
        "report": lambda: test_report(ml, checks, bunny),
        "decimate": lambda: test_decimate(ml, checks, bunny, dragon),
        "subdivide": lambda: test_subdivide(ml, checks, bunny),
        "smooth": lambda: test_smooth(ml, checks, bunny),
        "remesh": lambda: test_remesh(ml, checks, bunny),
        "fill_holes": lambda: test_fill_holes(ml, checks, bunny),
        "repair": lambda: test_repair(ml, checks, ml.mesh("dragon_res4.ply")),
        "make_delaunay": lambda: test_make_delaunay(ml, checks, bunny),
    }
    try:
        for op in ml.catalogue["operations"]:
            print(f"== {op['filter']}")
            try:
                specific.get(op["id"], lambda: test_any(ml, checks, op, bunny))()
            except mt.Failure as e:
                checks.check(False, f"{op['id']}: {e}")
        print("== polygons")
        if "subdivide" in ml.operations:
            test_polygons(ml, checks)
        if ml.runner == "hedge-mlx":
            print("== defaults")
            test_defaults(ml, checks, bunny)
        print("== chain")
        if all(op in ml.operations for op in ("remesh", "fill_holes", "smooth")):
            test_chain(ml, checks, bunny)
    finally:
        ml.close()
    checks.finish()


if __name__ == "__main__":
    main()
