// Euler operations of Mesh: adding faces, filling holes, flips, splits, edge insertion and
// removal, collapses and triangulation. Each keeps every invariant listed in mesh.h.
#include <algorithm>
#include <string>
#include <utility>
#include <vector>

#include "hedge/error.h"
#include "hedge/mesh.h"

namespace hedge {
namespace {

std::string id(Index i) { return std::to_string(i); }

bool exists(const Mesh& m, Vertex v) { return v.is_valid() && v.idx() < m.vertices_size() && !m.is_deleted(v); }
bool exists(const Mesh& m, Edge e) { return e.is_valid() && e.idx() < m.edges_size() && !m.is_deleted(e); }
bool exists(const Mesh& m, Halfedge h) { return h.is_valid() && h.idx() < m.halfedges_size() && !m.is_deleted(h); }
bool exists(const Mesh& m, Face f) { return f.is_valid() && f.idx() < m.faces_size() && !m.is_deleted(f); }

bool is_triangle(const Mesh& m, Halfedge h) { return m.next(m.next(m.next(h))) == h; }

// The ops that take a vertex to insert want a fresh one: an existing vertex with edges
// would end up with two fans.
void require_isolated(const Mesh& m, Vertex v, const char* op) {
  if (!exists(m, v)) throw Error(std::string(op) + ": vertex " + id(v.idx()) + " does not exist");
  if (!m.is_isolated(v))
    throw Error(std::string(op) + ": vertex " + id(v.idx()) + " has edges already; pass a new vertex (add_vertex)");
}

// Why each operation would break an invariant, or nullptr when it is legal. The is_*_ok()
// queries and the operations share them, so a refused operation can say why.

const char* flip_refusal(const Mesh& m, Edge e) {
  if (!exists(m, e)) return "the edge does not exist";
  if (m.is_boundary(e)) return "it lies on the boundary";
  Halfedge h0 = Mesh::halfedge(e, 0), h1 = Mesh::halfedge(e, 1);
  if (!is_triangle(m, h0) || !is_triangle(m, h1)) return "its two faces are not both triangles";
  Vertex a = m.to_vertex(m.next(h0)), b = m.to_vertex(m.next(h1));
  if (a == b) return "its two triangles share their third corner";
  if (m.find_halfedge(a, b).is_valid()) return "the flipped edge exists already";
  // An interior end vertex left with two edges would carry two faces glued along both.
  for (Vertex v : {m.to_vertex(h0), m.to_vertex(h1)})
    if (!m.is_boundary(v) && m.valence(v) <= 3) return "an end vertex would be left with only two edges";
  return nullptr;
}

const char* insert_refusal(const Mesh& m, Halfedge h0, Halfedge h1) {
  if (!exists(m, h0) || !exists(m, h1)) return "a half-edge does not exist";
  if (h0 == h1) return "the two half-edges are the same";
  if (m.face(h0) != m.face(h1)) return "the half-edges lie in different faces";
  if (!m.face(h0).is_valid()) return "the half-edges lie on a hole, not a face";
  if (m.next(h0) == h1 || m.next(h1) == h0) return "their target vertices are neighbours in the face";
  if (m.find_halfedge(m.to_vertex(h0), m.to_vertex(h1)).is_valid()) return "their target vertices are joined already";
  return nullptr;
}

const char* removal_refusal(const Mesh& m, Edge e) {
  if (!exists(m, e)) return "the edge does not exist";
  if (m.is_boundary(e)) return "it lies on the boundary";
  Halfedge h0 = Mesh::halfedge(e, 0), h1 = Mesh::halfedge(e, 1);
  Face f0 = m.face(h0), f1 = m.face(h1);
  if (f0 == f1) return "it has the same face on both sides";
  // The merged face would visit a shared vertex twice.
  Vertex v0 = m.to_vertex(h0), v1 = m.to_vertex(h1);
  for (Vertex v : m.vertices(f0))
    if (v != v0 && v != v1)
      for (Face f : m.faces(v))
        if (f == f1) return "its two faces share another vertex";
  return nullptr;
}

// The link condition of Dey et al. for polygon meshes: collapsing must not merge two edges
// other than the two sides of each triangle at h (those are merged on purpose), must not
// glue two triangles into a pillow, and no face may end up visiting the kept vertex twice.
const char* collapse_refusal(const Mesh& m, Halfedge h) {
  if (!exists(m, h)) return "the half-edge does not exist";
  Halfedge o = Mesh::opposite(h);
  Vertex v0 = m.to_vertex(o), v1 = m.to_vertex(h);
  Face fh = m.face(h), fo = m.face(o);
  Vertex vl, vr;  // opposite corners of the triangles at h (invalid for holes and larger polygons)
  if (fh.is_valid() && is_triangle(m, h)) {
    vl = m.to_vertex(m.next(h));
    if (m.is_boundary(Mesh::opposite(m.next(h))) && m.is_boundary(Mesh::opposite(m.prev(h))))
      return "the triangle on its left has its two other edges on the boundary";
  }
  if (fo.is_valid() && is_triangle(m, o)) {
    vr = m.to_vertex(m.next(o));
    if (m.is_boundary(Mesh::opposite(m.next(o))) && m.is_boundary(Mesh::opposite(m.prev(o))))
      return "the triangle on its right has its two other edges on the boundary";
  }
  if (vl.is_valid() && vl == vr) return "its two triangles share their third corner";
  // A hole of three (or two) edges would shrink below a triangle.
  for (Halfedge s : {h, o})
    if (!m.face(s).is_valid() && (m.next(m.next(s)) == s || m.next(m.next(m.next(s))) == s))
      return "it lies on a hole of three edges";
  if (!m.is_boundary(Mesh::edge(h)) && m.is_boundary(v0) && m.is_boundary(v1))
    return "it is an interior edge joining two boundary vertices (the surface would be pinched)";

  // Common neighbours other than vl and vr would become doubled edges; a second edge
  // between v0 and v1 (build() keeps those where the input has them) would become a loop.
  // v1's ring is read once into a small array when it fits, rather than walked again for
  // every neighbour of v0.
  constexpr int kRingMax = 32;
  Vertex ring1[kRingMax];
  int n1 = 0;
  for (Halfedge s : m.outgoing(v1)) {
    if (n1 == kRingMax) {
      n1 = -1;
      break;
    }
    ring1[n1++] = m.to_vertex(s);
  }
  auto joined_to_v1 = [&](Vertex v) {
    if (n1 < 0) return m.find_halfedge(v, v1).is_valid();
    for (int i = 0; i < n1; ++i)
      if (ring1[i] == v) return true;
    return false;
  };
  int edges_to_v1 = 0;
  for (Vertex v : m.vertices(v0)) {
    if (v == v1) {
      if (++edges_to_v1 > 1) return "a second edge joins its end vertices";
    } else if (v != vl && v != vr && joined_to_v1(v)) {
      return "its end vertices have a common neighbour besides the triangles' corners (link condition)";
    }
  }

  // Triangles (v0, vl, vr) and (v1, vl, vr) would become the same triangle twice.
  if (vl.is_valid() && vr.is_valid()) {
    Halfedge lr = m.find_halfedge(vl, vr);
    if (lr.is_valid()) {
      bool has0 = false, has1 = false;
      for (Halfedge s : {lr, Mesh::opposite(lr)}) {
        if (m.is_boundary(s) || !is_triangle(m, s)) continue;
        Vertex corner = m.to_vertex(m.next(s));
        has0 = has0 || corner == v0;
        has1 = has1 || corner == v1;
      }
      if (has0 && has1) return "two triangles would become one (link condition, e.g. a tetrahedron)";
    }
  }

  // A polygon through v0 and v1 that does not hold the edge would visit v1 twice. Triangles
  // through both hold the edge, so only larger faces need a walk.
  for (Halfedge s : m.outgoing(v0)) {
    Face f = m.face(s);
    if (!f.is_valid() || f == fh || f == fo || is_triangle(m, s)) continue;
    for (Vertex v : m.vertices(f))
      if (v == v1) return "a face other than the edge's own passes through both end vertices";
  }
  return nullptr;
}

std::string refused(const char* op, const std::string& what, const char* why) {
  return std::string(op) + ": " + what + " refused: " + why;
}

// Splits the face of h0 and h1 by a new edge to_vertex(h0) -> to_vertex(h1); no checks. The
// face keeps h0's side; the new face is h1's side, with corner 0 at to_vertex(h0). Walks
// only h1's side, so cutting small pieces off a big face is O(piece).
Halfedge split_face_by_edge(Mesh& m, Halfedge h0, Halfedge h1) {
  Face f = m.face(h0);
  Vertex v0 = m.to_vertex(h0), v1 = m.to_vertex(h1);
  Halfedge h2 = m.next(h0), h3 = m.next(h1);
  Halfedge h4 = m.new_edge(v0, v1), h5 = Mesh::opposite(h4);
  Face g = m.new_face();
  m.face_properties().copy_element(f.idx(), g.idx());
  // New corners continue the corners at the same vertex of the same old face.
  m.halfedge_properties().copy_element(h1.idx(), h4.idx());
  m.halfedge_properties().copy_element(h0.idx(), h5.idx());

  const Halfedge corner0 = m.halfedge(f);
  m.set_next(h0, h4);
  m.set_next(h4, h3);
  m.set_face(h4, f);
  m.set_next(h1, h5);
  m.set_next(h5, h2);
  bool corner0_moved = false;
  for (Halfedge h = h5;; h = m.next(h)) {
    m.set_face(h, g);
    corner0_moved = corner0_moved || h == corner0;
    if (h == h1) break;
  }
  m.set_halfedge(g, h5);
  if (corner0_moved) m.set_halfedge(f, h0);
  return h4;
}

}  // namespace

// ---- adding and removing ---------------------------------------------------------------

Vertex Mesh::add_vertex(const Point& p) {
  Vertex v = new_vertex();
  position(v) = p;
  return v;
}

Face Mesh::add_triangle(Vertex a, Vertex b, Vertex c) {
  const Vertex v[3] = {a, b, c};
  return add_face(std::span<const Vertex>(v));
}

Face Mesh::add_quad(Vertex a, Vertex b, Vertex c, Vertex d) {
  const Vertex v[4] = {a, b, c, d};
  return add_face(std::span<const Vertex>(v));
}

// pmp-library's add_face: find the existing half-edges, check everything, then link the new
// face into the boundary. Nothing is modified before all checks have passed.
Face Mesh::add_face(std::span<const Vertex> vertices) {
  const std::size_t n = vertices.size();
  auto describe = [&] {
    std::string s = "(";
    for (std::size_t i = 0; i < n; ++i) s += (i ? ", " : "") + id(vertices[i].idx());
    return s + ")";
  };
  auto fail = [&](const std::string& why) -> Error { return Error("add_face " + describe() + ": " + why); };

  if (n < 3) throw fail("a face needs at least 3 vertices");
  for (Vertex v : vertices)
    if (!exists(*this, v)) throw fail("vertex " + id(v.idx()) + " does not exist");
  {
    std::vector<Vertex> sorted(vertices.begin(), vertices.end());
    std::sort(sorted.begin(), sorted.end());
    auto dup = std::adjacent_find(sorted.begin(), sorted.end());
    if (dup != sorted.end()) throw fail("vertex " + id(dup->idx()) + " appears twice");
  }

  std::vector<Halfedge> inner(n);  // inner[i]: vertices[i] -> vertices[i+1]
  std::vector<char> is_new(n), needs_adjust(n, 0);
  std::vector<std::pair<Halfedge, Halfedge>> links;  // set_next() calls, applied at the end
  links.reserve(3 * n);

  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t j = (i + 1) % n;
    inner[i] = find_halfedge(vertices[i], vertices[j]);
    is_new[i] = !inner[i].is_valid();
    if (!is_new[i] && !is_boundary(inner[i]))
      throw fail("edge " + id(vertices[i].idx()) + "-" + id(vertices[j].idx()) +
                 " has a face on this side already (a third face on an edge, or opposite orientation)");
  }
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t j = (i + 1) % n;
    Vertex v = vertices[j];
    if (is_isolated(v)) continue;
    if (!is_boundary(v)) throw fail("vertex " + id(v.idx()) + " is surrounded by faces already");
    if (is_new[i] && is_new[j])
      throw fail("vertex " + id(v.idx()) +
                 " has faces already and the new face shares no edge with them: it would get two fans (non-manifold)");
  }

  // Re-link patches: where both edges at a vertex exist but are not consecutive on the
  // boundary, the half-edges between them move to another gap of that vertex. With one fan
  // per vertex they are always consecutive; this keeps add_face correct on meshes whose
  // low-level construction left a vertex with several fans.
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t j = (i + 1) % n;
    if (is_new[i] || is_new[j]) continue;
    Halfedge inner_prev = inner[i], inner_next = inner[j];
    if (next(inner_prev) == inner_next) continue;
    Halfedge outer_prev = opposite(inner_next);
    Halfedge boundary_prev = outer_prev;
    const std::size_t bound = halfedges_size();
    std::size_t steps = 0;
    do {
      boundary_prev = opposite(next(boundary_prev));
      if (++steps > bound) throw fail("the boundary around vertex " + id(vertices[j].idx()) + " is corrupt");
    } while (!is_boundary(boundary_prev) || boundary_prev == inner_prev);
    Halfedge boundary_next = next(boundary_prev);
    if (boundary_next == inner_next)
      throw fail("vertex " + id(vertices[j].idx()) + " has no free gap to re-link its faces into");
    Halfedge patch_start = next(inner_prev), patch_end = prev(inner_next);
    links.emplace_back(boundary_prev, patch_start);
    links.emplace_back(patch_end, boundary_next);
    links.emplace_back(inner_prev, inner_next);
  }

  // ---- all checks passed: modify ----
  for (std::size_t i = 0; i < n; ++i)
    if (is_new[i]) inner[i] = new_edge(vertices[i], vertices[(i + 1) % n]);

  Face f = new_face();
  set_halfedge(f, inner[n - 1]);  // points to vertices[0]: corner 0

  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t j = (i + 1) % n;
    Vertex v = vertices[j];
    Halfedge inner_prev = inner[i], inner_next = inner[j];
    const int kind = (is_new[i] ? 1 : 0) | (is_new[j] ? 2 : 0);
    if (kind) {
      Halfedge outer_prev = opposite(inner_next), outer_next = opposite(inner_prev);
      switch (kind) {
        case 1: {  // edge into v is new, edge out of v exists
          Halfedge boundary_prev = prev(inner_next);
          links.emplace_back(boundary_prev, outer_next);
          set_halfedge(v, outer_next);
          break;
        }
        case 2: {  // edge into v exists, edge out of v is new
          Halfedge boundary_next = next(inner_prev);
          links.emplace_back(outer_prev, boundary_next);
          set_halfedge(v, boundary_next);
          break;
        }
        case 3:  // both new: v was isolated (checked above)
          set_halfedge(v, outer_next);
          links.emplace_back(outer_prev, outer_next);
          break;
      }
      links.emplace_back(inner_prev, inner_next);
    } else {
      needs_adjust[j] = halfedge(v) == inner_next;
    }
    set_face(inner[i], f);
  }

  for (const auto& [a, b] : links) set_next(a, b);
  for (std::size_t i = 0; i < n; ++i)
    if (needs_adjust[i]) adjust_outgoing_halfedge(vertices[i]);
  return f;
}

