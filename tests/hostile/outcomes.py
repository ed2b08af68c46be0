"""What the hostile-input tests of every front end share: collecting checks, the outcome table
(case x operation) they print for the README, and the refusals the core is expected to make."""
import sys

# Refusals expected of the core, whatever the front end: (case, operation) -> a phrase the
# message must contain. Cases with a `defect` (NaN, infinite coordinates, bad indices) are
# refused by every operation with a message naming it; every run not listed must succeed.
NO_FACES = "the mesh has no faces"
LOOP_TRIANGLES = "the loop scheme works on triangle meshes"
DELAUNAY_TRIANGLES = "needs a triangle mesh"
REMESH_TOO_MANY = "give a larger target_edge_length"
EXPECTED_REFUSALS = {
    ("empty", "remesh"): NO_FACES,
    ("vertices_only", "remesh"): NO_FACES,
    ("coincident", "remesh"): "edges all have zero length",
    # The mean edge of a 100,000-gon on its own disc: about 1.8e9 triangles.
    ("huge_polygon", "remesh"): REMESH_TOO_MANY,
    ("huge_polygon", "subdivide"): LOOP_TRIANGLES,
    ("repeated_vertex_faces", "subdivide"): LOOP_TRIANGLES,
    ("self_crossing_polygon", "subdivide"): LOOP_TRIANGLES,
    ("huge_polygon", "make_delaunay"): DELAUNAY_TRIANGLES,
    ("repeated_vertex_faces", "make_delaunay"): DELAUNAY_TRIANGLES,
    ("self_crossing_polygon", "make_delaunay"): DELAUNAY_TRIANGLES,
}

# Known defects, reported but not failed: (case, operation) -> what goes wrong. When one no
# longer happens the test says so (remove the entry).
# (None now: fill_holes on the figure eight gave faces repeating a vertex until extract()
# learnt to keep such copies apart.)
KNOWN_DEFECTS = {}


def expected_refusal(case, op_id):
    if case.defect:
        return case.defect
    return EXPECTED_REFUSALS.get((case.name, op_id))


def known_defect(case_name, op_id):
    return KNOWN_DEFECTS.get((case_name, op_id))


class Checks:
    """Collects failed checks so one run reports all of them; exit code 1 if any failed."""

    def __init__(self, quiet_passes=True):
        self.failed = []
        self.passed = 0
        self.quiet_passes = quiet_passes

    def check(self, condition, what):
        if condition:
            self.passed += 1
            if not self.quiet_passes:
                print(f"  ok    {what}")
        else:
            self.failed.append(what)
            print(f"  FAIL  {what}")
        sys.stdout.flush()
        return condition

    def finish(self):
        print(f"{self.passed} checks passed, {len(self.failed)} failed")
        for what in self.failed:
            print(f"  failed: {what}")
        sys.stdout.flush()
        sys.exit(1 if self.failed else 0)


def short(message, case=None, width=60):
    """A refusal message cut for a table cell (the file name and 'soup: ' prefixes dropped)."""
    if case is not None and case.file_name + ": " in message:
        message = message.split(case.file_name + ": ", 1)[1]
    message = message.replace("soup: ", "").replace("|", "/")
    return "refused: " + (message if len(message) <= width else message[:width - 1] + "…")


class Table:
    def __init__(self, rows, columns):
        self.rows, self.columns = rows, columns
        self.cells = {}

    def set(self, row, column, text):
        self.cells[(row, column)] = text

    def get(self, row, column):
        return self.cells.get((row, column), "")

    def markdown(self):
        lines = ["| case | " + " | ".join(self.columns) + " |", "|---" * (len(self.columns) + 1) + "|"]
        for row in self.rows:
            lines.append(f"| {row} | " + " | ".join(self.get(row, c) for c in self.columns) + " |")
        return "\n".join(lines) + "\n"
