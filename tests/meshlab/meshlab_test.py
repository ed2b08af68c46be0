"""Shared helpers of the MeshLab host tests: a private X server and HOME, the "runner" that
applies .mlx scripts (meshlabserver from the PREFIX copy for 2020.09; hedge-mlx, MeshLab's own
library, for 2021.05+, run inside the version's Debian root), .mlx scripts generated from the
catalogue, and results read back with the hedge CLI."""
import argparse
import json
import os
import re
import shutil
import subprocess
import sys
import time
from xml.sax.saxutils import quoteattr

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "hostile"))
import defects  # noqa: E402


def parse_args(extra=None):
    parser = argparse.ArgumentParser()
    parser.add_argument("--runner", choices=("meshlabserver", "hedge-mlx"), default="meshlabserver",
                        help="what applies the scripts: meshlabserver (MeshLab 2020.09) or hedge-mlx (2021.05+)")
    parser.add_argument("--prefix", help="meshlabserver: PREFIX holding bin/meshlabserver (scripts/install_meshlab --prefix)")
    parser.add_argument("--mlx", help="hedge-mlx: the runner built for this MeshLab version")
    parser.add_argument("--plugin", help="hedge-mlx: libfilter_hedge.so built for this MeshLab version")
    parser.add_argument("--hedge", required=True, help="the hedge CLI")
    parser.add_argument("--catalogue", required=True,
                        help="hedge_meshlab_catalogue (the catalogue as JSON), or the JSON file it wrote")
    parser.add_argument("--meshes", required=True, help="real meshes (scripts/fetch_meshes)")
    parser.add_argument("--out", required=True, help="folder for this test's files")
    for name, kwargs in (extra or {}).items():
        parser.add_argument(name, **kwargs)
    args = parser.parse_args()
    needed = ("prefix",) if args.runner == "meshlabserver" else ("mlx", "plugin")
    for name in needed:
        if not getattr(args, name):
            parser.error(f"--runner {args.runner} needs --{name}")
    for name in ("prefix", "mlx", "plugin", "hedge", "catalogue", "meshes", "out"):
        if getattr(args, name):
            setattr(args, name, os.path.abspath(getattr(args, name)))
    return args