Face Mesh::add_face(std::span<const Halfedge> halfedges) {
  const std::size_t n = halfedges.size();
  auto fail = [&](const std::string& why) -> Error { return Error("add_face on half-edges: " + why); };
  if (n < 3) throw fail("a face needs at least 3 half-edges, got " + id(static_cast<Index>(n)));
  for (std::size_t i = 0; i < n; ++i) {
    Halfedge h = halfedges[i], g = halfedges[(i + 1) % n];
    if (!exists(*this, h)) throw fail("half-edge " + id(h.idx()) + " does not exist");
    if (!is_boundary(h)) throw fail("half-edge " + id(h.idx()) + " has a face already");
    if (exists(*this, g) && to_vertex(h) != from_vertex(g))
      throw fail("half-edge " + id(g.idx()) + " does not start where half-edge " + id(h.idx()) + " ends");
  }
  // A closed chain of boundary half-edges through distinct vertices is a whole hole, since a
  // manifold vertex has one boundary gap.
  std::vector<Vertex> corners;
  corners.reserve(n);
  for (Halfedge h : halfedges) corners.push_back(to_vertex(h));
  std::sort(corners.begin(), corners.end());
  if (auto dup = std::adjacent_find(corners.begin(), corners.end()); dup != corners.end())
    throw fail("the chain passes vertex " + id(dup->idx()) + " twice");
  for (std::size_t i = 0; i < n; ++i)
    if (next(halfedges[i]) != halfedges[(i + 1) % n]) throw fail("the half-edges are not one whole boundary loop");

  Face f = new_face();
  for (Halfedge h : halfedges) set_face(h, f);
  set_halfedge(f, halfedges[n - 1]);  // corner 0 is from_vertex(halfedges[0]), as add_face(vertices)
  for (Halfedge h : halfedges) adjust_outgoing_halfedge(to_vertex(h));
  return f;
}

