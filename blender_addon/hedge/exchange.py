# bpy.types.Mesh <-> the native module's mesh dict (hedge's Soup), through numpy only:
# foreach_get/foreach_set on whole buffers of the type Blender stores, no per-element loops.
#
# What crosses, and under which channel name (docs/decisions.md, "Blender add-on"):
#   vertex positions             positions
#   polygons of any size         face_sizes, corners (in loop order)
#   each UV map                  corner "uv:<map name>"     f32 x2
#   each colour attribute        "color:<name>"             f32 x4 (byte colours as sRGB /255)
#   generic attributes           "attr:<name>"              point, face or corner domain
#   material indices             face "material"            i32
#   smooth shading               face "smooth"              u8
#   selection, hiding            "selected", "hidden"       u8, vertex and face
#   vertex bevel weight          vertex "bevel_weight"      f32 (3.x; from 4.0 attr:bevel_weight_vert)
#   vertex identity              vertex "blender:vertex"    i32 (where each result vertex came from)
#   each vertex group            vertex "vgroup:<name>"     f32 weight (0 where not a member)
#   each shape key but the basis vertex "shape:<key name>"  f32 x3, the key's offset from the
#                                                           reference key (the basis)
# Edge data (seams, sharp edges, creases, bevel weights, generic edge attributes) has no
# channel: it is matched back by the pair of source vertices of each result edge.
#
# One code for Blender 3.4 to 5.x, chosen by what the running Blender has (never by trying and
# catching): 4.0 and later keep bevel weights, creases, sharp edges and (5.x) seams as generic
# attributes (bevel_weight_vert, bevel_weight_edge, crease_vert, crease_edge, sharp_edge,
# uv_seam), which the generic attribute path carries like any other; 3.x keeps them as
# properties behind has_* tests. Each datum is read once, by one path.
import ctypes

import bmesh
import bpy
import numpy as np

from .native import Error

# Blender attribute type -> (foreach property, numpy dtype, components)
# (a type the running Blender lacks never occurs: 3.4 has the first eight types below, 4.3 adds
# INT32_2D, QUATERNION and FLOAT4X4, 5.2 also INT16_2D and FLOAT4)
ATTRIBUTE_PREFIX = "attr:"  # a generic attribute's channel: "attr:<name>"
ATTRIBUTE_TYPES = {
    'FLOAT': ("value", np.float32, 1),
    'INT': ("value", np.int32, 1),
    'FLOAT_VECTOR': ("vector", np.float32, 3),
    'FLOAT2': ("vector", np.float32, 2),
    'FLOAT_COLOR': ("color", np.float32, 4),
    'BYTE_COLOR': ("color_srgb", np.float32, 4),
    'BOOLEAN': ("value", np.bool_, 1),
    'INT8': ("value", np.int8, 1),
    'INT32_2D': ("value", np.int32, 2),
    'QUATERNION': ("value", np.float32, 4),
    'FLOAT4X4': ("value", np.float32, 16),
    'INT16_2D': ("value", np.int16, 2),
    'FLOAT4': ("vector", np.float32, 4),
}
DOMAINS = {'POINT': "vertex", 'FACE': "face", 'CORNER': "corner"}
BLENDER_DOMAINS = {v: k for k, v in DOMAINS.items()}
# Attributes that the mesh API owns under another name (3.4 and later versions), and custom
# normals (4.4+ "custom_normal": encoded, not to be interpolated; reported as not carried).
RESERVED = {"position", "material_index", "sharp_face", "custom_normal"}

# Edge flags and the attribute that holds each from 4.0 on. A flag is read as a property only
# where the running Blender has the property and no visible generic attribute holds it (3.x;
# 4.x's hidden ".uv_seam"; freestyle marks until 5.0), so it never crosses twice.
EDGE_FLAGS = (("use_seam", "uv_seam"), ("use_edge_sharp", "sharp_edge"), ("use_freestyle_mark", "freestyle_edge"))
_EDGE_PROPERTIES = bpy.types.MeshEdge.bl_rna.properties
# 3.x: bevel weights and creases are properties present when the mesh's has_* says so.
LEGACY_LAYERS = "has_bevel_weight_vertex" in bpy.types.Mesh.bl_rna.properties
LEGACY_EDGE_LAYERS = (("has_crease_edge", "crease"), ("has_bevel_weight_edge", "bevel_weight"))
# Before 4.0 a polygon's loop count is stored beside its start and must be written too.
LOOP_TOTAL_WRITABLE = not bpy.types.MeshPolygon.bl_rna.properties["loop_total"].is_readonly
# 4.0+: node groups declare their sockets through `interface` (3.x: inputs/outputs).
NODE_INTERFACE = "interface" in bpy.types.NodeTree.bl_rna.properties
# Blender moves the mesh's own data from element flags into attributes version by version
# (3.4: selection, hiding, materials; 3.6: corners; 4.0: edges, smooth shading, sharp edges;
# 4.x: seams as ".uv_seam", 5.0: "uv_seam"). Where it keeps one as an attribute, it is read
# there, 10 to 25 times faster than through the element properties, and not at all when the
# mesh has no such attribute (every element has the default). Which ones, is found once on a
# scratch mesh (builtin_attributes()).
_BUILTIN_PROBE = (("vertices", "select", True, False), ("vertices", "hide", True, False),
                  ("polygons", "select", True, False), ("polygons", "hide", True, False),
                  ("polygons", "material_index", 1, 0), ("polygons", "use_smooth", True, False),
                  ("edges", "use_seam", True, False), ("edges", "use_edge_sharp", True, False),
                  ("edges", "use_freestyle_mark", True, False))
