// The half-edge mesh: allocation, queries that walk a neighbourhood, deletion and garbage
// collection. Euler operations live in euler.cpp.
#include "hedge/mesh.h"

#include <algorithm>
#include <cstring>

#include "hedge/error.h"
#include "hedge/limits.h"
#include "parallel.h"

namespace hedge {

void Mesh::clear() { *this = Mesh(); }

void Mesh::reserve(std::size_t vertices, std::size_t edges, std::size_t faces) {
  vertex_halfedge_.reserve(vertices);
  positions_.reserve(vertices);
  vprops_.reserve(vertices);
  halfedges_.reserve(2 * edges);
  hprops_.reserve(2 * edges);
  eprops_.reserve(edges);
  face_halfedge_.reserve(faces);
  fprops_.reserve(faces);
}

void Mesh::shrink_to_fit() {
  vertex_halfedge_.shrink_to_fit();
  positions_.shrink_to_fit();
  halfedges_.shrink_to_fit();
  face_halfedge_.shrink_to_fit();
  vdeleted_.shrink_to_fit();
  edeleted_.shrink_to_fit();
  fdeleted_.shrink_to_fit();
  vprops_.shrink_to_fit();
  hprops_.shrink_to_fit();
  eprops_.shrink_to_fit();
  fprops_.shrink_to_fit();
}

namespace {
// Handles are 32-bit; refuse growth that would wrap an index instead of corrupting.
void check_capacity(std::size_t count, const char* what, std::uint64_t limit = kMaxElements) {
  check_limit("mesh too large", count, limit, what);
}
}  // namespace

Vertex Mesh::new_vertex() {
  check_capacity(vertices_size() + 1, "vertices");
  vertex_halfedge_.push_back(Halfedge());
  positions_.emplace_back();
  vprops_.push_back();
  if (!vdeleted_.empty()) vdeleted_.push_back(0);
  return Vertex(static_cast<Index>(vertices_size() - 1));
}

Halfedge Mesh::new_edge(Vertex from, Vertex to) {
  check_capacity(halfedges_size() + 2, "half-edges", kMaxHalfedges);
  halfedges_.push_back({to, Face(), Halfedge(), Halfedge()});
  halfedges_.push_back({from, Face(), Halfedge(), Halfedge()});
  hprops_.push_back();
  hprops_.push_back();
  eprops_.push_back();
  if (!edeleted_.empty()) edeleted_.push_back(0);
  return Halfedge(static_cast<Index>(halfedges_size() - 2));
}

Face Mesh::new_face() {
  check_capacity(faces_size() + 1, "faces");
  face_halfedge_.push_back(Halfedge());
  fprops_.push_back();
  if (!fdeleted_.empty()) fdeleted_.push_back(0);
  return Face(static_cast<Index>(faces_size() - 1));
}

void Mesh::resize(std::size_t vertices, std::size_t edges, std::size_t faces) {
  const std::size_t v0 = vertices_size(), h0 = halfedges_size(), f0 = faces_size();
  resize_unset(vertices, edges, faces);
  if (vertices > v0) std::fill(vertex_halfedge_.begin() + v0, vertex_halfedge_.end(), Halfedge());
  if (2 * edges > h0) std::fill(halfedges_.begin() + h0, halfedges_.end(), HalfedgeRecord{});
  if (faces > f0) std::fill(face_halfedge_.begin() + f0, face_halfedge_.end(), Halfedge());
}

void Mesh::resize_unset(std::size_t vertices, std::size_t edges, std::size_t faces) {
  check_capacity(vertices, "vertices");
  check_capacity(2 * edges, "half-edges", kMaxHalfedges);
  check_capacity(faces, "faces");
  const std::size_t v0 = vertices_size(), h0 = halfedges_size(), f0 = faces_size();
  vertex_halfedge_.resize(vertices);
  positions_.resize(vertices);
  vprops_.resize(vertices);
  halfedges_.resize(2 * edges);
  hprops_.resize(2 * edges);
  eprops_.resize(edges);
  face_halfedge_.resize(faces);
  fprops_.resize(faces);
  if (!vdeleted_.empty()) vdeleted_.resize(vertices, 0);
  if (!edeleted_.empty()) edeleted_.resize(edges, 0);
  if (!fdeleted_.empty()) fdeleted_.resize(faces, 0);
#ifndef NDEBUG
  // Debug builds poison what was left unset, so a builder that misses a field fails validate().
  const Index poison = 0x5a5a5a5au;
  if (vertices > v0) std::fill(vertex_halfedge_.begin() + v0, vertex_halfedge_.end(), Halfedge(poison));
  if (2 * edges > h0)
    std::fill(halfedges_.begin() + h0, halfedges_.end(),
              HalfedgeRecord{Vertex(poison), Face(poison), Halfedge(poison), Halfedge(poison)});
  if (faces > f0) std::fill(face_halfedge_.begin() + f0, face_halfedge_.end(), Halfedge(poison));
#else
  (void)v0, (void)h0, (void)f0;
#endif
}

void Mesh::adjust_outgoing_halfedge(Vertex v) {
  Halfedge start = halfedge(v);
  if (!start.is_valid()) return;
  Halfedge h = start;
  do {
    if (is_boundary(h)) {
      set_halfedge(v, h);
      return;
    }
    h = ccw_rotated(h);
  } while (h != start);
}

bool Mesh::is_boundary(Face f) const {
  for (Halfedge h : halfedges(f))
    if (is_boundary(opposite(h))) return true;
  return false;
}

std::size_t Mesh::valence(Vertex v) const {
  std::size_t n = 0;
  for ([[maybe_unused]] Halfedge h : outgoing(v)) ++n;
  return n;
}

std::size_t Mesh::valence(Face f) const {
  std::size_t n = 0;
  for ([[maybe_unused]] Halfedge h : halfedges(f)) ++n;
  return n;
}

bool Mesh::is_triangle_mesh() const {
  for (Face f : faces())
    if (valence(f) != 3) return false;
  return true;
}

bool Mesh::is_quad_mesh() const {
  for (Face f : faces())
    if (valence(f) != 4) return false;
  return true;
}

Halfedge Mesh::find_halfedge(Vertex a, Vertex b) const {
  // Both rings hold the edge if it exists: walk them in step, so the cost is
  // O(min(valence(a), valence(b))) and a fan's apex of huge valence stays cheap to query.
  const Halfedge start_a = halfedge(a), start_b = halfedge(b);
  if (!start_a.is_valid() || !start_b.is_valid()) return Halfedge();
  Halfedge ha = start_a, hb = start_b;
  do {
    if (to_vertex(ha) == b) return ha;
    if (to_vertex(hb) == a) return opposite(hb);
    ha = ccw_rotated(ha);
    hb = ccw_rotated(hb);
  } while (ha != start_a && hb != start_b);
  return Halfedge();
}

Edge Mesh::find_edge(Vertex a, Vertex b) const {
  Halfedge h = find_halfedge(a, b);
  return h.is_valid() ? edge(h) : Edge();
}

void Mesh::mark_deleted(Vertex v, Deletions& tally) {
  if (is_deleted(v)) return;
  if (vdeleted_.size() != vertices_size()) vdeleted_.assign(vertices_size(), 0);
  vdeleted_[v.idx()] = 1;
  ++tally.vertices;
}

void Mesh::mark_deleted(Edge e, Deletions& tally) {
  if (is_deleted(e)) return;
  if (edeleted_.size() != edges_size()) edeleted_.assign(edges_size(), 0);
  edeleted_[e.idx()] = 1;
  ++tally.edges;
}

void Mesh::mark_deleted(Face f, Deletions& tally) {
  if (is_deleted(f)) return;
  if (fdeleted_.size() != faces_size()) fdeleted_.assign(faces_size(), 0);
  fdeleted_[f.idx()] = 1;
  ++tally.faces;
}

void Mesh::prepare_deletion_marks() {
  if (vdeleted_.size() != vertices_size()) vdeleted_.assign(vertices_size(), 0);
  if (edeleted_.size() != edges_size()) edeleted_.assign(edges_size(), 0);
  if (fdeleted_.size() != faces_size()) fdeleted_.assign(faces_size(), 0);
}

void Mesh::add_deletions(const Deletions& tally) {
  deleted_.vertices += tally.vertices;
  deleted_.edges += tally.edges;
  deleted_.faces += tally.faces;
}

void Mesh::delete_face(Face f) {
  if (is_deleted(f)) return;
  mark_deleted(f);

  // The face's half-edges become boundary; edges with no face left on either side go,
  // and so do vertices that end up with no edge.
  std::vector<Halfedge> loop;
  std::vector<Edge> dead_edges;
  std::vector<Vertex> touched;
  for (Halfedge h : halfedges(f)) {
    loop.push_back(h);
    touched.push_back(to_vertex(h));
  }
  for (Halfedge h : loop) {
    set_face(h, Face());
    if (is_boundary(opposite(h))) dead_edges.push_back(edge(h));
  }

  for (Edge e : dead_edges) {
    Halfedge h0 = halfedge(e, 0), h1 = halfedge(e, 1);
    Vertex v0 = to_vertex(h0), v1 = to_vertex(h1);
    Halfedge next0 = next(h0), prev0 = prev(h0);
    Halfedge next1 = next(h1), prev1 = prev(h1);
    // Unlink the edge from both loops; keep the vertices' outgoing half-edges valid.
    set_next(prev0, next1);
    set_next(prev1, next0);
    if (halfedge(v0) == h1) set_halfedge(v0, next0 == h1 ? Halfedge() : next0);
    if (halfedge(v1) == h0) set_halfedge(v1, next1 == h0 ? Halfedge() : next1);
    mark_deleted(e);
  }

  for (Vertex v : touched) {
    if (!halfedge(v).is_valid())
      mark_deleted(v);
    else
      adjust_outgoing_halfedge(v);
  }
}

void Mesh::delete_edge(Edge e) {
  Face f0 = face(e, 0), f1 = face(e, 1);
  if (f0.is_valid()) delete_face(f0);
  if (f1.is_valid()) delete_face(f1);
}

void Mesh::delete_vertex(Vertex v) {
  if (is_deleted(v)) return;
  std::vector<Face> around;
  for (Face f : faces(v)) around.push_back(f);
  for (Face f : around) delete_face(f);
  if (!is_deleted(v) && is_isolated(v)) mark_deleted(v);
}

namespace {
// data[i] becomes data[new_to_old[i]], and each element x then f(x), on all threads.
template <class Array, class F>
void gather(Array& data, std::span<const Index> new_to_old, F f) {
  Array out(new_to_old.size());
  parallel_for(new_to_old.size(), 0, [&](std::size_t begin, std::size_t end) {
    detail::gather_ahead(
        new_to_old.data(), begin, end, [&](Index j) { return &data[j]; },
        [&](std::size_t i, Index j) { out[i] = f(data[j]); });
  });
  data.swap(out);
}

// maps: old -> new for every old element, invalid for those not kept.
void fill_maps(GarbageMaps& maps, std::span<const Index> vkeep, std::span<const Index> ekeep,
               std::span<const Index> fkeep, std::size_t n_vertices, std::size_t n_edges, std::size_t n_faces) {
  auto old_to_new = [](std::vector<Index>& map, std::size_t n, std::span<const Index> keep) {
    map.assign(n, kInvalidIndex);
    for (std::size_t i = 0; i < keep.size(); ++i) map[keep[i]] = static_cast<Index>(i);
  };
  old_to_new(maps.vertices, n_vertices, vkeep);
  old_to_new(maps.edges, n_edges, ekeep);
  old_to_new(maps.faces, n_faces, fkeep);
}

// Old -> new indices through maps over every old element.
struct ThroughMaps {
  const GarbageMaps& maps;
  Index vertex(Index i) const { return maps.vertices[i]; }
  Index edge(Index i) const { return maps.edges[i]; }
  Index face(Index i) const { return maps.faces[i]; }
};

// Bits set in a word, without the popcnt instruction the baseline x86-64 target lacks.
inline unsigned count_bits(std::uint64_t x) {
  x -= (x >> 1) & 0x5555555555555555ull;
  x = (x & 0x3333333333333333ull) + ((x >> 2) & 0x3333333333333333ull);
  x = (x + (x >> 4)) & 0x0f0f0f0f0f0f0f0full;
  return unsigned((x * 0x0101010101010101ull) >> 56);
}

// The live elements of one kind as a bit per element (set: live), 64 to a word, with the
// number of live elements before each word: an element's new index when the live elements
// keep their order is that count plus the live bits below it in its word.
class LiveSet {
 public:
  // deleted: the deletion marks (bytes of 0 or 1), or empty when nothing of this kind was
  // deleted; n: how many elements there are.
  LiveSet(const std::vector<std::uint8_t>& deleted, std::size_t n) : n_(n) {
    const std::size_t words = (n + 63) / 64;
    words_.resize(words);
    parallel_for(
        words, 0,
        [&](std::size_t begin, std::size_t end) {
          for (std::size_t w = begin; w < end; ++w) words_[w] = live_bits(deleted, w);
        },
        4096);
    before_.resize(words + 1);
    Index live = 0;
    for (std::size_t w = 0; w < words; ++w) {
      before_[w] = live;
      live += count_bits(words_[w]);
    }
    before_[words] = live;
  }