Face Mesh::fill_hole(Halfedge h) {
  if (!exists(*this, h)) throw Error("fill_hole: half-edge " + id(h.idx()) + " does not exist");
  if (!is_boundary(h)) throw Error("fill_hole: half-edge " + id(h.idx()) + " is not on a hole");
  std::vector<Halfedge> hole;
  const std::size_t bound = halfedges_size();
  for (Halfedge g : loop(h)) {
    hole.push_back(g);
    if (hole.size() > bound) throw Error("fill_hole: the hole's loop does not close");
  }
  return add_face(std::span<const Halfedge>(hole));
}

void Mesh::remove_isolated_vertex(Vertex v) {
  if (!exists(*this, v)) throw Error("remove_isolated_vertex: vertex " + id(v.idx()) + " does not exist");
  if (!is_isolated(v))
    throw Error("remove_isolated_vertex: vertex " + id(v.idx()) + " has edges; use delete_vertex to remove its faces");
  mark_deleted(v);
}

// ---- flip --------------------------------------------------------------------------------

bool Mesh::is_flip_ok(Edge e) const { return flip_refusal(*this, e) == nullptr; }

void Mesh::flip(Edge e) {
  if (const char* why = flip_refusal(*this, e)) throw Error(refused("flip", "edge " + id(e.idx()), why));
  // a0 and b0 turn inside the quad a0 a1 a2 / b0 b1 b2; each face keeps its two outer edges
  // that stay on its side, so face identity is preserved (pmp-library's flip).
  Halfedge a0 = halfedge(e, 0), b0 = halfedge(e, 1);
  Halfedge a1 = next(a0), a2 = next(a1);
  Halfedge b1 = next(b0), b2 = next(b1);
  Vertex va0 = to_vertex(a0), va1 = to_vertex(a1);
  Vertex vb0 = to_vertex(b0), vb1 = to_vertex(b1);
  Face fa = face(a0), fb = face(b0);

  // a0 becomes the corner at va1 of fa, b0 the corner at vb1 of fb: continue those corners.
  hprops_.copy_element(a1.idx(), a0.idx());
  hprops_.copy_element(b1.idx(), b0.idx());

  set_vertex(a0, va1);
  set_vertex(b0, vb1);
  set_next(a0, a2);
  set_next(a2, b1);
  set_next(b1, a0);
  set_next(b0, b2);
  set_next(b2, a1);
  set_next(a1, b0);
  set_face(a1, fb);
  set_face(b1, fa);
  set_halfedge(fa, a0);
  set_halfedge(fb, b0);
  // The end vertices lost an interior half-edge; boundary half-edges are untouched.
  if (halfedge(va0) == b0) set_halfedge(va0, a1);
  if (halfedge(vb0) == a0) set_halfedge(vb0, b1);
}

