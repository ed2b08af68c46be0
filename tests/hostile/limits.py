"""Parameter values at and just beyond their limits, for every parameter of the catalogue
(shared by tests/hostile/test_limits.py for the CLI and tests/blender/test_hostile.py for
hedge.run): each limit itself must be accepted and run, the nearest value beyond it refused
with a message naming the parameter."""
import math


def cases(p):
    """[(value, accepted)] for parameter `p` (a catalogue dict of `hedge list --json`):
    integers and reals at min and max and the nearest values beyond, every choice of an enum
    and one that is not, both booleans, no vertex attribute and one the mesh lacks. A parameter with no upper limit (max None) takes a
    large value instead of its max."""
    if p["type"] == "int":
        if p["max"] is None:
            return [(p["min"], True), (2**31 - 1, True), (p["min"] - 1, False)]
        return [(p["min"], True), (p["max"], True), (p["min"] - 1, False), (p["max"] + 1, False)]
    if p["type"] == "float":
        below = [(float(p["min"]), True), (math.nextafter(float(p["min"]), -math.inf), False),
                 (math.nan, False), (math.inf, False)]
        if p["max"] is None:
            return below + [(1e30, True)]
        return below + [(float(p["max"]), True), (math.nextafter(float(p["max"]), math.inf), False)]
    if p["type"] == "enum":
        return [(c, True) for c in p["choices"]] + [("no_such_" + p["id"], False)]
    if p["type"] == "bool":
        return [(True, True), (False, True)]
    if p["type"] == "vertex_channel":
        # Empty is "none"; any name resolves, and the operation refuses one the mesh lacks.
        return [("", True), ("no_such_attribute", False)]
    raise ValueError(f"unknown parameter type {p['type']}")


def text(value):
    """The value as typed on a command line: shortest round-trip text for reals."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        if math.isnan(value):
            return "nan"
        if math.isinf(value):
            return "inf" if value > 0 else "-inf"
        return repr(value)
    return str(value)


def refusal_names_parameter(message, op_id, p):
    """A refusal names the operation, the parameter and what is allowed (for a vertex
    attribute: that the mesh has none of that name, in the core's words or the host's)."""
    if p["type"] == "vertex_channel":
        return f"{op_id}: {p['id']}: " in message and " has no vertex " in message
    return f"{op_id}: parameter {p['id']} must be {p['range_text']}" in message