_builtin_attributes = None
# Blender before 4.0 copies a boolean into foreach_get's buffer element by element (3.4: 17 to
# 19 ns each, the dragon's selection and smooth flags more than the whole exchange floor);
# 4.3 and 5.2 copy it whole, and there taking an element of an attribute first copies a layer
# it shares. So only before 4.0 are booleans read from Blender's own arrays (_read_bits).
BOOLEANS_ELEMENT_BY_ELEMENT = bpy.app.version < (4, 0, 0)
# (element RNA, property) -> (stride, byte, bit) of the booleans _read_bits reads, found on the
# scratch mesh of builtin_attributes().
_bit_layouts = {}


def _first_values(me):
    return {a.name: a.data[0].value for a in me.attributes if a.data_type in ('BOOLEAN', 'INT') and len(a.data)}


def builtin_attributes():
    """{(collection, property): attribute name} for the element data the running Blender keeps
    as attributes (("polygons", "use_smooth") is held inverted, as "sharp_face"), and
    ".corner_vert" / ".edge_verts" / "position" for the corners' and edges' vertices and the
    vertices' places. Found by setting each property of a scratch triangle two ways and seeing
    which attribute follows."""
    global _builtin_attributes
    if _builtin_attributes is not None:
        return _builtin_attributes
    found = {}
    me = bpy.data.meshes.new("hedge probe")
    try:
        me.from_pydata([(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0)], [], [(0, 1, 2), (0, 2, 3)])
        if BOOLEANS_ELEMENT_BY_ELEMENT:
            _probe_bit_layouts(me)
        for name in (".corner_vert", ".edge_verts", "position"):
            if name in me.attributes:
                found[name] = name
        for collection, prop, first, second in _BUILTIN_PROBE:
            element = getattr(me, collection)[0]
            if prop not in element.bl_rna.properties:
                continue
            setattr(element, prop, first)
            at_first = _first_values(me)
            setattr(element, prop, second)
            at_second = _first_values(me)
            changed = [n for n, v in at_first.items() if n in at_second and at_second[n] != v]
            if len(changed) == 1 and (prop != "use_smooth" or changed[0] == "sharp_face"):
                found[(collection, prop)] = changed[0]
    finally:
        bpy.data.meshes.remove(me)
    _builtin_attributes = found
    return found


def _bit_layout(collection, prop):
    """(stride, byte, bit) of boolean `prop` in the elements of `collection` (two at least),
    found by setting it on the first element both ways and seeing which one bit of the
    element's bytes follows; None when the elements do not lie evenly apart or not exactly one
    bit follows."""
    first = collection[0]
    start = first.as_pointer()
    stride = collection[1].as_pointer() - start
    if not 0 < stride <= 64:
        return None
    was = getattr(first, prop)
    setattr(first, prop, True)
    on = ctypes.string_at(start, stride)
    setattr(first, prop, False)
    off = ctypes.string_at(start, stride)
    setattr(first, prop, was)
    if collection[0].as_pointer() != start:
        return None
    changed = [(i, a ^ b) for i, (a, b) in enumerate(zip(on, off)) if a != b]
    if len(changed) != 1:
        return None
    byte, bit = changed[0]
    one_bit = bit & (bit - 1) == 0
    return (stride, byte, bit) if one_bit and on[byte] & bit else None


def _probe_bit_layouts(me):
    """_bit_layouts for the mesh's boolean element properties (those the attribute probe sets,
    the edge flags among them) and for boolean attributes."""
    for collection_name, prop in [(c, p) for c, p, first, _ in _BUILTIN_PROBE if first is True]:
        collection = getattr(me, collection_name)
        if prop in collection[0].bl_rna.properties:
            _bit_layouts[(collection[0].bl_rna.identifier, prop)] = _bit_layout(collection, prop)
    attribute = me.attributes.new("hedge probe", 'BOOLEAN', 'POINT')
    _bit_layouts[(attribute.data[0].bl_rna.identifier, "value")] = _bit_layout(attribute.data, "value")
    me.attributes.remove(attribute)


def _read_bits(collection, prop, out):
    """Fills `out` with boolean `prop` of every element, read from the elements' own bytes where
    _bit_layouts knows where it lies and the elements are found evenly apart; False when it
    cannot (foreach_get then reads it)."""
    n = len(out)
    if not BOOLEANS_ELEMENT_BY_ELEMENT or n < 2:
        return False
    builtin_attributes()  # finds the layouts
    first = collection[0]
    layout = _bit_layouts.get((first.bl_rna.identifier, prop))
    if layout is None:
        return False
    stride, byte, bit = layout
    start = first.as_pointer()
    if collection[1].as_pointer() - start != stride or collection[n - 1].as_pointer() - start != stride * (n - 1):
        return False
    elements = np.ctypeslib.as_array((ctypes.c_uint8 * (stride * n)).from_address(start)).reshape(n, stride)
    np.not_equal(elements[:, byte] & bit, 0, out=out)
    return True


_unsigned = {}
# The mesh's element collections by their own RNA name ("MeshPolygons"): their elements' RNA.
_ELEMENTS = {p.srna.identifier: p.fixed_type for p in bpy.types.Mesh.bl_rna.properties
             if p.type == 'COLLECTION' and p.srna is not None}