// ---- splits ------------------------------------------------------------------------------

// pmp-library's insert_vertex, keeping corner 0 of both faces where it was.
Halfedge Mesh::split_edge(Edge e, Vertex v) {
  if (!exists(*this, e)) throw Error("split_edge: edge " + id(e.idx()) + " does not exist");
  require_isolated(*this, v, "split_edge");
  //  v0 --h0--> v2   becomes   v0 --h0--> v --h1--> v2
  //     <--o0--                   <--o0--    <--o1--
  Halfedge h0 = halfedge(e, 0), o0 = halfedge(e, 1);
  Halfedge h2 = next(h0), o2 = prev(o0);
  Vertex v2 = to_vertex(h0);
  Face fh = face(h0), fo = face(o0);

  Halfedge h1 = new_edge(v, v2), o1 = opposite(h1);
  eprops_.copy_element(e.idx(), edge(h1).idx());
  // Corners: h1 takes over h0's corner at v2; the corners at v blend their face's
  // neighbouring corners.
  hprops_.copy_element(h0.idx(), h1.idx());
  const float half[2] = {0.5f, 0.5f};
  const Index h_side[2] = {prev(h0).idx(), h1.idx()};
  hprops_.interpolate(h0.idx(), h_side, half);
  const Index o_side[2] = {o2.idx(), o0.idx()};
  hprops_.interpolate(o1.idx(), o_side, half);

  set_next(h1, h2);
  set_next(h0, h1);
  set_vertex(h0, v);
  set_face(h1, fh);
  set_next(o2, o1);
  set_next(o1, o0);
  set_face(o1, fo);

  if (halfedge(v2) == o0) set_halfedge(v2, o1);
  set_halfedge(v, is_boundary(o0) ? o0 : h1);
  if (fh.is_valid() && halfedge(fh) == h0) set_halfedge(fh, h1);
  return h0;
}

