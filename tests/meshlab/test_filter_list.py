"""The runner's filter list (meshlabserver -d for 2020.09, hedge-mlx --list for 2021.05+) holds
every Hedge filter with every parameter of the catalogue (compared with `hedge list`): name,
help, Rich type, label, and the script name in the tooltip; MeshLab's own filters are there too.
2021.05+: pymeshlab's name hedge_<id>, a FilterClass other than Generic, single-mesh arity and
the catalogue's pre/postconditions, defaults as the catalogue's; the plugin installed for the
user by scripts/install_meshlab --user is found without --plugins."""
import html
import subprocess

import meshlab_test as mt

EXPECTED_TYPES = {"bool": {"RichBool"}, "int": {"RichInt"}, "float": {"RichFloat", "RichDynamicFloat"},
                  "enum": {"RichEnum"}, "vertex_channel": {"RichString"}}
# MeshModel's bits: MM_FACENUMBER; MM_GEOMETRY_AND_TOPOLOGY_CHANGE; MM_NONE.
PRECONDITION = 0x00080000
CHANGES_MESH, NO_CHANGE = 0x431E7BE7, 0x00000000


def hedge_list(hedge):
    """{op id: [param ids]} from the CLI's own listing."""
    ops = {}
    current = None
    for line in subprocess.run([hedge, "list"], check=True, capture_output=True, text=True).stdout.splitlines():
        if not line.startswith(" "):
            current = line.split()[0]
            ops[current] = []
        elif line.strip().startswith("--"):
            ops[current].append(line.split()[0][2:].replace("-", "_"))
    return ops


def check_filter_plugin_fields(ml, checks, op, entry):
    """What MeshLab 2021.05+'s loader and pymeshlab read of each filter."""
    name = op["filter"]
    checks.check(entry["python_name"] == "hedge_" + op["id"], f"{name}: pymeshlab name {entry['python_name']}")
    checks.check(entry["class"] == op["filter_class"] and entry["class"] != 0,
                 f"{name}: FilterClass {entry['class']:#x} (not Generic)")
    checks.check(entry["arity"] == 1, f"{name}: single-mesh arity ({entry['arity']})")
    checks.check(entry["preconditions"] == PRECONDITION, f"{name}: needs faces ({entry['preconditions']:#x})")
    expected = CHANGES_MESH if op["changes_mesh"] else NO_CHANGE
    checks.check(entry["postcondition"] == expected, f"{name}: postcondition {entry['postcondition']:#x}")
    for p, listed in zip(op["params"], entry["parameters"]):
        value = listed["value"]
        default = mt.default_value(p)
        if p["type"] == "enum":
            default = p["choices"].index(default)
            checks.check(listed.get("choices") == p["choices"], f"{name}: {p['id']} offers {p['choices']}")
        if p["rich_type"] == "RichDynamicFloat":
            checks.check(abs(listed["min"] - p["min"]) <= 1e-6 * max(1, abs(p["min"])) and
                         abs(listed["max"] - p["max"]) <= 1e-6 * max(1, abs(p["max"])),
                         f"{name}: {p['id']} slider from {p['min']} to {p['max']}")
        same = abs(float(value) - float(default)) <= 1e-6 * max(1.0, abs(float(default))) \
            if p["type"] == "float" else value == default
        checks.check(same, f"{name}: {p['id']} defaults to {default} ({value})")


def main():
    args = mt.parse_args()
    checks = mt.Checks()
    ml = mt.MeshLab(args)
    try:
        filters = ml.filters()
        checks.check(len(filters) > 50, f"the list holds MeshLab's own filters too ({len(filters)})")

        cli = hedge_list(args.hedge)
        checks.check(set(cli) == set(ml.operations),
                     f"hedge list and the catalogue JSON agree on the operations ({sorted(cli)})")
        hedge_filters = sorted(name for name in filters if name.startswith("Hedge: "))
        expected = sorted(op["filter"] for op in ml.catalogue["operations"])
        checks.check(hedge_filters == expected, f"exactly one Hedge filter per operation: {hedge_filters}")

        for op in ml.catalogue["operations"]:
            name = op["filter"]
            if not checks.check(name in filters, f"{name} is listed"):
                continue
            entry = filters[name]
            info, rows = entry["info"], entry["params"]
            checks.check(name == "Hedge: " + op["title"], f"{name} is named after the title")
            checks.check(len(info) > 40 and html.unescape(info).split(".")[0] in
                         subprocess.run([args.hedge, "help", op["id"]], capture_output=True, text=True).stdout,
                         f"{name}: its info is the catalogue's help")
            ids = [p["id"] for p in op["params"]]
            checks.check(ids == cli.get(op["id"]), f"{name}: parameters {ids} are those of hedge list")
            checks.check(len(rows) == len(op["params"]), f"{name}: {len(op['params'])} parameters listed ({len(rows)})")
            for p, row in zip(op["params"], rows):
                checks.check(row["type"] in EXPECTED_TYPES[p["type"]] and row["type"] == p["rich_type"],
                             f"{name}: {p['id']} is a {row['type']} ({p['type']})")
                checks.check(row["name"] in (None, p["id"]), f"{name}: {p['id']} is named {row['name']} in scripts")
                checks.check(html.unescape(row["label"]) == p["label"], f"{name}: {p['id']} labelled '{row['label']}'")
                checks.check(f"[{p['id']}: " in row["tooltip"], f"{name}: {p['id']}'s tooltip names it for scripts")
                if p["type"] == "enum":
                    checks.check(all(c in row["tooltip"] for c in p["choices"]), f"{name}: {p['id']} lists its choices")
            if ml.runner == "hedge-mlx":
                check_filter_plugin_fields(ml, checks, op, entry)

        if ml.runner == "hedge-mlx":
            # As a user installs it: into HOME's MeshLabExtraPlugins/<version>, found with no --plugins.
            done = ml.install_for_user()
            checks.check(done.returncode == 0, f"install_meshlab --user: {done.stderr.strip()}")
            code, output, errors = ml.list_filters(plugins=False)
            installed = mt.json.loads(output) if code == 0 else {"filters": [], "plugins": []}
            found = sorted(f["name"] for f in installed["filters"] if f["name"].startswith("Hedge: "))
            checks.check(found == expected, f"hedge-mlx finds the user's installed plugin ({len(found)} Hedge filters)")
            ours = [p for p in installed["plugins"] if p["file"].endswith("libfilter_hedge.so")]
            checks.check(len(ours) == 1 and "MeshLabExtraPlugins/" + ml.version in ours[0]["file"],
                         f"loaded from MeshLabExtraPlugins/{ml.version}: {[p['file'] for p in ours]}")
            failed = [p for p in installed["plugins"] if not p["loaded"]]
            print(f"  note  system plugins that do not load in this root: {failed or 'none'}")
    finally:
        ml.close()
    checks.finish()


if __name__ == "__main__":
    main()