  std::size_t size() const { return before_.back(); }
  bool contains(Index i) const { return (words_[i >> 6] >> (i & 63)) & 1; }
  Index rank(Index old) const {
    const std::uint64_t below = (std::uint64_t(1) << (old & 63)) - 1;
    return before_[old >> 6] + count_bits(words_[old >> 6] & below);
  }
  // The live elements in index order.
  std::vector<Index> elements() const {
    std::vector<Index> out(size());
    parallel_for(
        words_.size(), 0,
        [&](std::size_t begin, std::size_t end) {
          for (std::size_t w = begin; w < end; ++w) {
            Index* at = out.data() + before_[w];
            for (std::uint64_t bits = words_[w]; bits; bits &= bits - 1)
              *at++ = Index(w * 64 + unsigned(__builtin_ctzll(bits)));
          }
        },
        4096);
    return out;
  }

 private:
  // Word w's live bits: eight deletion bytes at a time gathered into eight bits by one
  // multiplication (each byte's low bit lands in the top byte at its own place), inverted.
  std::uint64_t live_bits(const std::vector<std::uint8_t>& deleted, std::size_t w) const {
    const std::size_t begin = w * 64, end = std::min(begin + 64, n_);
    const std::uint64_t all = end - begin == 64 ? ~std::uint64_t(0) : (std::uint64_t(1) << (end - begin)) - 1;
    if (deleted.empty()) return all;
    std::uint64_t dead = 0;
    std::size_t i = begin;
    for (; i + 8 <= end; i += 8) {
      std::uint64_t bytes;
      std::memcpy(&bytes, deleted.data() + i, sizeof bytes);
      dead |= ((bytes * 0x0102040810204080ull) >> 56) << (i - begin);
    }
    for (; i < end; ++i) dead |= std::uint64_t(deleted[i]) << (i - begin);
    return ~dead & all;
  }