Halfedge Mesh::split_edge_triangles(Edge e, Vertex v) {
  if (!exists(*this, e)) throw Error("split_edge_triangles: edge " + id(e.idx()) + " does not exist");
  require_isolated(*this, v, "split_edge_triangles");
  for (unsigned side = 0; side < 2; ++side) {
    Halfedge h = halfedge(e, side);
    if (!is_boundary(h) && !is_triangle(*this, h))
      throw Error("split_edge_triangles: face " + id(face(h).idx()) + " of edge " + id(e.idx()) +
                  " is not a triangle; use split_edge");
  }
  // Two triangles with the same third corner (a pillow) would get two edges from v to it.
  if (!is_boundary(e) && to_vertex(next(halfedge(e, 0))) == to_vertex(next(halfedge(e, 1))))
    throw Error("split_edge_triangles: the two triangles of edge " + id(e.idx()) +
                " share their third corner; connecting it twice would double an edge");
  Halfedge h = split_edge(e, v);    // v0 -> v
  Halfedge o1 = opposite(next(h));  // v2 -> v
  if (!is_boundary(h)) split_face_by_edge(*this, h, next(next(h)));
  if (!is_boundary(o1)) split_face_by_edge(*this, o1, next(next(o1)));
  return h;
}

// pmp-library's split(Face, Vertex): triangle i is (c[i-1], c[i], v) with corner 0 at c[i];
// f keeps the triangle of its corner 0.
void Mesh::split_face(Face f, Vertex v) {
  if (!exists(*this, f)) throw Error("split_face: face " + id(f.idx()) + " does not exist");
  require_isolated(*this, v, "split_face");
  std::vector<Halfedge> rim;
  for (Halfedge h : halfedges(f)) rim.push_back(h);
  const std::size_t n = rim.size();

  // spoke_in[i]: rim[i]'s target -> v; its opposite runs v -> to_vertex(rim[i]).
  std::vector<Halfedge> spoke_in(n);
  for (std::size_t i = 0; i < n; ++i) spoke_in[i] = new_edge(to_vertex(rim[i]), v);

  // Corners at v take the face's average corner; the others continue the rim's corners.
  std::vector<Index> from(n);
  std::vector<float> weights(n, 1.0f / static_cast<float>(n));
  for (std::size_t i = 0; i < n; ++i) from[i] = rim[i].idx();
  hprops_.interpolate(spoke_in[0].idx(), from, weights);
  for (std::size_t i = 1; i < n; ++i) hprops_.copy_element(spoke_in[0].idx(), spoke_in[i].idx());
  for (std::size_t i = 0; i < n; ++i) hprops_.copy_element(rim[i].idx(), opposite(spoke_in[i]).idx());

  for (std::size_t i = 0; i < n; ++i) {
    // Triangle of rim[i]: rim[i] -> spoke_in[i] -> opposite(spoke_in[i-1]).
    Face t = i == 0 ? f : new_face();
    if (i) fprops_.copy_element(f.idx(), t.idx());
    Halfedge back = opposite(spoke_in[(i + n - 1) % n]);
    set_next(rim[i], spoke_in[i]);
    set_next(spoke_in[i], back);
    set_next(back, rim[i]);
    set_face(rim[i], t);
    set_face(spoke_in[i], t);
    set_face(back, t);
    set_halfedge(t, rim[i]);
  }
  set_halfedge(v, opposite(spoke_in[0]));
}