def _buffer_type(collection, prop, dtype):
    """The buffer type foreach_get/set copy in one go. The mesh's own index properties (loop
    starts and totals, corner and edge vertices, material indices) are ints of subtype
    UNSIGNED, which Blender copies whole only into unsigned 32-bit buffers: an int32 buffer is
    filled element by element, ten times slower (3.4 to 5.2; attributes' ints take int32).
    Found from the collection's RNA, not an element's: taking an attribute's first element
    makes Blender copy a layer it shares (a few ms)."""
    if dtype != np.int32:
        return dtype
    rna = getattr(collection, "bl_rna", None)
    key = (rna.identifier if rna is not None else None, prop)
    if key not in _unsigned:
        element = _ELEMENTS.get(key[0])
        p = element.properties.get(prop) if element is not None else None
        _unsigned[key] = p is not None and p.type == 'INT' and p.subtype == 'UNSIGNED'
    return np.uint32 if _unsigned[key] else dtype


def _get(collection, prop, n, dtype, components=1, zeros=np.zeros):
    """n elements (of `components` values each) of every element's `prop`, read into an array
    that zeros(size, dtype) makes: numpy's by default, or a block of the soup's buffers."""
    out = zeros(n * components, _buffer_type(collection, prop, dtype))
    if n and not (dtype == np.bool_ and components == 1 and _read_bits(collection, prop, out)):
        collection.foreach_get(prop, out)
    out = out.view(dtype)
    return out.reshape(n, components) if components > 1 else out


def _builtin(me, name, n, dtype, default, components=1, zeros=np.zeros):
    """A datum Blender keeps as attribute `name`: all `default` when the mesh has none."""
    attribute = me.attributes.get(name)
    if attribute is None:
        values = zeros(n * components, dtype)
        if default:
            values.fill(default)
        return values.reshape(n, components) if components > 1 else values
    return _get(attribute.data, "value", n, dtype, components, zeros)


def _held(me, collection, prop):
    """False when the running Blender keeps the element property as an attribute and the mesh
    has none (every element has the default)."""
    name = builtin_attributes().get((collection, prop))
    return name is None or name in me.attributes


def _flag(me, collection, prop, n, dtype, zeros=np.zeros):
    """An element property (selection, hiding, material, smooth shading, edge flags), from its
    attribute where the running Blender keeps one ("sharp_face" holds smooth shading inverted)."""
    name = builtin_attributes().get((collection, prop))
    if name == "sharp_face":
        values = _builtin(me, name, n, np.bool_, False, zeros=zeros)
        return np.logical_not(values, out=values)
    if name is not None:
        return _builtin(me, name, n, dtype, 0, zeros=zeros)
    return _get(getattr(me, collection), prop, n, dtype, zeros=zeros)


def _set(collection, prop, values):
    if len(collection):
        values = np.ascontiguousarray(values).ravel()
        collection.foreach_set(prop, values.view(_buffer_type(collection, prop, values.dtype)))


_DOMAIN_OF = {"vertices": 'POINT', "edges": 'EDGE', "polygons": 'FACE'}
# The element properties that cross as channels: (channel, domain, collection, property, type).
_FLAG_CHANNELS = (("material", "face", "polygons", "material_index", np.int32),
                  ("smooth", "face", "polygons", "use_smooth", np.bool_),
                  ("selected", "vertex", "vertices", "select", np.bool_),
                  ("selected", "face", "polygons", "select", np.bool_),
                  ("hidden", "vertex", "vertices", "hide", np.bool_),
                  ("hidden", "face", "polygons", "hide", np.bool_),
                  ("bevel_weight", "vertex", "vertices", "bevel_weight", np.float32))
# Those that stay out of the soup when the mesh does not hold them: written as defaults.
_DEFAULT_WHEN_ABSENT = {"material", "selected", "hidden"}


def _put_flag(me, collection, prop, values):
    """Writes what _flag() reads: into the attribute where the running Blender keeps it (made
    when the mesh has none yet; 100 times faster than the element property in 5.2), else into
    the element property."""
    name = builtin_attributes().get((collection, prop))
    if name is None:
        _set(getattr(me, collection), prop, values)
        return
    stored = ~values if name == "sharp_face" else values
    data_type, domain = 'BOOLEAN' if values.dtype == np.bool_ else 'INT', _DOMAIN_OF[collection]
    attribute = me.attributes.get(name)
    if attribute is None:
        if not stored.any():
            return  # no attribute: every element has the default
        attribute = me.attributes.new(name, data_type, domain)
    if attribute.data_type != data_type or attribute.domain != domain:
        _set(getattr(me, collection), prop, values)
    else:
        _set(attribute.data, "value", stored)


def _positions(me):
    """Where the vertices' places are copied in one go: the "position" attribute where Blender
    keeps one (3.5 on; 10 to 70 times faster than the vertices' co), else the vertices."""
    if "position" in builtin_attributes():
        attribute = me.attributes.get("position")
        if attribute is not None and attribute.data_type == 'FLOAT_VECTOR' and attribute.domain == 'POINT':
            return attribute.data, "vector"
    return me.vertices, "co"


