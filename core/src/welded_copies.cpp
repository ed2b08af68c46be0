#include "welded_copies.h"

#include <algorithm>
#include <utility>

namespace hedge::detail {

WeldedCopies::WeldedCopies(const Mesh& mesh) {
  const auto* source = mesh.vertex_properties().get<std::uint32_t>("hedge:source");
  if (!source) return;
  std::vector<std::pair<std::uint32_t, Index>> by_source;
  for (Vertex v : mesh.vertices())
    if (const std::uint32_t s = source->vector()[v.idx()]; s != kInvalidIndex) by_source.emplace_back(s, v.idx());
  std::sort(by_source.begin(), by_source.end());
  group_.assign(mesh.vertices_size(), kNone);
  for (std::size_t i = 0; i < by_source.size();) {
    std::size_t j = i + 1;
    while (j < by_source.size() && by_source[j].first == by_source[i].first) ++j;
    if (j - i > 1) {
      const std::uint32_t g = std::uint32_t(start_.size());
      start_.push_back(std::uint32_t(members_.size()));
      for (std::size_t k = i; k < j; ++k) {
        group_[by_source[k].second] = g;
        members_.push_back(by_source[k].second);
      }
    }
    i = j;
  }
  start_.push_back(std::uint32_t(members_.size()));
}

std::span<const Index> WeldedCopies::copies(Vertex v, const Index& alone) const {
  if (!is_copy(v)) return {&alone, 1};
  const std::uint32_t g = group_[v.idx()];
  return {members_.data() + start_[g], members_.data() + start_[g + 1]};
}

bool WeldedCopies::edge_elsewhere(const Mesh& mesh, Vertex u, Vertex v, Edge except) const {
  const Index alone = u.idx();
  for (Index a : copies(u, alone)) {
    if (mesh.is_deleted(Vertex(a))) continue;
    for (Halfedge h : mesh.outgoing(Vertex(a)))
      if (Mesh::edge(h) != except && same(mesh.to_vertex(h), v)) return true;
  }
  return false;
}

}  // namespace hedge::detail
