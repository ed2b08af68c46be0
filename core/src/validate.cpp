// The invariant checker. Walks every element once; loops are bounded by the number of
// half-edges so a corrupted mesh is reported, never looped over forever. Each pass runs over
// parts of its elements on several threads and reports the failure at the lowest index, the
// one a single thread checking in order would meet first: the message is the same for any
// thread count.
#include "hedge/validate.h"

#include <atomic>
#include <mutex>
#include <optional>
#include <sstream>
#include <utility>
#include <vector>

#include "hedge/error.h"
#include "parallel.h"

namespace hedge {
namespace {

// What one part of a pass found: its first failure, and the scratch its checks share.
struct Part {
  std::optional<std::pair<Index, std::string>> failure;
  std::vector<Index> seen;  // face(): the face that last visited each vertex
  std::size_t count = 0;    // live half-edges seen (halfedge()), or held by fans (vertex())

  template <class... Args>
  bool fail(Index at, Args&&... args) {
    std::ostringstream out;
    (out << ... << args);
    failure.emplace(at, out.str());
    return false;
  }
};

class Checker {
 public:
  explicit Checker(const Mesh& mesh) : m_(mesh) {}

  Validation run() {
    if (!sizes()) return result_;
    std::size_t live = 0, in_fans = 0;
    auto halfedges = [this](Index i, Part& p) { return halfedge(i, p); };
    if (!each(m_.halfedges_size(), halfedges, &live)) return result_;
    if (!each(m_.faces_size(), [this](Index i, Part& p) { return face(i, p); })) return result_;
    // Every vertex's fan closes and leaves only it, so the fans are apart: when they hold every
    // live half-edge, no vertex is non-manifold. Otherwise the vertices are checked again with
    // each one's count of outgoing half-edges, which names the first one that breaks.
    auto vertices = [this](const std::vector<Index>* outgoing, std::size_t* held) {
      return each(
          m_.vertices_size(), [&](Index i, Part& p) { return vertex(i, p, outgoing); }, held);
    };
    if (vertices(nullptr, &in_fans) && in_fans == live) return result_;
    result_ = {};
    const std::vector<Index> outgoing = count_outgoing();
    vertices(&outgoing, nullptr);
    return result_;
  }

 private:
  bool fail(std::string message) {
    result_ = {false, std::move(message)};
    return false;
  }

  // check(i, part) for every i in [0, n), parts of the range on several threads; true when
  // every check passes, else false with the message of the failure at the lowest index.
  // `total`: the parts' counts added up.
  template <class Check>
  bool each(std::size_t n, Check&& check, std::size_t* total = nullptr) {
    std::mutex mutex;
    std::optional<std::pair<Index, std::string>> first;
    std::size_t sum = 0;
    parallel_for(n, 0, [&](std::size_t begin, std::size_t end) {
      Part part;
      for (std::size_t i = begin; i < end; ++i)
        if (!check(static_cast<Index>(i), part)) break;
      std::lock_guard lock(mutex);
      sum += part.count;
      if (part.failure && (!first || part.failure->first < first->first)) first = std::move(part.failure);
    });
    if (total) *total = sum;
    return first ? fail(std::move(first->second)) : true;
  }

  bool sizes() {
    if (m_.positions().size() != m_.vertices_size())
      return fail("positions: " + std::to_string(m_.positions().size()) + " entries for " +
                  std::to_string(m_.vertices_size()) + " vertices");
    if (m_.vertex_properties().size() != m_.vertices_size() || m_.halfedge_properties().size() != m_.halfedges_size() ||
        m_.edge_properties().size() != m_.edges_size() || m_.face_properties().size() != m_.faces_size())
      return fail("properties: a container's length differs from its element count");
    return true;
  }

  bool in_range(Halfedge h) const { return h.is_valid() && h.idx() < m_.halfedges_size(); }
  bool in_range(Vertex v) const { return v.is_valid() && v.idx() < m_.vertices_size(); }
  bool in_range(Face f) const { return f.is_valid() && f.idx() < m_.faces_size(); }