def read_catalogue(tool_or_json):
    if tool_or_json.endswith(".json"):
        with open(tool_or_json) as f:
            return json.load(f)
    return json.loads(subprocess.run([tool_or_json], check=True, capture_output=True, text=True).stdout)


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
    """The MeshLab under test with a private HOME (a ~/.config/VCG written by the GUI changes
    meshlabserver's behaviour) and, when the runner or the test needs one, our own X server.

    runner "meshlabserver": MeshLab 2020.09's meshlabserver and meshlab from PREFIX; a failed
    filter exits 255. runner "hedge-mlx": hedge-mlx with MeshLab's system plugins and ours (by
    --plugins, shadowing any installed copy), no X server; the GUI is the system meshlab with our
    plugin installed into the private HOME as a user does; a failed filter exits 1."""

    def __init__(self, args, need_x=False):
        self.args = args
        self.runner = args.runner
        self.out = os.path.abspath(args.out)
        shutil.rmtree(self.out, ignore_errors=True)
        os.makedirs(self.out)
        self.home = os.path.join(self.out, "home")
        os.makedirs(self.home, mode=0o700)
        if self.runner == "meshlabserver":
            self.server = os.path.join(args.prefix, "bin", "meshlabserver")
            self.gui = os.path.join(args.prefix, "bin", "meshlab")
            if not os.access(self.server, os.X_OK):
                raise Failure(f"{self.server} is missing: run scripts/install_meshlab --prefix {args.prefix} PLUGIN")
            self.filter_failed = 255
            self.version = "2020.09"
        else:
            self.server = args.mlx
            self.gui = "/usr/bin/meshlab"
            if not os.access(self.server, os.X_OK):
                raise Failure(f"{self.server} is missing: build it (cmake --build BUILD --target hedge_mlx_<version>)")
            self.filter_failed = 1
            self.version = os.path.basename(os.path.dirname(args.mlx)).removeprefix("meshlab-")
        self.x = XServer() if self.runner == "meshlabserver" or need_x else None
        self.catalogue = read_catalogue(args.catalogue)
        self.operations = {op["id"]: op for op in self.catalogue["operations"]}
        self.dump = None

    def close(self):
        if self.x:
            self.x.close()

    def env(self):
        env = dict(os.environ, HOME=self.home, XDG_RUNTIME_DIR=self.home)
        if self.x:
            env["DISPLAY"] = self.x.display
        env.pop("QT_QPA_PLATFORM", None)
        return env

    def run_server(self, arguments, timeout=900):
        """Runs the runner with `arguments` as they are; returns (exit code, output, seconds).
        meshlabserver is run again (3 runs at most) while it dies before it loads any plugin:
        once in a few hundred runs on a loaded machine its X connection fails (SIGPIPE, or Qt
        "could not connect to display" and abort), and the run did not happen."""
        command = [self.server] + arguments
        if self.runner == "hedge-mlx":
            command = [self.server, "--plugins", os.path.dirname(self.args.plugin)] + arguments
        for _ in range(3):
            start = time.monotonic()
            try:
                done = subprocess.run(command, env=self.env(), capture_output=True, text=True, errors="replace",
                                      timeout=timeout, cwd=self.out)
            except subprocess.TimeoutExpired as e:
                raise Failure(f"{os.path.basename(self.server)} {' '.join(arguments)} took more than {timeout} s") from e
            seconds = time.monotonic() - start
            output = done.stdout + done.stderr
            if (self.runner != "meshlabserver" or done.returncode in (0, self.filter_failed)
                    or "Loading Plugins" in output):
                break
            print(f"  NOTE  meshlabserver died before starting (exit {done.returncode}); run again")
        return done.returncode, output, seconds

    def arguments(self, mesh_in, mesh_out, script, save_flags=None):
        """The runner's arguments to load mesh_in, run script (None: no filter) and save mesh_out
        (None: no save) with the meshlabserver -m flags save_flags."""
        if self.runner == "meshlabserver":
            arguments = ["-i", mesh_in]
            if mesh_out:
                arguments += ["-o", mesh_out] + (["-m"] + save_flags if save_flags else [])
            return arguments + (["-s", script] if script else [])
        if script is None:
            script = os.path.join(self.out, "empty.mlx")
            with open(script, "w") as f:
                f.write(mlx(self, []))
        return (["-m"] + save_flags if save_flags else []) + [mesh_in, mesh_out or "-", script]

    def convert(self, mesh_in, mesh_out, save_flags=None, timeout=900):
        """Loads and saves with no filter. Returns (exit code, output, seconds)."""
        if os.path.exists(mesh_out):
            os.remove(mesh_out)
        return self.run_server(self.arguments(mesh_in, mesh_out, None, save_flags), timeout)

    def apply(self, mesh_in, mesh_out, filters, name, save_flags=None, timeout=900, extra=()):
        """Writes the .mlx for `filters` (see mlx()), runs it on mesh_in, saving to mesh_out.
        Returns (exit code, output, seconds)."""
        script = os.path.join(self.out, name + ".mlx")
        with open(script, "w") as f:
            f.write(mlx(self, filters))
        if mesh_out and os.path.exists(mesh_out):
            os.remove(mesh_out)
        code, output, seconds = self.run_server(list(extra) + self.arguments(mesh_in, mesh_out, script, save_flags),
                                                timeout)
        with open(os.path.join(self.out, name + ".log"), "w") as f:
            f.write(output)
        return code, output, seconds

    def filters(self):
        """Every filter the runner has loaded: {name: {"info", "params": [{"type" (Rich...),
        "name", "label", "tooltip"}], and with hedge-mlx "python_name", "class", "arity",
        "preconditions", "postcondition"}}."""
        if self.runner == "meshlabserver":
            dump = self.path("filters.txt")
            code, output, _ = self.run_server(["-d", dump])
            if code != 0:
                raise Failure(f"meshlabserver -d exits {code}: {output[-2000:]}")
            return parse_doxygen_dump(open(dump, encoding="utf-8", errors="replace").read())
        code, output, _ = self.list_filters()
        if code != 0:
            raise Failure(f"hedge-mlx --list exits {code}: {output[-2000:]}")
        return {f["name"]: dict(f, params=[{"type": p["type"], "name": p["name"], "label": p["description"],
                                             "tooltip": p["tooltip"]} for p in f["parameters"]])
                for f in json.loads(output)["filters"]}

    def list_filters(self, plugins=True):
        """hedge-mlx --list on the bunny (stdout only: the JSON); with plugins=False only the
        default folders (system, the user's MeshLabExtraPlugins). Returns (code, stdout, stderr)."""
        command = [self.server] + (["--plugins", os.path.dirname(self.args.plugin)] if plugins else [])
        done = subprocess.run(command + ["--list", self.mesh("bunny.off")], env=self.env(), capture_output=True,
                              text=True, errors="replace", cwd=self.out, timeout=300)
        with open(self.path("list.json" if plugins else "list_installed.json"), "w") as f:
            f.write(done.stdout)
        return done.returncode, done.stdout, done.stderr

    def install_for_user(self):
        """scripts/install_meshlab --user into the private HOME (hedge-mlx runner: the GUI, and
        hedge-mlx without --plugins, load it from there)."""
        script = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "scripts", "install_meshlab")
        return subprocess.run([script, "--user", "--home", self.home, self.args.plugin], capture_output=True, text=True)

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


