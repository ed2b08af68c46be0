// The invariant checker. Walks every element once; loops are bounded by the number of
// half-edges so a corrupted mesh is reported, never looped over forever.
#include "hedge/validate.h"

#include <sstream>
#include <vector>

#include "hedge/error.h"

namespace hedge {
namespace {

class Checker {
 public:
  explicit Checker(const Mesh& mesh) : m_(mesh) {}

  Validation run() {
    if (!sizes() || !halfedges() || !faces() || !vertices()) return result_;
    return result_;
  }

 private:
  template <class... Args>
  bool fail(Args&&... args) {
    std::ostringstream out;
    (out << ... << args);
    result_ = {false, out.str()};
    return false;
  }

  bool sizes() {
    if (m_.positions().size() != m_.vertices_size())
      return fail("positions: ", m_.positions().size(), " entries for ", m_.vertices_size(), " vertices");
    if (m_.vertex_properties().size() != m_.vertices_size() || m_.halfedge_properties().size() != m_.halfedges_size() ||
        m_.edge_properties().size() != m_.edges_size() || m_.face_properties().size() != m_.faces_size())
      return fail("properties: a container's length differs from its element count");
    return true;
  }

  bool in_range(Halfedge h) const { return h.is_valid() && h.idx() < m_.halfedges_size(); }
  bool in_range(Vertex v) const { return v.is_valid() && v.idx() < m_.vertices_size(); }
  bool in_range(Face f) const { return f.is_valid() && f.idx() < m_.faces_size(); }

  bool halfedges() {
    for (Index i = 0; i < m_.halfedges_size(); ++i) {
      Halfedge h(i);
      if (m_.is_deleted(h)) continue;
      Halfedge n = m_.next(h), p = m_.prev(h);
      Vertex v = m_.to_vertex(h);
      Face f = m_.face(h);
      if (!in_range(n) || !in_range(p)) return fail("half-edge ", i, ": next or prev is not a valid half-edge");
      if (m_.is_deleted(n) || m_.is_deleted(p)) return fail("half-edge ", i, ": next or prev is deleted");
      if (m_.prev(n) != h) return fail("half-edge ", i, ": prev(next(h)) is ", m_.prev(n).idx());
      if (m_.next(p) != h) return fail("half-edge ", i, ": next(prev(h)) is ", m_.next(p).idx());
      if (!in_range(v) || m_.is_deleted(v)) return fail("half-edge ", i, ": target vertex is invalid or deleted");
      if (f.is_valid() && (!in_range(f) || m_.is_deleted(f)))
        return fail("half-edge ", i, ": face is out of range or deleted");
      if (m_.face(n) != f) return fail("half-edge ", i, ": next(h) lies in another face");
      if (m_.to_vertex(p) != m_.from_vertex(h))
        return fail("half-edge ", i, ": to_vertex(prev(h)) is not the origin of h (to_vertex(opposite(h)))");
      if (v == m_.from_vertex(h)) return fail("half-edge ", i, ": starts and ends at vertex ", v.idx());
      if (m_.is_boundary(h) && m_.is_boundary(Mesh::opposite(h)))
        return fail("edge ", i / 2, ": has no face on either side");
    }
    return true;
  }

  bool faces() {
    std::vector<Index> seen(m_.vertices_size(), kInvalidIndex);
    const std::size_t bound = m_.halfedges_size();
    for (Index i = 0; i < m_.faces_size(); ++i) {
      Face f(i);
      if (m_.is_deleted(f)) continue;
      Halfedge start = m_.halfedge(f);
      if (!in_range(start) || m_.is_deleted(start)) return fail("face ", i, ": its half-edge is invalid or deleted");
      if (m_.face(start) != f) return fail("face ", i, ": face(halfedge(f)) is not f");
      std::size_t n = 0;
      Halfedge h = start;
      do {
        Vertex v = m_.to_vertex(h);
        if (seen[v.idx()] == i) return fail("face ", i, ": visits vertex ", v.idx(), " twice");
        seen[v.idx()] = i;
        h = m_.next(h);
        if (++n > bound) return fail("face ", i, ": its loop does not close");
      } while (h != start);
      if (n < 3) return fail("face ", i, ": has ", n, " corners, fewer than 3");
    }
    return true;
  }

  bool vertices() {
    // Every vertex must be manifold: rotating around it reaches all its outgoing half-edges.
    std::vector<Index> outgoing(m_.vertices_size(), 0);
    for (Index i = 0; i < m_.halfedges_size(); ++i)
      if (!m_.is_deleted(Halfedge(i))) ++outgoing[m_.from_vertex(Halfedge(i)).idx()];
    const std::size_t bound = m_.halfedges_size();
    for (Index i = 0; i < m_.vertices_size(); ++i) {
      Vertex v(i);
      if (m_.is_deleted(v)) {
        if (outgoing[i]) return fail("vertex ", i, ": deleted but still has ", outgoing[i], " edges");
        continue;
      }
      Halfedge start = m_.halfedge(v);
      if (!start.is_valid()) {
        if (outgoing[i]) return fail("vertex ", i, ": has no half-edge but ", outgoing[i], " edges");
        continue;
      }
      if (!in_range(start) || m_.is_deleted(start)) return fail("vertex ", i, ": its half-edge is invalid or deleted");
      if (m_.from_vertex(start) != v) return fail("vertex ", i, ": halfedge(v) does not start at v");
      std::size_t n = 0, boundary = 0;
      Halfedge h = start;
      do {
        if (m_.from_vertex(h) != v) return fail("vertex ", i, ": rotation reached a half-edge not leaving it");
        if (m_.is_boundary(h)) ++boundary;
        h = m_.ccw_rotated(h);
        if (++n > bound) return fail("vertex ", i, ": rotation does not close");
      } while (h != start);
      if (n != outgoing[i])
        return fail("vertex ", i, ": non-manifold, its fan holds ", n, " of its ", outgoing[i], " edges");
      if (boundary > 1) return fail("vertex ", i, ": non-manifold, ", boundary, " boundary gaps");
      if (boundary == 1 && !m_.is_boundary(start))
        return fail("vertex ", i, ": on the boundary but halfedge(v) is not its boundary half-edge");
    }
    return true;
  }

  const Mesh& m_;
  Validation result_;
};

}  // namespace

Validation validate(const Mesh& mesh) { return Checker(mesh).run(); }

void check_valid(const Mesh& mesh, const std::string& context) {
  Validation v = validate(mesh);
  if (!v) throw Error(context + ": invalid mesh: " + v.message);
}

}  // namespace hedge