  std::size_t n_;
  std::vector<std::uint64_t> words_;
  std::vector<Index> before_;
};

// The live vertices, edges and faces; old -> new by rank.
struct LiveSets {
  LiveSet vertices, edges, faces;
  Index vertex(Index i) const { return vertices.rank(i); }
  Index edge(Index i) const { return edges.rank(i); }
  Index face(Index i) const { return faces.rank(i); }
};
}  // namespace

GarbageMaps Mesh::garbage_collect() {
  GarbageMaps maps;
  if (!has_garbage()) {
    auto identity = [](std::vector<Index>& map, std::size_t n) {
      map.resize(n);
      for (std::size_t i = 0; i < n; ++i) map[i] = static_cast<Index>(i);
    };
    identity(maps.vertices, vertices_size());
    identity(maps.edges, edges_size());
    identity(maps.faces, faces_size());
    return maps;
  }
  const LiveSets live{LiveSet(vdeleted_, vertices_size()), LiveSet(edeleted_, edges_size()),
                      LiveSet(fdeleted_, faces_size())};
  // Old -> new for every old element, invalid for the deleted.
  auto old_to_new = [](std::vector<Index>& map, const LiveSet& set, std::size_t n) {
    map.resize(n);
    parallel_for(n, 0, [&](std::size_t begin, std::size_t end) {
      for (std::size_t i = begin; i < end; ++i) map[i] = set.contains(Index(i)) ? set.rank(Index(i)) : kInvalidIndex;
    });
  };
  old_to_new(maps.vertices, live.vertices, vertices_size());
  old_to_new(maps.edges, live.edges, edges_size());
  old_to_new(maps.faces, live.faces, faces_size());
  renumber(live.vertices.elements(), live.edges.elements(), live.faces.elements(), live);
  return maps;
}

void Mesh::compact() {
  if (!has_garbage()) return;
  const LiveSets live{LiveSet(vdeleted_, vertices_size()), LiveSet(edeleted_, edges_size()),
                      LiveSet(fdeleted_, faces_size())};
  renumber(live.vertices.elements(), live.edges.elements(), live.faces.elements(), live);
}

GarbageMaps Mesh::reorder(std::span<const Index> vertex_order, std::span<const Index> edge_order,
                          std::span<const Index> face_order) {
  // Each order must name every live element once, and nothing else.
  auto check = [](std::span<const Index> order, std::size_t n, std::size_t live, auto is_deleted, const char* what) {
    if (order.size() != live)
      throw Error(std::string("reorder: the ") + what + " order lists " + std::to_string(order.size()) + " " + what +
                  "; the mesh has " + std::to_string(live));
    std::vector<std::uint8_t> seen(n, 0);
    for (Index i : order) {
      if (i >= n || is_deleted(i) || seen[i])
        throw Error(std::string("reorder: the ") + what + " order names " + what + " " + std::to_string(i) + ", " +
                    (i >= n    ? "which does not exist"
                     : seen[i] ? "twice"
                               : "which is deleted"));
      seen[i] = 1;
    }
  };
  check(
      vertex_order, vertices_size(), n_vertices(), [&](Index i) { return is_deleted(Vertex(i)); }, "vertices");
  check(
      edge_order, edges_size(), n_edges(), [&](Index i) { return is_deleted(Edge(i)); }, "edges");
  check(
      face_order, faces_size(), n_faces(), [&](Index i) { return is_deleted(Face(i)); }, "faces");
  GarbageMaps maps;
  fill_maps(maps, vertex_order, edge_order, face_order, vertices_size(), edges_size(), faces_size());
  renumber(vertex_order, edge_order, face_order, ThroughMaps{maps});
  return maps;
}

template <class Renumbered>
void Mesh::renumber(std::span<const Index> vkeep, std::span<const Index> ekeep, std::span<const Index> fkeep,
                    const Renumbered& renumbered) {
  std::vector<Index> hkeep(2 * ekeep.size());
  parallel_for(ekeep.size(), 0, [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
      hkeep[2 * i] = 2 * ekeep[i];
      hkeep[2 * i + 1] = 2 * ekeep[i] + 1;
    }
  });