class MeshData:
    """One mesh read from Blender: the dict the native module takes, and what is needed to
    write a result back (names of layers and attributes, edge data keyed by vertex pair)."""

    def __init__(self):
        self.soup = None          # dict: positions, face_sizes, corners, channels
        self.loop_order = None    # corner -> loop index when loops are not in polygon order
        self.uv_names = []
        self.active_uv = None
        self.render_uv = None
        self.colors = []          # (name, data_type, domain)
        self.active_color = None
        self.render_color = None
        self.attributes = []      # (name, data_type, domain) generic point/face/corner
        self.edges = None         # (n, 2) int32 vertex pairs
        self.edge_data = {}       # name -> array per edge (flags, crease, bevel weight)
        self.edge_attributes = [] # (name, data_type) generic edge attributes, values in edge_data
        self.edges_read = False   # read_edges() done
        self.not_carried = []     # what could not cross, for the report
        self.vertex_groups = []   # names, in order, when read (read_vertex_groups)
        self.active_group = -1
        self.shape_keys = []      # key block names in order, the reference key first (read_shape_keys)
        self.buffers = None       # the native SoupBuffers the soup's arrays lie in, if any


def _gaps_in_place(values, end, run=1 << 16):
    """Turns rising starts into the gaps between them, in place (the last one's gap is to
    `end`), a run of elements at a time, so that no array of their size is made besides: on
    a large mesh fresh memory costs more than the subtraction."""
    n = len(values)
    for first in range(0, n - 1, run):
        last = min(first + run, n - 1)
        np.subtract(values[first + 1:last + 1], values[first:last], out=values[first:last])
    if n:
        values[-1] = end - values[-1]


def _indices(n, zeros, run=1 << 16):
    """0 to n - 1 (int32) in an array that zeros(n, dtype) makes, a run at a time: np.arange
    would make an array of its own, which the native module would then copy."""
    out = zeros(n, np.int32)
    first_run = np.arange(min(n, run), dtype=np.int32)
    for first in range(0, n, run):
        count = min(run, n - first)
        np.add(first_run[:count], first, out=out[first:first + count])
    return out


def read_mesh(me, edges=True, buffers=None):
    """Reads a bpy.types.Mesh (object mode data) into a MeshData; its edges' data too unless
    `edges` is False (read_edges() then reads them before writing back). Given `buffers` (the
    native module's SoupBuffers), the soup's arrays are read into buffers it makes, which an
    operation then reads where they lie instead of copying them."""
    d = MeshData()
    nv, nl, nf, ne = len(me.vertices), len(me.loops), len(me.polygons), len(me.edges)
    if buffers is None:
        zeros = own_positions = own_sizes = own_corners = np.zeros
    else:
        into = buffers(nv, nf, nl)

        def zeros(size, dtype):
            return into.zeros(size, np.dtype(dtype))

        def inside(block):
            return lambda size, dtype: block.reshape(-1).view(dtype)

        own_positions, own_sizes, own_corners = inside(into.positions), inside(into.face_sizes), inside(into.corners)
        d.buffers = into
    positions = _get(*_positions(me), nv, np.float32, 3, own_positions)
    builtin = builtin_attributes()
    # The loop starts are read into the sizes' buffer and become the sizes there: each
    # polygon's size is the gap to the next start. Starts rising from 0 are the loops in
    # polygon order; otherwise (possible before 3.6) they are read again, the sizes read and
    # the order checked.
    loop_total = own_sizes(nf, np.int32)
    _get(me.polygons, "loop_start", nf, np.int32, zeros=lambda size, dtype: loop_total.view(dtype))
    in_order = not nf or loop_total[0] == 0
    _gaps_in_place(loop_total, nl)
    in_order = in_order and (not nf or loop_total.min() > 0)
    if not in_order:
        loop_start = _get(me.polygons, "loop_start", nf, np.int32)
        _get(me.polygons, "loop_total", nf, np.int32, zeros=lambda size, dtype: loop_total.view(dtype))
    if ".corner_vert" in builtin:
        vertex_index = _builtin(me, ".corner_vert", nl, np.int32, 0, zeros=own_corners)
    else:
        vertex_index = _get(me.loops, "vertex_index", nl, np.int32, zeros=own_corners)
    corners = vertex_index
    if not in_order:
        starts = np.zeros(nf, np.int64)
        np.cumsum(loop_total[:-1], out=starts[1:])
        if not np.array_equal(starts, loop_start):
            # Loops not stored in polygon order: corner k of polygon f is loop loop_start[f] + k.
            d.loop_order = (np.repeat(loop_start - starts, loop_total) +
                            np.arange(int(loop_total.sum()))).astype(np.int64)
            corners = vertex_index[d.loop_order]
    channels = []

    def corner_values(values):
        return values if d.loop_order is None else values[d.loop_order]

    for layer in me.uv_layers:
        uv = _get(layer.data, "uv", nl, np.float32, 2, zeros)
        channels.append(("uv:" + layer.name, "corner", corner_values(uv)))
        d.uv_names.append(layer.name)
    if me.uv_layers.active is not None:
        d.active_uv = me.uv_layers.active.name
    for layer in me.uv_layers:
        if layer.active_render:
            d.render_uv = layer.name

    color_names = set()
    for attr in me.color_attributes:
        color_names.add(attr.name)
    if me.color_attributes.active_color is not None:
        d.active_color = me.color_attributes.active_color.name
    try:
        d.render_color = me.color_attributes[me.color_attributes.render_color_index].name
    except (IndexError, AttributeError):
        d.render_color = None

    sizes = {"vertex": nv, "face": nf, "corner": nl}
    for attr in me.attributes:
        name = attr.name
        if name.startswith(".") or name in RESERVED or name in d.uv_names:
            continue
        kind = ATTRIBUTE_TYPES.get(attr.data_type)
        if kind is None:
            d.not_carried.append(f"attribute {name} ({attr.data_type})")
            continue
        prop, dtype, comps = kind
        if attr.domain == 'EDGE':
            d.edge_attributes.append((name, attr.data_type))
            d.edge_data[ATTRIBUTE_PREFIX + name] = _get(attr.data, prop, ne, dtype, comps)
            continue
        domain = DOMAINS.get(attr.domain)
        if domain is None:
            d.not_carried.append(f"attribute {name} ({attr.domain})")
            continue
        values = _get(attr.data, prop, sizes[domain], dtype, comps, zeros)
        if dtype == np.bool_:
            values = values.view(np.uint8)
        if domain == "corner":
            values = corner_values(values)
        if name in color_names:
            channels.append(("color:" + name, domain, values))
            d.colors.append((name, attr.data_type, attr.domain))
        else:
            channels.append((ATTRIBUTE_PREFIX + name, domain, values))
            d.attributes.append((name, attr.data_type, attr.domain))

    # Materials, selection and hiding cross only when the mesh holds them: absent, every
    # element has the default, which new geometry has too (the write makes sure), and no
    # operation tells an absent channel from one of defaults (the selection: both or neither).
    selected = _held(me, "vertices", "select") or _held(me, "polygons", "select")
    for name, domain, collection, prop, dtype in _FLAG_CHANNELS:
        if name == "bevel_weight":
            continue  # below: a 3.x layer of its own
        if name in _DEFAULT_WHEN_ABSENT and not (selected if name == "selected" else _held(me, collection, prop)):
            continue
        values = _flag(me, collection, prop, sizes[domain], dtype, zeros)
        channels.append((name, domain, values.view(np.uint8) if dtype == np.bool_ else values))
    if LEGACY_LAYERS and me.has_bevel_weight_vertex:
        channels.append(("bevel_weight", "vertex", _get(me.vertices, "bevel_weight", nv, np.float32)))
    channels.append(("blender:vertex", "vertex", _indices(nv, zeros)))

    if me.has_custom_normals:
        d.not_carried.append("custom split normals")
    d.soup = {"positions": positions, "face_sizes": loop_total, "corners": corners, "channels": channels}
    if d.buffers is not None:
        d.soup["buffers"] = d.buffers
    if edges:
        read_edges(me, d)
    return d


