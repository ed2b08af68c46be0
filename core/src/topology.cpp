// Topology counts by one pass over the elements and a union-find over vertices.
#include "hedge/topology.h"

#include <algorithm>
#include <numeric>
#include <vector>

#include "hedge/provenance.h"

namespace hedge {
namespace {

class UnionFind {
 public:
  explicit UnionFind(std::size_t n) : parent_(n) { std::iota(parent_.begin(), parent_.end(), Index(0)); }
  Index find(Index i) {
    while (parent_[i] != i) {
      parent_[i] = parent_[parent_[i]];
      i = parent_[i];
    }
    return i;
  }
  void unite(Index a, Index b) {
    a = find(a);
    b = find(b);
    if (a != b) parent_[std::max(a, b)] = std::min(a, b);
  }

 private:
  std::vector<Index> parent_;
};

}  // namespace

TopologyStats topology_stats(const Mesh& mesh) {
  TopologyStats s;
  s.vertices = mesh.n_vertices();
  s.edges = mesh.n_edges();
  s.faces = mesh.n_faces();
  s.halfedges = mesh.n_halfedges();

  UnionFind sets(mesh.vertices_size());
  for (Edge e : mesh.edges()) sets.unite(mesh.vertex(e, 0).idx(), mesh.vertex(e, 1).idx());
  for (Vertex v : mesh.vertices()) {
    if (mesh.is_isolated(v))
      ++s.isolated_vertices;
    else if (sets.find(v.idx()) == v.idx())
      ++s.components;
  }

  std::vector<bool> visited(mesh.halfedges_size(), false);
  for (Halfedge h : mesh.halfedges()) {
    if (!mesh.is_boundary(h)) continue;
    ++s.boundary_edges;
    if (visited[h.idx()]) continue;
    ++s.boundary_loops;
    for (Halfedge b : mesh.loop(h)) visited[b.idx()] = true;
  }

  s.euler_characteristic = static_cast<std::int64_t>(s.vertices - s.isolated_vertices) -
                           static_cast<std::int64_t>(s.edges) + static_cast<std::int64_t>(s.faces);
  s.genus = (2 * static_cast<std::int64_t>(s.components) - static_cast<std::int64_t>(s.boundary_loops) -
             s.euler_characteristic) /
            2;
  return s;
}

std::size_t face_components(const Mesh& mesh, std::vector<Index>& component_of_face) {
  component_of_face.assign(mesh.faces_size(), kInvalidIndex);
  std::vector<Face> stack;
  Index next_id = 0;
  for (Face seed : mesh.faces()) {
    if (component_of_face[seed.idx()] != kInvalidIndex) continue;
    component_of_face[seed.idx()] = next_id;
    stack.push_back(seed);
    while (!stack.empty()) {
      Face f = stack.back();
      stack.pop_back();
      for (Face g : mesh.faces(f))
        if (component_of_face[g.idx()] == kInvalidIndex) {
          component_of_face[g.idx()] = next_id;
          stack.push_back(g);
        }
    }
    ++next_id;
  }
  return next_id;
}

std::vector<std::uint64_t> welded_vertex_ids(const Mesh& mesh) {
  const auto* source = mesh.vertex_properties().get<std::uint32_t>(provenance::kVertexSource);
  if (!source) return {};
  const std::uint64_t n = mesh.vertices_size();
  std::vector<std::uint64_t> welded(n);
  for (Index v = 0; v < n; ++v) {
    const std::uint32_t s = source->vector()[v];
    welded[v] = s != kInvalidIndex ? s : n + v;
  }
  return welded;
}

std::vector<bool> split_seam_edges(const Mesh& mesh) {
  const std::vector<std::uint64_t> welded = welded_vertex_ids(mesh);
  if (welded.empty()) return {};
  const std::uint64_t n = mesh.vertices_size();
  auto key = [&](Halfedge h) {
    std::uint64_t a = welded[mesh.from_vertex(h).idx()], b = welded[mesh.to_vertex(h).idx()];
    if (a > b) std::swap(a, b);
    return a * 2 * n + b;  // a, b < 2n
  };
  std::vector<std::uint64_t> face_sides;  // one key per face side of every edge
  for (Halfedge h : mesh.halfedges())
    if (!mesh.is_boundary(h)) face_sides.push_back(key(h));
  std::sort(face_sides.begin(), face_sides.end());
  std::vector<bool> seam(mesh.edges_size(), false);
  for (Edge e : mesh.edges()) {
    if (!mesh.is_boundary(e)) continue;
    auto [lo, hi] = std::equal_range(face_sides.begin(), face_sides.end(), key(Mesh::halfedge(e, 0)));
    seam[e.idx()] = hi - lo >= 2;
  }
  return seam;
}

}  // namespace hedge