// ---- insert and remove edges (split and merge polygons) -----------------------------------

bool Mesh::is_insert_ok(Halfedge h0, Halfedge h1) const { return insert_refusal(*this, h0, h1) == nullptr; }

Halfedge Mesh::insert_edge(Halfedge h0, Halfedge h1) {
  if (const char* why = insert_refusal(*this, h0, h1))
    throw Error(refused("insert_edge", "half-edges " + id(h0.idx()) + " and " + id(h1.idx()), why));
  return split_face_by_edge(*this, h0, h1);
}

bool Mesh::is_removal_ok(Edge e) const { return removal_refusal(*this, e) == nullptr; }

// The face with the lower index survives, so insert_edge followed by remove_edge gives the
// face back; corner 0 stays at the same vertex.
void Mesh::remove_edge(Edge e) {
  if (const char* why = removal_refusal(*this, e)) throw Error(refused("remove_edge", "edge " + id(e.idx()), why));
  Halfedge a = halfedge(e, 0), b = halfedge(e, 1);  // a: p -> q, b: q -> p
  if (face(b) < face(a)) std::swap(a, b);           // a's face survives
  Face keep = face(a), gone = face(b);
  Vertex p = to_vertex(b), q = to_vertex(a);
  Halfedge a_prev = prev(a), a_next = next(a), b_prev = prev(b), b_next = next(b);

  if (halfedge(p) == a) set_halfedge(p, b_next);
  if (halfedge(q) == b) set_halfedge(q, a_next);
  if (halfedge(keep) == a) set_halfedge(keep, b_prev);  // both point to q
  for (Halfedge h = b_next; h != b; h = next(h)) set_face(h, keep);
  set_next(a_prev, b_next);
  set_next(b_prev, a_next);
  mark_deleted(gone);
  mark_deleted(e);
}