def read_edges(me, d):
    """Adds to `d` what only the write-back needs, which may be read while the operation runs:
    the edges' flags and layers, keyed by their vertex pairs."""
    ne = len(me.edges)
    builtin = builtin_attributes()
    for prop, attribute in EDGE_FLAGS:
        if prop not in _EDGE_PROPERTIES or attribute in me.attributes:
            continue
        values = _flag(me, "edges", prop, ne, np.bool_)
        if values.any():
            d.edge_data[prop] = values
    if LEGACY_LAYERS:
        for has, prop in LEGACY_EDGE_LAYERS:
            if getattr(me, has):
                d.edge_data[prop] = _get(me.edges, prop, ne, np.float32)
    # The edges' vertex pairs key the edge data for writing back: read only when there is some.
    if not d.edge_data:
        d.edges = np.zeros((0, 2), np.int32)
    elif ".edge_verts" in builtin:
        d.edges = _builtin(me, ".edge_verts", ne, np.int32, 0, 2)
    else:
        d.edges = _get(me.edges, "vertices", ne, np.int32, 2)
    d.edges_read = True


def _socket(sockets, name, kind):
    return next(s for s in sockets if s.name == name and s.type == kind)


GROUP_PREFIX = "vgroup:"


def vertex_attribute_channel(data, name):
    """The channel a parameter naming a vertex attribute means: the vertex group `name` when
    the object has one (read_vertex_groups), else the point attribute `name`; None when it is
    neither. An empty name (none) stays empty."""
    if not name:
        return name
    if name in data.vertex_groups:
        return GROUP_PREFIX + name
    channels = {c[0] for c in data.soup["channels"] if c[1] == "vertex"}
    return ATTRIBUTE_PREFIX + name if ATTRIBUTE_PREFIX + name in channels else None


# Attribute types that hold one number per element (what a vertex-attribute parameter reads).
ONE_NUMBER_TYPES = ('FLOAT', 'INT', 'BOOLEAN', 'INT8')


def vertex_attribute_names(groups, attributes):
    """The names a vertex-attribute parameter may take, as Blender shows them: the vertex
    groups, then the point attributes of one number per vertex ((name, data_type, domain)
    triples of generic attributes)."""
    return list(groups) + [name for name, data_type, domain in attributes
                           if domain == 'POINT' and data_type in ONE_NUMBER_TYPES and name not in groups]


