#!/usr/bin/env bash
# The command line's progress bar and Ctrl-C: stages and a bar on stderr only when it is a
# terminal (a pty here) and not --quiet; Ctrl-C exits with 130, says so and leaves no OUT.
set -euo pipefail
HEDGE=$1
MESHES=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

for mesh in bunny.off dragon_res2.ply; do
  [ -f "$MESHES/$mesh" ] || { echo "FAIL: missing $MESHES/$mesh: run scripts/fetch_meshes" >&2; exit 1; }
done

python3 - "$HEDGE" "$MESHES" "$work" <<'PY'
import os, pty, select, signal, subprocess, sys, time

hedge, meshes, work = sys.argv[1:]
bunny, dragon = f"{meshes}/bunny.off", f"{meshes}/dragon_res2.ply"


def fail(message):
    sys.exit(f"FAIL: {message}")


def read_available(fd, until=None, timeout=120):
    """Reads the pty until the child closes it, `until` appears or `timeout` passes; EIO means closed."""
    text, deadline = b"", time.monotonic() + timeout
    while (left := deadline - time.monotonic()) > 0:
        if not select.select([fd], [], [], left)[0]:
            break
        try:
            chunk = os.read(fd, 4096)
        except OSError:
            break
        if not chunk:
            break
        text += chunk
        if until and until in text:
            break
    return text.decode(errors="replace")


def cancelled_within(child, seconds, what):
    """The exit code once the child has ended, `seconds` at most after the SIGINT it was sent."""
    try:
        return child.wait(timeout=seconds)
    except subprocess.TimeoutExpired:
        child.kill()
        child.wait()
        fail(f"{what}: still running {seconds} s after Ctrl-C")


def start_on_pty(args):
    """hedge with stderr on a fresh terminal and stdout a pipe, as `hedge OP ... > report.txt`."""
    master, slave = pty.openpty()
    child = subprocess.Popen([hedge] + args, stdout=subprocess.PIPE, stderr=slave, stdin=subprocess.DEVNULL)
    os.close(slave)
    return child, master


def run_on_pty(args):
    child, master = start_on_pty(args)
    stderr = read_available(master)
    stdout = child.stdout.read().decode()
    child.wait(timeout=120)
    os.close(master)
    return child.returncode, stdout, stderr


# On a terminal: reading, the operation's own stages, writing, a bar redrawn with \r, 100 % at the end.
out = f"{work}/small.off"
code, stdout, stderr = run_on_pty(["decimate", bunny, out, "--target-ratio", "0.2"])
if code != 0 or not os.path.exists(out):
    fail(f"decimate on a pty: exit {code}, stderr {stderr!r}")
for stage in ["reading bunny.off", "building the half-edge mesh", "collapsing edges", "writing small.off"]:
    if stage not in stderr:
        fail(f"stage {stage!r} not shown: {stderr!r}")
if "\r" not in stderr or "[" + "#" * 30 + "] 100 %" not in stderr:
    fail(f"no bar redrawn in place reaching 100 %: {stderr!r}")
if not stderr.rstrip("\r\n").endswith("100 %" + "\033[K"):
    fail(f"the last line is not the finished bar: {stderr!r}")
if "faces" not in stdout or "\r" in stdout or "collapsing edges" in stdout:
    fail(f"the report on stdout is missing or mixed with the bar: {stdout!r}")

# --quiet and -q on a terminal, and any run with stderr a pipe: nothing at all on stderr.
for flag in ["--quiet", "-q"]:
    code, stdout, stderr = run_on_pty(["decimate", bunny, out, flag, "--target-ratio", "0.2"])
    if code != 0 or stderr:
        fail(f"decimate {flag} on a pty: exit {code}, stderr {stderr!r}")
    if "faces" not in stdout:
        fail(f"decimate {flag}: no report: {stdout!r}")
piped = subprocess.run([hedge, "decimate", bunny, out, "--target-ratio", "0.2"], capture_output=True, timeout=120)
if piped.returncode != 0 or piped.stderr:
    fail(f"decimate with stderr a pipe: exit {piped.returncode}, stderr {piped.stderr!r}")

# Ctrl-C while the operation runs (seen on the terminal): the cancel path, exit 130, no OUT. The
# whole run takes minutes; cancelled, it ends at the operation's next progress report, well within 10 s.
out = f"{work}/cancelled_pty.ply"
long_run = lambda mesh, out: ["remesh", mesh, out, "--iterations", "100"]
child, master = start_on_pty(long_run(f"{meshes}/dragon.ply", out))
seen = read_available(master, until=b"splitting long edges")
if "splitting long edges" not in seen:
    child.kill()
    fail(f"remesh never reached its first round: {seen!r}")
started = time.monotonic()
child.send_signal(signal.SIGINT)
rest = read_available(master, timeout=10)
cancelled_within(child, 10, "Ctrl-C on a pty")
os.close(master)
if child.returncode != 130:
    fail(f"Ctrl-C on a pty: exit {child.returncode}, stderr {rest!r}")
if "hedge: cancelled" not in rest:
    fail(f"Ctrl-C on a pty: no message: {rest!r}")
if os.path.exists(out):
    fail("Ctrl-C on a pty left the output file behind")
print(f"cancelled on a pty {time.monotonic() - started:.2f} s after Ctrl-C")

# A plain SIGINT with no terminal at all (--quiet, stderr a pipe): cancelled the same way, and an
# OUT that was there before is left as it was.
out = f"{work}/cancelled_pipe.ply"
with open(out, "w") as f:
    f.write("an older result\n")
child = subprocess.Popen([hedge] + long_run(dragon, out) + ["--quiet"], stdout=subprocess.PIPE, stderr=subprocess.PIPE)
time.sleep(1.5)
if child.poll() is not None:
    fail(f"remesh ended before the SIGINT: exit {child.returncode}")
child.send_signal(signal.SIGINT)
cancelled_within(child, 10, "SIGINT with a pipe")
stdout, stderr = child.stdout.read(), child.stderr.read()
if child.returncode != 130 or stderr.decode().strip() != "hedge: cancelled by the user":
    fail(f"SIGINT with a pipe: exit {child.returncode}, stderr {stderr!r}")
if stdout or open(out).read() != "an older result\n":
    fail(f"SIGINT with a pipe: a report {stdout!r} was printed or the older OUT was changed")
leftovers = sorted(set(os.listdir(work)) - {"small.off", "cancelled_pipe.ply"})
if leftovers:
    fail(f"partial files left behind: {leftovers}")

# OUT is written under a hidden name and renamed; a failed write still names the file asked for.
missing = f"{work}/no/such/dir/out.off"
failed = subprocess.run([hedge, "decimate", bunny, missing], capture_output=True, timeout=120)
if failed.returncode != 1 or failed.stderr.decode().strip() != f"hedge: cannot write {missing}: No such file or directory":
    fail(f"a write into a missing folder: exit {failed.returncode}, stderr {failed.stderr!r}")
print("progress and Ctrl-C: ok")
PY