// ---- collapse -------------------------------------------------------------------------------

bool Mesh::is_collapse_ok(Halfedge h) const { return collapse_refusal(*this, h) == nullptr; }

// pmp-library's collapse with remove_edge_helper and remove_loop_helper, made polygon-aware:
// faces of more than three corners only lose one, triangles (2-gons after the edge goes)
// are removed by merging their two remaining edges.
void Mesh::collapse(Halfedge h) {
  if (const char* why = collapse_refusal(*this, h)) throw Error(refused("collapse", "half-edge " + id(h.idx()), why));
  collapse_unchecked(h);
}

void Mesh::collapse_unchecked(Halfedge h) { collapse_unchecked(h, deleted_); }

void Mesh::collapse_unchecked(Halfedge h, Deletions& tally) {
#ifndef NDEBUG
  if (const char* why = collapse_refusal(*this, h))
    throw Error(refused("collapse_unchecked", "half-edge " + id(h.idx()), why) + " (the caller's precondition)");
#endif
  Halfedge o = opposite(h);
  Vertex v0 = to_vertex(o), v1 = to_vertex(h);
  Halfedge hn = next(h), hp = prev(h), on = next(o), op = prev(o);
  Face fh = face(h), fo = face(o);
  // Only a vertex on the boundary has an outgoing boundary half-edge to restore, and a legal
  // collapse changes no vertex's boundary status but v1's (it becomes v0's or v1's). So the
  // walk around v1 is needed only when that is a boundary vertex, and the walk around a
  // loop's far corner only when its outgoing half-edge was the one removed.
  const bool boundary_kept = is_boundary(v0) || is_boundary(v1);

  // After the edge goes, hp is fh's corner at v1: it continues h's corner there.
  hprops_.copy_element(h.idx(), hp.idx());
  for (Halfedge s : outgoing(v0)) set_vertex(opposite(s), v1);
  set_next(hp, hn);
  set_next(op, on);
  if (fh.is_valid() && halfedge(fh) == h) set_halfedge(fh, hp);
  if (fo.is_valid() && halfedge(fo) == o) set_halfedge(fo, op);
  if (halfedge(v1) == o) set_halfedge(v1, hn);
  set_halfedge(v0, Halfedge());
  mark_deleted(v0, tally);
  mark_deleted(edge(h), tally);

  // A 2-gon g -> next(g) -> g: keep next(g)'s edge (the one at v1), put it where
  // opposite(g) was, and drop g's edge and face.
  auto remove_loop = [&](Halfedge g) {
    Halfedge k = next(g), og = opposite(g), ok = opposite(k);
    Vertex a = to_vertex(g), b = to_vertex(k);
    Face loop_face = face(g), outer = face(og);
    hprops_.copy_element(og.idx(), k.idx());
    set_next(prev(og), k);
    set_next(k, next(og));
    set_face(k, outer);
    if (outer.is_valid() && halfedge(outer) == og) set_halfedge(outer, k);
    if (halfedge(a) == og) set_halfedge(a, k);
    if (halfedge(b) == g) {
      set_halfedge(b, ok);
      adjust_outgoing_halfedge(b);
    }
    if (loop_face.is_valid()) mark_deleted(loop_face, tally);
    mark_deleted(edge(g), tally);
  };
  if (next(next(hp)) == hp) remove_loop(hp);
  // The first removal may have deleted on's edge (when fo also held hp's outer side).
  if (!is_deleted(on) && next(next(on)) == on) remove_loop(on);
  if (boundary_kept) adjust_outgoing_halfedge(v1);
}