def read_vertex_groups(obj, me, data):
    """Adds each vertex group of `obj` (whose weights live in `me`) as a vertex channel.
    Blender 3.4 has no bulk access to weights: a temporary geometry-nodes modifier stores
    each group as a float attribute of the evaluated mesh, read with foreach_get."""
    names = [g.name for g in obj.vertex_groups]
    if not names:
        return
    tree = bpy.data.node_groups.new("hedge vertex groups", 'GeometryNodeTree')
    temp = None
    try:
        if NODE_INTERFACE:
            tree.interface.new_socket("Geometry", in_out='INPUT', socket_type='NodeSocketGeometry')
            tree.interface.new_socket("Geometry", in_out='OUTPUT', socket_type='NodeSocketGeometry')
        else:
            tree.inputs.new('NodeSocketGeometry', "Geometry")
            tree.outputs.new('NodeSocketGeometry', "Geometry")
        geometry = tree.nodes.new('NodeGroupInput').outputs[0]
        for i, name in enumerate(names):
            read = tree.nodes.new('GeometryNodeInputNamedAttribute')
            read.data_type = 'FLOAT'
            read.inputs["Name"].default_value = name
            store = tree.nodes.new('GeometryNodeStoreNamedAttribute')
            store.data_type = 'FLOAT'
            store.domain = 'POINT'
            store.inputs["Name"].default_value = f"hedge_group_{i}"
            tree.links.new(geometry, store.inputs["Geometry"])
            tree.links.new(_socket(read.outputs, "Attribute", 'VALUE'), _socket(store.inputs, "Value", 'VALUE'))
            geometry = store.outputs["Geometry"]
        tree.links.new(geometry, tree.nodes.new('NodeGroupOutput').inputs[0])
        temp = bpy.data.objects.new("hedge vertex groups", me)
        bpy.context.scene.collection.objects.link(temp)
        temp.modifiers.new("hedge", 'NODES').node_group = tree
        bpy.context.view_layer.update()
        evaluated = temp.evaluated_get(bpy.context.evaluated_depsgraph_get())
        result = evaluated.to_mesh()
        try:
            nv = len(data.soup["positions"])
            if len(result.vertices) != nv:
                raise RuntimeError("the evaluated mesh has other vertices")
            for i, name in enumerate(names):
                weights = _get(result.attributes[f"hedge_group_{i}"].data, "value", nv, np.float32)
                data.soup["channels"].append((GROUP_PREFIX + name, "vertex", weights))
        finally:
            evaluated.to_mesh_clear()
        data.vertex_groups = names
        data.active_group = obj.vertex_groups.active_index
    except (RuntimeError, KeyError, StopIteration) as e:
        data.not_carried.append(f"vertex groups ({e})")
    finally:
        if temp is not None:
            bpy.data.objects.remove(temp)
        bpy.data.node_groups.remove(tree)


SHAPE_PREFIX = "shape:"


def read_shape_keys(me, data):
    """Adds each shape key of `me` but the reference key (the basis) as a vertex channel
    holding the key's offset from the basis, and makes the basis the positions. Offsets, not
    coordinates: an operation that moves or replaces a vertex moves the basis, and the
    interpolated offset added to the new basis keeps the key's deformation (a dent stays a
    dent where the surface went). Relative and absolute keys alike: each is rebuilt as
    basis + offset, whatever it is relative to."""
    key = me.shape_keys
    if key is None or len(key.key_blocks) == 0:
        return
    nv = len(data.soup["positions"])
    reference = key.reference_key
    for block in key.key_blocks:
        if len(block.data) != nv:
            raise Error(f"shape key '{block.name}' of {me.name} has {len(block.data)} points for {nv} vertices; "
                        f"the mesh and its shape keys disagree (apply or remove the keys)")
    basis = _get(reference.data, "co", nv, np.float32, 3)
    for block in key.key_blocks:
        co = basis if block == reference else _get(block.data, "co", nv, np.float32, 3)
        if not np.isfinite(co).all():
            raise Error(f"shape key '{block.name}' of {me.name} has NaN or infinite coordinates")
        if block != reference:
            data.soup["channels"].append((SHAPE_PREFIX + block.name, "vertex", co - basis))
    # In Edit Mode the mesh read holds the active key's shape; the basis is what keys are
    # relative to (and what Object Mode shows with every key at 0).
    data.soup["positions"] = basis
    data.shape_keys = [block.name for block in key.key_blocks]


def missing_shape_keys(me, data, result):
    """What stops the result's keys from being written: the keys changed since they were
    read (names or order), or a key's channel did not come back. None when all is well."""
    key = me.shape_keys
    names = [block.name for block in key.key_blocks] if key is not None else []
    if names != data.shape_keys:  # keys read as none when the mesh had none
        return "its shape keys changed while Hedge ran"
    lost = [name for name in names[1:] if channel(result, SHAPE_PREFIX + name, "vertex") is None]
    if lost:
        return "shape keys " + ", ".join(repr(name) for name in lost) + " did not come through"
    return None


def _resize_key_blocks(me, n):
    """Gives every key block of `me` n points while keeping the Key data-block, so the key
    blocks' settings, relative keys, drivers and animation (which address key blocks by
    name) all stay. Writing a BMesh into the mesh is the only way the API resizes key
    blocks; a BMesh made from the mesh itself has shape layers tied to the key blocks, so
    Blender resizes them without falling back (and warning). The mesh is left with n loose
    vertices: its geometry is rebuilt right after."""
    old = len(me.vertices)
    me.clear_geometry()
    # Vertices only, no more than the key blocks hold: the BMesh reads that many points.
    me.vertices.add(min(old, n))
    bm = bmesh.new()
    try:
        bm.from_mesh(me)
        # The vertices the result has more of; one by one is the fastest way (0.4 s a million;
        # bmesh.ops.create_circle takes 0.7 s, duplicate 4 s).
        new_vertex = bm.verts.new
        for _ in range(n - len(bm.verts)):
            new_vertex()
        bm.to_mesh(me)
    finally:
        bm.free()


