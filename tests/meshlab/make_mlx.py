#!/usr/bin/env python3
"""Writes a MeshLab .mlx script of Hedge filters from the catalogue, every parameter listed with
its Rich type as meshlabserver 2020.09 requires (defaults unless given); hedge-mlx (2021.05+)
runs the same scripts.

  make_mlx.py --catalogue build/bin/hedge_meshlab_catalogue OUT.mlx "decimate target_ratio=0.1" "fill_holes"
"""
import argparse
import sys

import meshlab_test as mt


class Catalogue:
    def __init__(self, tool):
        data = mt.read_catalogue(tool)
        self.operations = {op["id"]: op for op in data["operations"]}


def parse_value(p, text):
    if p["type"] == "bool":
        if text not in ("true", "false", "1", "0"):
            raise SystemExit(f"{p['id']}: true or false, not {text!r}")
        return text in ("true", "1")
    if p["type"] == "int":
        return int(text)
    if p["type"] == "float":
        return float(text)
    if p["type"] == "vertex_channel":
        return text
    return text if text in p["choices"] else int(text)


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--catalogue", required=True, help="the hedge_meshlab_catalogue program, or its JSON")
    parser.add_argument("out", help="the .mlx file to write ('-' for stdout)")
    parser.add_argument("steps", nargs="+", help="an operation id and its id=value pairs, one argument per filter")
    args = parser.parse_args()
    catalogue = Catalogue(args.catalogue)
    filters = []
    for step in args.steps:
        op_id, *pairs = step.split()
        if op_id not in catalogue.operations:
            raise SystemExit(f"unknown operation {op_id!r}; the operations are: {', '.join(catalogue.operations)}")
        params = {p["id"]: p for p in catalogue.operations[op_id]["params"]}
        values = {}
        for pair in pairs:
            key, _, text = pair.partition("=")
            if key not in params:
                raise SystemExit(f"{op_id} has no parameter {key!r}; its parameters are: {', '.join(params)}")
            values[key] = parse_value(params[key], text)
        filters.append(mt.hedge_filter(catalogue, op_id, **values))
    script = mt.mlx(catalogue, filters)
    if args.out == "-":
        sys.stdout.write(script)
    else:
        with open(args.out, "w") as f:
            f.write(script)


if __name__ == "__main__":
    main()
