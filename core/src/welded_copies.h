// build()'s copies as operations see them: which vertices extract() welds into one, so an
// operation can refuse a change the weld would turn into a defect (docs/architecture.md,
// "No mesh comes back worse"). Private to the core.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "hedge/mesh.h"

namespace hedge::detail {

class WeldedCopies {
 public:
  //! Reads "hedge:source"; vertices an operation adds later are never copies.
  explicit WeldedCopies(const Mesh& mesh);

  //! False when no two vertices share a source: every weld is the identity, nothing to check.
  bool any() const { return !members_.empty(); }
  //! Whether v shares its source with another vertex.
  bool is_copy(Vertex v) const { return v.idx() < group_.size() && group_[v.idx()] != kNone; }
  //! Whether the weld makes a and b one vertex.
  bool same(Vertex a, Vertex b) const {
    return a == b || (is_copy(a) && is_copy(b) && group_[a.idx()] == group_[b.idx()]);
  }
  //! Whether, after the weld, u - v is an edge through a mesh edge other than `except`.
  bool edge_elsewhere(const Mesh& mesh, Vertex u, Vertex v, Edge except = Edge()) const;
  //! Whether the weld meets a flip of interior edge e: e is one edge with another (a split
  //! non-manifold edge), or the new diagonal is there already or joins a vertex to itself.
  bool meets_flip(const Mesh& mesh, Edge e) const;
  //! Whether the weld meets the collapse of h (from_vertex into to_vertex): the removed end
  //! is on an edge the weld shares with other copies (a split non-manifold edge, which would
  //! move), or has a neighbour that welds with the kept end (an edge from a vertex to itself)
  //! or whose edge to the kept end other copies already make (a third face on it).
  bool meets_collapse(const Mesh& mesh, Halfedge h) const;

 private:
  static constexpr std::uint32_t kNone = ~std::uint32_t(0);
  std::span<const Index> copies(Vertex v, const Index& alone) const;

  std::vector<std::uint32_t> group_;  //!< per vertex: its group, kNone when it has no copies
  std::vector<std::uint32_t> start_;  //!< group g's members are members_[start_[g] .. start_[g + 1])
  std::vector<Index> members_;
};

}  // namespace hedge::detail