  // Live elements refer only to live elements.
  auto map_h = [&](Halfedge h) {
    return h.is_valid() ? Halfedge(2 * renumbered.edge(h.idx() >> 1) + (h.idx() & 1)) : h;
  };
  auto map_v = [&](Vertex v) { return v.is_valid() ? Vertex(renumbered.vertex(v.idx())) : v; };
  auto map_f = [&](Face f) { return f.is_valid() ? Face(renumbered.face(f.idx())) : f; };

  gather(vertex_halfedge_, vkeep, map_h);
  gather(positions_, vkeep, [](const Point& p) { return p; });
  gather(halfedges_, hkeep, [&](HalfedgeRecord r) {
    r.vertex = map_v(r.vertex);
    r.face = map_f(r.face);
    r.next = map_h(r.next);
    r.prev = map_h(r.prev);
    return r;
  });
  gather(face_halfedge_, fkeep, map_h);

  vprops_.permute(vkeep);
  hprops_.permute(hkeep);
  eprops_.permute(ekeep);
  fprops_.permute(fkeep);

  vdeleted_.clear();
  edeleted_.clear();
  fdeleted_.clear();
  deleted_ = {};
}

std::size_t Mesh::heap_bytes() const {
  return halfedges_.capacity() * sizeof(HalfedgeRecord) + vertex_halfedge_.capacity() * sizeof(Halfedge) +
         face_halfedge_.capacity() * sizeof(Halfedge) + positions_.capacity() * sizeof(Point) + vdeleted_.capacity() +
         edeleted_.capacity() + fdeleted_.capacity() + vprops_.heap_bytes() + hprops_.heap_bytes() +
         eprops_.heap_bytes() + fprops_.heap_bytes();
}

}  // namespace hedge
