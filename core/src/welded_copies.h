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

 private:
  static constexpr std::uint32_t kNone = ~std::uint32_t(0);
  std::span<const Index> copies(Vertex v, const Index& alone) const;

  std::vector<std::uint32_t> group_;  //!< per vertex: its group, kNone when it has no copies
  std::vector<std::uint32_t> start_;  //!< group g's members are members_[start_[g] .. start_[g + 1])
  std::vector<Index> members_;
};

}  // namespace hedge::detail
