"""A no-op Hedge filter leaves a mesh with UVs, vertex colours, face colours and qualities bit
for bit: the file MeshLab saves after `Hedge: Mesh Report` or `Hedge: Repair` (which rebuilds
the mesh through the Soup) is byte-identical to the one it saves with no filter at all.
Operations that change the mesh keep every attribute channel. With hedge-mlx (2021.05+), a
filter that fails (a refused value) leaves the document as it was: run with --keep-going, the
saved file is byte-identical to the reference."""
import filecmp

import mesh_files
import meshlab_test as mt

SAVE = ["vc", "vq", "vn", "fc", "fq", "wt"]
CARRIED = ["property uchar red", "property float quality", "property list uchar float texcoord"]


def main():
    args = mt.parse_args()
    checks = mt.Checks()
    ml = mt.MeshLab(args)
    try:
        for source in ("bunny.off", "dragon.ply"):
            stem = source.split(".")[0]
            attributed = ml.path(stem + "_attributes.ply")
            if source.endswith(".off"):
                mesh_files.write_attributed_ply(ml.mesh(source), attributed)
            else:  # the full Stanford dragon as it is (clean: Repair has nothing to do)
                attributed = ml.mesh(source)
            reference = ml.path(stem + "_reference.ply")
            code, output, _ = ml.convert(attributed, reference, SAVE)
            if not checks.check(code == 0 and mesh_files.nonempty(reference), f"{stem}: MeshLab saves it unchanged"):
                print(output[-2000:])
                continue
            header = mesh_files.ply_header(reference)
            if source.endswith(".off"):
                checks.check(all(any(line.startswith(p) for line in header) for p in CARRIED),
                             f"{stem}: the reference holds colours, qualities and wedge UVs")
            # No-ops: the report (writes nothing back), Repair on a clean mesh, and Decimate to 100 %
            # (both rebuild the mesh through the Soup). The dragon has zero-area faces Repair removes.
            no_ops = [("report", {}), ("decimate", {"target_ratio": 1.0})]
            if stem == "bunny":
                no_ops.append(("repair", {}))
            for op_id, values in no_ops:
                out = ml.path(f"{stem}_{op_id}.ply")
                code, output, _ = ml.apply(attributed, out, [mt.hedge_filter(ml, op_id, **values)], f"{stem}_{op_id}", SAVE)
                checks.check(code == 0 and mesh_files.nonempty(out), f"{stem}: Hedge {op_id} runs ({code})")
                same = mesh_files.nonempty(out) and filecmp.cmp(reference, out, shallow=False)
                checks.check(same, f"{stem}: after Hedge {op_id} the saved file is byte-identical to the reference")
            if ml.runner == "hedge-mlx":
                # A refused value: MLException thrown, the document untouched, the rest of the script runs.
                out = ml.path(f"{stem}_failed.ply")
                failing = [mt.hedge_filter(ml, "decimate", target_ratio=1.5), mt.hedge_filter(ml, "report")]
                code, output, _ = ml.apply(attributed, out, failing, f"{stem}_failed", SAVE, extra=["--keep-going"])
                checks.check(code == ml.filter_failed and "Hedge: Decimate failed: " in output,
                             f"{stem}: a refused Decimate fails (exit {code})")
                same = mesh_files.nonempty(out) and filecmp.cmp(reference, out, shallow=False)
                checks.check(same, f"{stem}: after the failed Decimate the saved file is byte-identical to the reference")

        # Changing operations carry every channel (colours, qualities, UVs) through.
        attributed = ml.path("bunny_attributes.ply")
        for op_id, values in (("decimate", {"target_ratio": 0.5}), ("subdivide", {}), ("remesh", {"iterations": 2}),
                              ("smooth", {}), ("fill_holes", {})):
            if op_id not in ml.operations:
                continue
            out = ml.path(f"bunny_{op_id}.ply")
            code, output, _ = ml.apply(attributed, out, [mt.hedge_filter(ml, op_id, **values)], f"bunny_{op_id}", SAVE)
            if not checks.check(code == 0 and mesh_files.nonempty(out), f"bunny {op_id}: runs"):
                continue
            header = mesh_files.ply_header(out)
            missing = [p for p in CARRIED if not any(line.startswith(p) for line in header)]
            faces = [line for line in header if line.startswith("element face")]
            checks.check(not missing, f"bunny {op_id}: the result keeps colours, qualities and wedge UVs {missing or ''}")
            checks.check(faces and faces[0] != "element face 0", f"bunny {op_id}: {faces}")
    finally:
        ml.close()
    checks.finish()


if __name__ == "__main__":
    main()
