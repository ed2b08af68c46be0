"""meshlabserver -d lists every Hedge filter with every parameter of the catalogue (compared
with `hedge list`): name, help, Rich type, label, and the script name in the tooltip."""
import html
import re
import subprocess

import meshlab_test as mt

EXPECTED_TYPES = {"bool": {"Bool"}, "int": {"Int"}, "float": {"Float", "DynamicFloat"}, "enum": {"Enum"}}


def parse_dump(text):
    """{filter name: (info, [(type, label, tooltip)])} from meshlabserver's doxygen dump."""
    filters = {}
    sections = re.split(r"\n\\section f\d+ ", "\n" + text)
    for section in sections[1:]:
        name, _, rest = section.partition(" \n")
        info, _, params_text = rest.partition("<H2> Parameters </h2>")
        rows = re.findall(r"<TR><TD> \\c (\w+)  </TD> <TD> (.*?) </TD> <TD><i> (.*?) -- </i></TD> </TR>", params_text, re.S)
        filters[name.strip()] = (info.strip(), rows)
    return filters


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


def main():
    args = mt.parse_args()
    checks = mt.Checks()
    meshlab = mt.MeshLab(args)
    try:
        dump = meshlab.path("filters.txt")
        code, output, _ = meshlab.run_server(["-d", dump])
        checks.check(code == 0, f"meshlabserver -d exits 0 (got {code})")
        filters = parse_dump(open(dump, encoding="utf-8", errors="replace").read())
        checks.check(len(filters) > 50, f"the dump lists MeshLab's own filters too ({len(filters)})")

        cli = hedge_list(args.hedge)
        checks.check(set(cli) == set(meshlab.operations),
                      f"hedge list and the catalogue JSON agree on the operations ({sorted(cli)})")
        hedge_filters = sorted(name for name in filters if name.startswith("Hedge: "))
        expected = sorted(op["filter"] for op in meshlab.catalogue["operations"])
        checks.check(hedge_filters == expected, f"exactly one Hedge filter per operation: {hedge_filters}")

        for op in meshlab.catalogue["operations"]:
            name = op["filter"]
            if not checks.check(name in filters, f"{name} is listed"):
                continue
            info, rows = filters[name]
            checks.check(name == "Hedge: " + op["title"], f"{name} is named after the title")
            checks.check(len(info) > 40 and html.unescape(info).split(".")[0] in
                         subprocess.run([args.hedge, "help", op["id"]], capture_output=True, text=True).stdout,
                         f"{name}: its info is the catalogue's help")
            ids = [p["id"] for p in op["params"]]
            checks.check(ids == cli.get(op["id"]), f"{name}: parameters {ids} are those of hedge list")
            checks.check(len(rows) == len(op["params"]), f"{name}: {len(op['params'])} parameters listed ({len(rows)})")
            for p, (rich, label, tooltip) in zip(op["params"], rows):
                checks.check(rich in EXPECTED_TYPES[p["type"]] and "Rich" + rich == p["rich_type"],
                             f"{name}: {p['id']} is a Rich{rich} ({p['type']})")
                checks.check(html.unescape(label) == p["label"], f"{name}: {p['id']} labelled '{label}'")
                checks.check(f"[{p['id']}: " in tooltip, f"{name}: {p['id']}'s tooltip names it for scripts")
                if p["type"] == "enum":
                    checks.check(all(c in tooltip for c in p["choices"]), f"{name}: {p['id']} lists its choices")
    finally:
        meshlab.close()
    checks.finish()


if __name__ == "__main__":
    main()
