// What the subdivision steps share and need not inline (subdivide_refine.h).
#include "subdivide_refine.h"

#include <algorithm>
#include <limits>
#include <numbers>
#include <tuple>
#include <typeinfo>
#include <utility>
#include <vector>

#include "hedge/error.h"
#include "hedge/normals.h"
#include "hedge/provenance.h"
#include "hedge/vec.h"
#include "selection.h"

namespace hedge::subdivision {

unsigned threads_for(const std::vector<Target>& all, unsigned threads) {
  for (const Target& t : all)
    if (t.array->type() == typeid(bool)) return 1;
  return threads;
}

std::vector<Target> targets(PropertyContainer& c) {
  std::vector<Target> out;
  for (std::size_t i = 0; i < c.count(); ++i) {
    Target t;
    t.array = &c.at(i);
    t.internal = t.array->is_internal();
    if (t.array->type() == typeid(ChannelArray)) t.channel = static_cast<ChannelArray*>(t.array);
    out.push_back(t);
  }
  return out;
}

void check_index_range(std::size_t vertices, std::size_t edges, std::size_t faces) {
  const std::size_t limit = std::numeric_limits<Index>::max() - 1;
  if (vertices > limit || 2 * edges > limit || faces > limit)
    throw Error("subdivide: the result would have more elements than 32-bit indices can number");
}

void copy_parents(PropertyContainer from, PropertyContainer& to, std::size_t default_slot,
                  const std::vector<Index>& map, std::size_t size) {
  if (from.count()) {
    from.resize(default_slot + 1);
    from.permute(map);
  } else {
    from.resize(size);
  }
  to = std::move(from);
}

Region selected_region(const Mesh& m) {
  Region r;
  r.face = detail::selected_faces(m);
  r.vertex = detail::inside_selection(m, r.face);
  r.edge.assign(m.edges_size(), 0);
  for (Edge e : m.edges()) {
    bool open = true;
    for (unsigned side = 0; side < 2; ++side)
      if (const Face f = m.face(e, side); f.is_valid() && !r.face[f.idx()]) open = false;
    r.edge[e.idx()] = open;
  }
  // Copies of one input edge (build() split a non-manifold edge) are welded back into one by
  // extract(): split one and not another, and the weld would meet a T-junction. They open
  // together or not at all.
  const auto* source = m.vertex_properties().get<std::uint32_t>(provenance::kVertexSource);
  if (!source) return r;
  std::vector<std::tuple<std::uint32_t, std::uint32_t, Index>> welded;  // (sources of the ends, edge)
  for (Edge e : m.edges()) {
    const std::uint32_t a = source->vector()[m.vertex(e, 0).idx()], b = source->vector()[m.vertex(e, 1).idx()];
    if (a != kInvalidIndex && b != kInvalidIndex) welded.emplace_back(std::min(a, b), std::max(a, b), e.idx());
  }
  std::sort(welded.begin(), welded.end());
  for (std::size_t i = 0; i < welded.size();) {
    std::size_t j = i + 1;
    bool open = r.edge[std::get<2>(welded[i])];
    for (; j < welded.size() && std::get<0>(welded[j]) == std::get<0>(welded[i]) &&
           std::get<1>(welded[j]) == std::get<1>(welded[i]);
         ++j)
      open = open && r.edge[std::get<2>(welded[j])];
    for (std::size_t k = i; k < j; ++k) r.edge[std::get<2>(welded[k])] = open;
    i = j;
  }
  return r;
}

void drop_unlinked(Mesh& m, Index old_vertices, std::vector<bool>& crease) {
  std::vector<Index> keep_v, keep_e, keep_f;
  std::vector<Index> new_v(m.vertices_size(), kInvalidIndex), new_f(m.faces_size(), kInvalidIndex);
  for (Index v = 0; v < m.vertices_size(); ++v)
    if (v < old_vertices || m.halfedge(Vertex(v)).is_valid()) {
      new_v[v] = Index(keep_v.size());
      keep_v.push_back(v);
    }
  for (Index e = 0; e < m.edges_size(); ++e)
    if (m.to_vertex(Mesh::halfedge(Edge(e), 0)).is_valid()) keep_e.push_back(e);
  for (Index f = 0; f < m.faces_size(); ++f)
    if (m.halfedge(Face(f)).is_valid()) {
      new_f[f] = Index(keep_f.size());
      keep_f.push_back(f);
    }
  if (keep_v.size() == m.vertices_size() && keep_e.size() == m.edges_size() && keep_f.size() == m.faces_size()) return;
  std::vector<Index> keep_h, new_h(m.halfedges_size(), kInvalidIndex);
  for (Index e : keep_e)
    for (Index side = 0; side < 2; ++side) {
      new_h[2 * e + side] = Index(keep_h.size());
      keep_h.push_back(2 * e + side);
    }
  auto map_h = [&](Halfedge h) { return h.is_valid() ? Halfedge(new_h[h.idx()]) : h; };

  Mesh out;
  out.resize_unset(keep_v.size(), keep_e.size(), keep_f.size());
  for (Index i = 0; i < keep_h.size(); ++i) {
    const Halfedge h(keep_h[i]);
    const Face f = m.face(h);
    out.set_vertex(Halfedge(i), Vertex(new_v[m.to_vertex(h).idx()]));
    out.set_face(Halfedge(i), f.is_valid() ? Face(new_f[f.idx()]) : f);
    out.set_next(Halfedge(i), map_h(m.next(h)));
  }
  for (Index i = 0; i < keep_v.size(); ++i) {
    out.set_halfedge(Vertex(i), map_h(m.halfedge(Vertex(keep_v[i]))));
    out.position(Vertex(i)) = m.position(Vertex(keep_v[i]));
  }
  for (Index i = 0; i < keep_f.size(); ++i) out.set_halfedge(Face(i), map_h(m.halfedge(Face(keep_f[i]))));
  auto gather = [](PropertyContainer& from, PropertyContainer& to, const std::vector<Index>& keep) {
    from.permute(keep);
    to = std::move(from);
  };
  gather(m.vertex_properties(), out.vertex_properties(), keep_v);
  gather(m.halfedge_properties(), out.halfedge_properties(), keep_h);
  gather(m.edge_properties(), out.edge_properties(), keep_e);
  gather(m.face_properties(), out.face_properties(), keep_f);
  if (!crease.empty()) {
    std::vector<bool> kept(keep_e.size());
    for (std::size_t i = 0; i < keep_e.size(); ++i) kept[i] = crease[keep_e[i]];
    crease = std::move(kept);
  }
  m = std::move(out);
}

std::vector<bool> detect_creases(const Mesh& m, double degrees) {
  const std::vector<Vec3f> normal = face_normals(m);
  std::vector<bool> crease(m.edges_size(), false);
  for (Edge e : m.edges()) {
    if (m.is_boundary(e)) continue;
    const Vec3d n0 = to_double(normal[m.face(Mesh::halfedge(e, 0)).idx()]);
    const Vec3d n1 = to_double(normal[m.face(Mesh::halfedge(e, 1)).idx()]);
    if (sqrnorm(n0) == 0 || sqrnorm(n1) == 0) continue;
    crease[e.idx()] = angle_between(n0, n1) * 180.0 / std::numbers::pi > degrees;
  }
  return crease;
}

std::vector<bool> split_creases(const std::vector<bool>& crease, std::size_t edges_after) {
  std::vector<bool> next(edges_after, false);
  for (std::size_t e = 0; e < crease.size(); ++e) next[2 * e] = next[2 * e + 1] = crease[e];
  return next;
}

}  // namespace hedge::subdivision
