"""Shared helpers of the MeshLab host tests: a private X server and HOME, the PREFIX copy of
meshlabserver, .mlx scripts generated from the catalogue, and results read back with the hedge CLI."""
import argparse
import json
import os
import re
import shutil
import subprocess
import sys
import time
from xml.sax.saxutils import quoteattr


def parse_args(extra=None):
    parser = argparse.ArgumentParser()
    parser.add_argument("--prefix", required=True, help="PREFIX holding bin/meshlabserver (scripts/install_meshlab --prefix)")
    parser.add_argument("--hedge", required=True, help="the hedge CLI")
    parser.add_argument("--catalogue", required=True, help="hedge_meshlab_catalogue (the catalogue as JSON)")
    parser.add_argument("--meshes", required=True, help="real meshes (scripts/fetch_meshes)")
    parser.add_argument("--out", required=True, help="folder for this test's files")
    for name, kwargs in (extra or {}).items():
        parser.add_argument(name, **kwargs)
    args = parser.parse_args()
    for name in ("prefix", "hedge", "catalogue", "meshes", "out"):
        setattr(args, name, os.path.abspath(getattr(args, name)))
    return args


class Failure(Exception):
    pass


class Checks:
    """Collects failed checks so one run reports all of them; exit code 1 if any failed."""

    def __init__(self):
        self.failed = []
        self.passed = 0

    def check(self, condition, what):
        if condition:
            self.passed += 1
            print(f"  ok    {what}")
        else:
            self.failed.append(what)
            print(f"  FAIL  {what}")
        return condition

    def finish(self):
        print(f"{self.passed} checks passed, {len(self.failed)} failed")
        for what in self.failed:
            print(f"  failed: {what}")
        sys.exit(1 if self.failed else 0)