def write_shape_keys(me, data, result):
    """Sets every key block from the result: the reference key at the result's positions,
    every other key at positions + its carried offset."""
    key = me.shape_keys
    positions = result["positions"]
    for block in key.key_blocks:
        if block == key.reference_key:
            _set(block.data, "co", positions)
        else:
            _set(block.data, "co", positions + channel(result, SHAPE_PREFIX + block.name, "vertex"))


def write_vertex_groups(obj, me, data, result):
    """Recreates the vertex groups of a rebuilt mesh, in their order, from their channels
    (float attributes converted by Blender's own operator; weight 0 means not a member)."""
    if not data.vertex_groups:
        return
    for name in data.vertex_groups:
        if name in obj.vertex_groups:
            obj.vertex_groups.remove(obj.vertex_groups[name])
    for name in data.vertex_groups:
        weights = channel(result, GROUP_PREFIX + name, "vertex")
        attr = me.attributes.new(name, 'FLOAT', 'POINT')
        if weights is not None:
            _set(attr.data, "value", weights)
        me.attributes.active = attr
        # edit_object=None: in Edit Mode the stand-in object of the scratch mesh is converted.
        with bpy.context.temp_override(object=obj, active_object=obj, edit_object=None):
            bpy.ops.geometry.attribute_convert(mode='VERTEX_GROUP')
    if 0 <= data.active_group < len(obj.vertex_groups):
        obj.vertex_groups.active_index = data.active_group


def new_attribute(me, name, data_type, domain):
    """A fresh attribute `name`, replacing one of that name (never a second one named .001)."""
    old = me.attributes.get(name)
    if old is not None:
        me.attributes.remove(old)
    return me.attributes.new(name, data_type, domain)


def channel(soup, name, domain):
    for n, dom, values in soup["channels"]:
        if n == name and dom == domain:
            return values
    return None


def same_topology(before, after):
    """True when the result has the input's vertices and polygons (positions or attributes
    may differ): it can then be written in place, keeping everything hedge does not carry."""
    return (len(before["positions"]) == len(after["positions"])
            and np.array_equal(before["face_sizes"], after["face_sizes"])
            and np.array_equal(before["corners"], after["corners"]))


def _edge_keys(pairs, n):
    a = np.minimum(pairs[:, 0], pairs[:, 1]).astype(np.int64)
    b = np.maximum(pairs[:, 0], pairs[:, 1]).astype(np.int64)
    return a * max(n, 1) + b


def _write_channels_in_place(me, data, result):
    """Topology unchanged: positions and the channels hedge may have changed, nothing else."""
    _set(*_positions(me), result["positions"])
    inverse = None
    if data.loop_order is not None:
        inverse = np.empty_like(data.loop_order)
        inverse[data.loop_order] = np.arange(len(data.loop_order))
    _write_attributes(me, data, result, create=False, loop_inverse=inverse)


def _write_attributes(me, data, result, create, loop_inverse=None):
    soup = result

    def loops(values):
        return values if loop_inverse is None else values[loop_inverse]

    for name in data.uv_names:
        values = channel(soup, "uv:" + name, "corner")
        if values is None:
            continue
        layer = me.uv_layers.get(name) if not create else me.uv_layers.new(name=name, do_init=False)
        if layer is not None:
            _set(layer.data, "uv", loops(values))
    if create:
        if data.active_uv and data.active_uv in me.uv_layers:
            me.uv_layers.active = me.uv_layers[data.active_uv]
        if data.render_uv and data.render_uv in me.uv_layers:
            me.uv_layers[data.render_uv].active_render = True

    for prefix, entries in (("color:", data.colors), (ATTRIBUTE_PREFIX, data.attributes)):
        for name, data_type, bl_domain in entries:
            values = channel(soup, prefix + name, DOMAINS[bl_domain])
            if values is None:
                continue
            if create:
                attr = (me.color_attributes.new(name, data_type, bl_domain) if prefix == "color:"
                        else new_attribute(me, name, data_type, bl_domain))
            else:
                attr = me.attributes.get(name)
            if attr is None:
                continue
            prop, dtype, _ = ATTRIBUTE_TYPES[data_type]
            if dtype == np.bool_:
                values = values.view(np.bool_)
            if bl_domain == 'CORNER':
                values = loops(values)
            _set(attr.data, prop, values)
    if create and data.colors:
        if data.active_color and data.active_color in me.color_attributes:
            me.color_attributes.active_color = me.color_attributes[data.active_color]
        if data.render_color and data.render_color in me.color_attributes:
            me.color_attributes.render_color_index = me.color_attributes.find(data.render_color)

    for name, domain, collection, prop, dtype in _FLAG_CHANNELS:
        values = channel(soup, name, domain)
        if values is None:
            if not create or name not in _DEFAULT_WHEN_ABSENT:
                continue
            values = np.zeros(len(getattr(me, collection)), dtype)  # the mesh held none
        values = values.view(dtype) if dtype == np.bool_ else values.astype(dtype, copy=False)
        # What new geometry holds already (zeros, False; smooth faces from 4.1 on), read the fast
        # way where Blender keeps it as an attribute (new geometry has none but "sharp_face").
        if create and np.array_equal(_flag(me, collection, prop, len(getattr(me, collection)), dtype), values):
            continue
        _put_flag(me, collection, prop, values)