_counted = {}


def count_defects(path):
    """defects.count of a mesh file, remembered per file and modification time (inputs recur)."""
    key = (path, os.stat(path).st_mtime_ns)
    if key not in _counted:
        _counted[key] = defects.count(defects.read_mesh(path)[1])
    return _counted[key]


def check_defects(checks, label, mesh_in, mesh_out, subdivision_steps=0):
    """The saved result has no more defects of any category than the input file (but what
    `subdivision_steps` may multiply: defects.allowed); returns the two counts."""
    before, after = count_defects(mesh_in), count_defects(mesh_out)
    for passed, message in defects.verdicts(label, before, after, subdivision_steps):
        checks.check(passed, message)
    return before, after


def write_table(ml, table, file_name):
    """Prints an outcomes.Table and writes it as Markdown into the test's folder."""
    print(table.markdown())
    with open(ml.path(file_name), "w") as f:
        f.write(table.markdown())


def parse_doxygen_dump(text):
    """meshlabserver -d's doxygen dump as filters(): {name: {"info", "params"}}."""
    filters = {}
    sections = re.split(r"\n\\section f\d+ ", "\n" + text)
    for section in sections[1:]:
        name, _, rest = section.partition(" \n")
        info, _, params_text = rest.partition("<H2> Parameters </h2>")
        rows = re.findall(r"<TR><TD> \\c (\w+)  </TD> <TD> (.*?) </TD> <TD><i> (.*?) -- </i></TD> </TR>", params_text, re.S)
        filters[name.strip()] = {"info": info.strip(), "params": [{"type": "Rich" + rich, "name": None, "label": label,
                                                                    "tooltip": tooltip} for rich, label, tooltip in rows]}
    return filters


def result_of(output, filter_name):
    """What hedge-mlx printed as the filter's returned map (RESULT: name: {...}), last run; None if none."""
    found = None
    for line in output.splitlines():
        if line.startswith(f"RESULT: {filter_name}: "):
            found = json.loads(line[len(f"RESULT: {filter_name}: "):])
    return found


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


def subdivision_steps(meshlab, filters):
    """How many subdivision steps a list of Hedge filters makes (their `iterations` added up)."""
    name = meshlab.operations["subdivide"]["filter"]
    steps = 0
    for filter_name, params in filters:
        if filter_name == name:
            given = [re.search(r'value="(\d+)"', p) for p in params if 'name="iterations"' in p]
            steps += int(given[0].group(1)) if given and given[0] else 1
    return steps


def hedge_filter_given(meshlab, op_id, **values):
    """A Hedge filter with only the parameters given (2021.05+ runners take defaults for the rest)."""
    op = meshlab.operations[op_id]
    by_id = {p["id"]: p for p in op["params"]}
    unknown = set(values) - set(by_id)
    if unknown:
        raise Failure(f"{op_id} has no parameters {sorted(unknown)}")
    return op["filter"], [param_xml(by_id[k], v) for k, v in values.items()]


def default_value(p):
    if p["type"] == "bool":
        return bool(p["default"])
    if p["type"] == "int":
        return int(p["default"])
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
    elif rich == "RichString":
        attributes["value"] = str(value)
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