class XServer:
    """An Xvfb of our own (meshlabserver needs GLX even in batch mode). -displayfd lets Xvfb
    pick a free display itself, so tests running in parallel never race for one."""

    def __init__(self, width=1600, height=1000):
        read_end, write_end = os.pipe()
        self.process = subprocess.Popen(
            ["Xvfb", "-displayfd", str(write_end), "-screen", "0", f"{width}x{height}x24", "-nolisten", "tcp"],
            pass_fds=(write_end,), stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        os.close(write_end)
        with os.fdopen(read_end) as pipe:
            number = pipe.readline().strip()
        if not number:
            raise Failure("Xvfb did not start")
        self.display = ":" + number

    def close(self):
        self.process.terminate()
        try:
            self.process.wait(10)
        except subprocess.TimeoutExpired:
            self.process.kill()


class MeshLab:
    """meshlabserver and meshlab from PREFIX, with a private HOME (a ~/.config/VCG written by
    the GUI changes meshlabserver's behaviour) and our own X server."""

    def __init__(self, args):
        self.args = args
        self.out = os.path.abspath(args.out)
        shutil.rmtree(self.out, ignore_errors=True)
        os.makedirs(self.out)
        self.home = os.path.join(self.out, "home")
        os.makedirs(self.home, mode=0o700)
        self.server = os.path.join(args.prefix, "bin", "meshlabserver")
        self.gui = os.path.join(args.prefix, "bin", "meshlab")
        if not os.access(self.server, os.X_OK):
            raise Failure(f"{self.server} is missing: run scripts/install_meshlab --prefix {args.prefix} PLUGIN")
        self.x = XServer()
        self.catalogue = json.loads(subprocess.run([args.catalogue], check=True, capture_output=True, text=True).stdout)
        self.operations = {op["id"]: op for op in self.catalogue["operations"]}

    def close(self):
        self.x.close()

    def env(self):
        env = dict(os.environ, HOME=self.home, DISPLAY=self.x.display, XDG_RUNTIME_DIR=self.home)
        env.pop("QT_QPA_PLATFORM", None)
        return env

    def run_server(self, arguments, timeout=900):
        """Runs meshlabserver; returns (exit code, output, seconds)."""
        start = time.monotonic()
        try:
            done = subprocess.run([self.server] + arguments, env=self.env(), capture_output=True, text=True,
                                  errors="replace", timeout=timeout, cwd=self.out)
        except subprocess.TimeoutExpired as e:
            raise Failure(f"meshlabserver {' '.join(arguments)} took more than {timeout} s") from e
        seconds = time.monotonic() - start
        return done.returncode, done.stdout + done.stderr, seconds

    def apply(self, mesh_in, mesh_out, filters, name, save_flags=None, timeout=900):
        """Writes the .mlx for `filters` (see mlx()), runs it on mesh_in, saving to mesh_out.
        Returns (exit code, output, seconds)."""
        script = os.path.join(self.out, name + ".mlx")
        with open(script, "w") as f:
            f.write(mlx(self, filters))
        if mesh_out and os.path.exists(mesh_out):
            os.remove(mesh_out)
        arguments = ["-i", mesh_in]
        if mesh_out:
            arguments += ["-o", mesh_out]
            if save_flags:
                arguments += ["-m"] + save_flags
        arguments += ["-s", script]
        code, output, seconds = self.run_server(arguments, timeout)
        with open(os.path.join(self.out, name + ".log"), "w") as f:
            f.write(output)
        return code, output, seconds

    def path(self, name):
        return os.path.join(self.out, name)

    def mesh(self, name):
        return os.path.join(self.args.meshes, name)

    # Reading results back with the hedge CLI (an independent reader of what MeshLab saved).
    def info(self, path):
        done = subprocess.run([self.args.hedge, "info", path, "--json"], capture_output=True, text=True)
        if done.returncode != 0:
            raise Failure(f"hedge info {path}: {done.stderr.strip()}")
        return json.loads(done.stdout)

    def report(self, path):
        done = subprocess.run([self.args.hedge, "report", path, "--json"], capture_output=True, text=True)
        if done.returncode != 0:
            raise Failure(f"hedge report {path}: {done.stderr.strip()}")
        return json.loads(done.stdout)


def hedge_filter(meshlab, op_id, **values):
    """A Hedge filter with every parameter, defaults from the catalogue unless given."""
    op = meshlab.operations[op_id]
    unknown = set(values) - {p["id"] for p in op["params"]}
    if unknown:
        raise Failure(f"{op_id} has no parameters {sorted(unknown)}")
    params = []
    for p in op["params"]:
        value = values.get(p["id"], default_value(p))
        params.append(param_xml(p, value))
    return op["filter"], params


def default_value(p):
    if p["type"] == "bool":
        return bool(p["default"])
    if p["type"] == "int":
        return int(p["default"])
    if p["type"] == "enum":
        return p["choices"][int(p["default"])]
    return p["default"]


def param_xml(p, value):
    """One <Param> as MeshLab 2020.09 reads it: every parameter with its Rich type, or
    meshlabserver aborts."""
    rich = p["rich_type"]
    attributes = {"name": p["id"], "type": rich, "description": p["label"], "tooltip": ""}
    if rich == "RichBool":
        attributes["value"] = "true" if value else "false"
    elif rich == "RichInt":
        attributes["value"] = str(int(value))
    elif rich in ("RichFloat", "RichDynamicFloat"):
        attributes["value"] = repr(float(value))
        if rich == "RichDynamicFloat":
            attributes["min"] = repr(float(p["min"]))
            attributes["max"] = repr(float(p["max"]))
    elif rich == "RichEnum":
        index = p["choices"].index(value) if isinstance(value, str) else int(value)
        attributes["value"] = str(index)
        attributes["enum_cardinality"] = str(len(p["choices"]))
        for i, choice in enumerate(p["choices"]):
            attributes[f"enum_val{i}"] = choice
    else:
        raise Failure(f"unknown Rich type {rich}")
    return attributes


def meshlab_filter(name, *params):
    """One of MeshLab's own filters: params are (type, name, value) for every parameter."""
    out = []
    for rich, pname, value in params:
        if rich == "RichBool":
            value = "true" if value else "false"
        out.append({"name": pname, "type": rich, "value": str(value), "description": pname, "tooltip": ""})
    return name, out


def mlx(meshlab, filters):
    lines = ["<!DOCTYPE FilterScript>", "<FilterScript>"]
    for name, params in filters:
        lines.append(f" <filter name={quoteattr(name)}>")
        for attributes in params:
            text = " ".join(f"{k}={quoteattr(str(v))}" for k, v in attributes.items())
            lines.append(f"  <Param {text}/>")
        lines.append(" </filter>")
    lines.append("</FilterScript>")
    return "\n".join(lines) + "\n"


def logged(output, filter_name):
    """The key = value lines a Hedge filter wrote to MeshLab's log, as a dict (last wins)."""
    values = {}
    for match in re.finditer(re.escape(filter_name) + r": (\w+) = ([^\n]*)", output):
        values[match.group(1)] = match.group(2).strip()
    return values


def quadric_edge_collapse(target_faces):
    """MeshLab's own Quadric Edge Collapse Decimation (2020.09 parameters, all of them)."""
    return meshlab_filter(
        "Simplification: Quadric Edge Collapse Decimation",
        ("RichInt", "TargetFaceNum", target_faces), ("RichFloat", "TargetPerc", 0), ("RichFloat", "QualityThr", 0.3),
        ("RichBool", "PreserveBoundary", False), ("RichFloat", "BoundaryWeight", 1), ("RichBool", "PreserveNormal", False),
        ("RichBool", "PreserveTopology", False), ("RichBool", "OptimalPlacement", True),
        ("RichBool", "PlanarQuadric", False), ("RichFloat", "PlanarWeight", 0.001), ("RichBool", "QualityWeight", False),
        ("RichBool", "AutoClean", True), ("RichBool", "Selected", False))