def _write_edges(me, data, result):
    """Edge data follows the source-vertex pair of each new edge (both ends must come from
    vertices that were joined by an edge carrying the data)."""
    if not data.edge_data:
        return
    source = channel(result, "blender:vertex", "vertex")
    ne = len(me.edges)
    if source is None or ne == 0 or len(data.edges) == 0:
        return
    n_before = len(data.soup["positions"])
    old_keys = _edge_keys(data.edges, n_before)
    order = np.argsort(old_keys, kind="stable")
    sorted_keys = old_keys[order]
    new_pairs = _get(me.edges, "vertices", ne, np.int32, 2)
    src = source[new_pairs]
    new_keys = _edge_keys(src, n_before)
    pos = np.searchsorted(sorted_keys, new_keys)
    pos = np.minimum(pos, len(sorted_keys) - 1)
    found = (sorted_keys[pos] == new_keys) & (src[:, 0] != src[:, 1])
    match = order[pos]
    for name, values in data.edge_data.items():
        if name.startswith(ATTRIBUTE_PREFIX):
            continue
        out = np.zeros(ne, values.dtype)
        out[found] = values[match[found]]
        _set(me.edges, name, out)
    for name, data_type in data.edge_attributes:
        values = data.edge_data[ATTRIBUTE_PREFIX + name]
        prop, dtype, comps = ATTRIBUTE_TYPES[data_type]
        attr = new_attribute(me, name, data_type, 'EDGE')
        out = np.zeros((ne, comps) if comps > 1 else ne, values.dtype)
        out[found] = values[match[found]]
        _set(attr.data, prop, out)


def repeated_vertex_faces(sizes, corners):
    """Faces that visit a vertex twice in a row (all such triangles), which Blender must not hold."""
    if len(sizes) == 0:
        return 0
    if len(corners) == 3 * len(sizes) and np.all(sizes == 3):  # triangles: no walk around faces
        t = corners.reshape(-1, 3)
        return int(np.count_nonzero((t[:, 0] == t[:, 1]) | (t[:, 1] == t[:, 2]) | (t[:, 2] == t[:, 0])))
    starts = np.zeros(len(sizes), np.int64)
    np.cumsum(sizes[:-1], out=starts[1:])
    nxt = np.arange(1, len(corners) + 1)
    nxt[starts + sizes - 1] = starts
    repeat = corners == corners[nxt]
    return int(np.count_nonzero(np.add.reduceat(repeat, starts)))


def write_mesh(me, data, result, rebuild=False, obj=None):
    """Writes a result dict into `me`. Same topology: in place (unless `rebuild`). Otherwise
    the geometry is rebuilt and every layer recreated from its channel; vertex groups too
    when `obj` (an object using `me`) is given."""
    keyed = bool(data.shape_keys)
    if not rebuild and same_topology(data.soup, result):
        _write_channels_in_place(me, data, result)
        if keyed:
            write_shape_keys(me, data, result)
        me.update()
        return []
    positions = result["positions"]
    if keyed:
        _resize_key_blocks(me, len(positions))
    sizes = result["face_sizes"]
    corners = result["corners"]
    nv, nf, nc = len(positions), len(sizes), len(corners)
    me.clear_geometry()
    me.vertices.add(nv)
    me.loops.add(nc)
    me.polygons.add(nf)
    _set(*_positions(me), positions)
    corner_vert = me.attributes.get(".corner_vert") if ".corner_vert" in builtin_attributes() else None
    if corner_vert is not None:
        _set(corner_vert.data, "value", corners)
    else:
        _set(me.loops, "vertex_index", corners)
    starts = np.zeros(nf, np.int32)
    if nf:
        np.cumsum(sizes[:-1], out=starts[1:])
    _set(me.polygons, "loop_start", starts)
    if LOOP_TOTAL_WRITABLE:
        _set(me.polygons, "loop_total", sizes)
    me.update(calc_edges=True)
    _write_attributes(me, data, result, create=True)
    _write_edges(me, data, result)
    if obj is not None:
        write_vertex_groups(obj, me, data, result)
    if keyed:
        write_shape_keys(me, data, result)
    messages = [f"Blender: not carried: {what}" for what in data.not_carried]
    bad = repeated_vertex_faces(sizes, corners)
    if bad:
        # Never leave Blender a face that repeats a vertex; validate() (slow) only then.
        me.validate(clean_customdata=False)
        messages.append(f"Blender: removed {bad} faces that repeat a vertex (validate)")
    me.update()
    return messages


def write_new(me, soup):
    """Fills an empty mesh from a soup read by hedge's file reader (positions, polygons, and
    the file's per-corner or per-vertex "uv" as a UV map; other channels are not imported)."""
    data = MeshData()
    data.soup = {"positions": np.zeros((0, 3), np.float32), "face_sizes": np.zeros(0, np.int32),
                 "corners": np.zeros(0, np.int32), "channels": []}
    channels = []
    nf = len(soup["face_sizes"])
    for name, domain, values in soup["channels"]:
        if name == "uv" and values.dtype == np.float32 and values.ndim == 2 and values.shape[1] == 2:
            channels.append(("uv:UVMap", "corner", values if domain == "corner" else values[soup["corners"]]))
            data.uv_names = ["UVMap"]
            data.active_uv = data.render_uv = "UVMap"
    result = dict(soup, channels=channels)
    if nf == 0 and len(soup["positions"]) == 0:
        return []
    return write_mesh(me, data, result)