  bool halfedge(Index i, Part& part) const {
    Halfedge h(i);
    if (m_.is_deleted(h)) return true;
    ++part.count;
    Halfedge n = m_.next(h), p = m_.prev(h);
    Vertex v = m_.to_vertex(h);
    Face f = m_.face(h);
    if (!in_range(n) || !in_range(p)) return part.fail(i, "half-edge ", i, ": next or prev is not a valid half-edge");
    if (m_.is_deleted(n) || m_.is_deleted(p)) return part.fail(i, "half-edge ", i, ": next or prev is deleted");
    if (m_.prev(n) != h) return part.fail(i, "half-edge ", i, ": prev(next(h)) is ", m_.prev(n).idx());
    if (m_.next(p) != h) return part.fail(i, "half-edge ", i, ": next(prev(h)) is ", m_.next(p).idx());
    if (!in_range(v) || m_.is_deleted(v)) return part.fail(i, "half-edge ", i, ": target vertex is invalid or deleted");
    if (f.is_valid() && (!in_range(f) || m_.is_deleted(f)))
      return part.fail(i, "half-edge ", i, ": face is out of range or deleted");
    if (m_.face(n) != f) return part.fail(i, "half-edge ", i, ": next(h) lies in another face");
    if (m_.to_vertex(p) != m_.from_vertex(h))
      return part.fail(i, "half-edge ", i, ": to_vertex(prev(h)) is not the origin of h (to_vertex(opposite(h)))");
    if (v == m_.from_vertex(h)) return part.fail(i, "half-edge ", i, ": starts and ends at vertex ", v.idx());
    if (m_.is_boundary(h) && m_.is_boundary(Mesh::opposite(h)))
      return part.fail(i, "edge ", i / 2, ": has no face on either side");
    return true;
  }

  bool face(Index i, Part& part) const {
    Face f(i);
    if (m_.is_deleted(f)) return true;
    if (part.seen.empty()) part.seen.assign(m_.vertices_size(), kInvalidIndex);
    const std::size_t bound = m_.halfedges_size();
    Halfedge start = m_.halfedge(f);
    if (!in_range(start) || m_.is_deleted(start))
      return part.fail(i, "face ", i, ": its half-edge is invalid or deleted");
    if (m_.face(start) != f) return part.fail(i, "face ", i, ": face(halfedge(f)) is not f");
    std::size_t n = 0;
    Halfedge h = start;
    do {
      Vertex v = m_.to_vertex(h);
      if (part.seen[v.idx()] == i) return part.fail(i, "face ", i, ": visits vertex ", v.idx(), " twice");
      part.seen[v.idx()] = i;
      h = m_.next(h);
      if (++n > bound) return part.fail(i, "face ", i, ": its loop does not close");
    } while (h != start);
    if (n < 3) return part.fail(i, "face ", i, ": has ", n, " corners, fewer than 3");
    return true;
  }

  // How many live half-edges leave each vertex, counted on several threads (atomically only
  // when the count is split).
  std::vector<Index> count_outgoing() const {
    const std::size_t n = m_.halfedges_size();
    std::vector<Index> outgoing(m_.vertices_size(), 0);
    parallel_for(n, 0, [&](std::size_t begin, std::size_t end) {
      const bool alone = begin == 0 && end == n;
      for (std::size_t i = begin; i < end; ++i) {
        const Halfedge h(static_cast<Index>(i));
        if (m_.is_deleted(h)) continue;
        Index& count = outgoing[m_.from_vertex(h).idx()];
        if (alone)
          ++count;
        else
          std::atomic_ref(count).fetch_add(1, std::memory_order_relaxed);
      }
    });
    return outgoing;
  }

  // Every vertex must be manifold: its fan closes, every half-edge in it leaves the vertex, at
  // most one gap. The fan's size goes to part.count; given `outgoing` (each vertex's count of
  // live half-edges leaving it), the fan must also hold all of them.
  bool vertex(Index i, Part& part, const std::vector<Index>* outgoing) const {
    Vertex v(i);
    const Index leaving = outgoing ? (*outgoing)[i] : 0;
    if (m_.is_deleted(v)) {
      if (leaving) return part.fail(i, "vertex ", i, ": deleted but still has ", leaving, " edges");
      return true;
    }
    Halfedge start = m_.halfedge(v);
    if (!start.is_valid()) {
      if (leaving) return part.fail(i, "vertex ", i, ": has no half-edge but ", leaving, " edges");
      return true;
    }
    if (!in_range(start) || m_.is_deleted(start))
      return part.fail(i, "vertex ", i, ": its half-edge is invalid or deleted");
    if (m_.from_vertex(start) != v) return part.fail(i, "vertex ", i, ": halfedge(v) does not start at v");
    const std::size_t bound = m_.halfedges_size();
    std::size_t n = 0, boundary = 0;
    Halfedge h = start;
    do {
      if (m_.from_vertex(h) != v) return part.fail(i, "vertex ", i, ": rotation reached a half-edge not leaving it");
      if (m_.is_boundary(h)) ++boundary;
      h = m_.ccw_rotated(h);
      if (++n > bound) return part.fail(i, "vertex ", i, ": rotation does not close");
    } while (h != start);
    if (outgoing && n != leaving)
      return part.fail(i, "vertex ", i, ": non-manifold, its fan holds ", n, " of its ", leaving, " edges");
    if (boundary > 1) return part.fail(i, "vertex ", i, ": non-manifold, ", boundary, " boundary gaps");
    if (boundary == 1 && !m_.is_boundary(start))
      return part.fail(i, "vertex ", i, ": on the boundary but halfedge(v) is not its boundary half-edge");
    part.count += n;
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
