#include "welded_copies.h"

#include <algorithm>
#include <utility>

namespace hedge::detail {

WeldedCopies::WeldedCopies(const Mesh& mesh) {
  const auto* source = mesh.vertex_properties().get<std::uint32_t>(provenance::kVertexSource);
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

bool WeldedCopies::meets_flip(const Mesh& mesh, Edge e) const {
  if (!any()) return false;
  const Halfedge h0 = Mesh::halfedge(e, 0), h1 = Mesh::halfedge(e, 1);
  const Vertex c = mesh.to_vertex(mesh.next(h0)), d = mesh.to_vertex(mesh.next(h1));
  return edge_elsewhere(mesh, mesh.to_vertex(h0), mesh.to_vertex(h1), e) || same(c, d) || edge_elsewhere(mesh, c, d);
}

bool WeldedCopies::meets_collapse(const Mesh& mesh, Halfedge h) const {
  if (!any()) return false;
  const Vertex v0 = mesh.from_vertex(h), v1 = mesh.to_vertex(h);
  const Halfedge o = Mesh::opposite(h);
  const Vertex vl = mesh.is_boundary(h) ? Vertex() : mesh.to_vertex(mesh.next(h));
  const Vertex vr = mesh.is_boundary(o) ? Vertex() : mesh.to_vertex(mesh.next(o));
  for (Halfedge g : mesh.outgoing(v0)) {
    const Vertex r = mesh.to_vertex(g);
    if (!is_copy(v0) && !is_copy(r) && !is_copy(v1)) continue;
    // The removed end's edges that the weld shares with other copies would move to v1.
    if (edge_elsewhere(mesh, v0, r, Mesh::edge(g))) return true;
    if (r == v1) continue;
    // vl and vr keep their edge to v1; the weld must not make it one with another, or the
    // triangle v0 leaves on them (when v0 has three neighbours) may weld onto an existing one.
    if (r == vl || r == vr) {
      const Edge kept = Mesh::edge(r == vl ? mesh.next(h) : mesh.prev(o));
      if (edge_elsewhere(mesh, v1, r, kept)) return true;
      continue;
    }
    if (same(v1, r) || edge_elsewhere(mesh, v1, r)) return true;
  }
  return false;
}

}  // namespace hedge::detail