// ---- triangulation ---------------------------------------------------------------------------

// A fan from one corner, cutting one triangle off per insert: O(n). Corner 0 is the apex
// unless one of its diagonals exists already outside the face (only possible in polygon
// meshes), then the first corner whose diagonals are all free; every triangle starts at the apex.
void Mesh::triangulate(Face f) {
  if (!exists(*this, f)) throw Error("triangulate: face " + id(f.idx()) + " does not exist");
  std::vector<Halfedge> rim;
  for (Halfedge h : halfedges(f)) rim.push_back(h);
  const std::size_t n = rim.size();
  if (n <= 3) return;

  std::vector<Vertex> neighbours;
  auto apex_ok = [&](std::size_t k) {
    Vertex apex = to_vertex(rim[k]);
    neighbours.clear();
    for (Vertex w : vertices(apex)) neighbours.push_back(w);
    std::sort(neighbours.begin(), neighbours.end());
    for (std::size_t d = 2; d + 1 < n; ++d)
      if (std::binary_search(neighbours.begin(), neighbours.end(), to_vertex(rim[(k + d) % n]))) return false;
    return true;
  };
  std::size_t apex = 0;
  while (apex < n && !apex_ok(apex)) ++apex;
  if (apex == n)
    throw Error("triangulate: face " + id(f.idx()) +
                " cannot be fanned from any corner without doubling an edge that exists outside it");

  Halfedge h0 = rim[apex];
  for (std::size_t k = 3; k < n; ++k) split_face_by_edge(*this, h0, next(next(h0)));
}

void Mesh::triangulate() {
  const std::size_t n = faces_size();
  for (Index i = 0; i < n; ++i)
    if (!is_deleted(Face(i))) triangulate(Face(i));
}

}  // namespace hedge
