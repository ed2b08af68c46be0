// What the subdivision steps share (subdivide.cpp): stencils, the refinement of vertex and
// corner properties into fresh arrays, the weight formulas and the creases. Private to the core.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <numbers>
#include <span>
#include <utility>
#include <vector>

#include "hedge/mesh.h"
#include "hedge/progress.h"
#include "hedge/subdivide.h"
#include "parallel.h"

namespace hedge::subdivision {

//! One subdivision stencil: the new value is sum weight[i] * old[index[i]]. Rings up to 32
//! neighbours stay in the object; bigger ones spill to the heap.
class Stencil {
 public:
  Stencil() = default;
  Stencil(const Stencil&) = delete;
  Stencil& operator=(const Stencil&) = delete;
  void clear() { size_ = 0; }
  // Inlined into the stencil loops (it runs once per weight); growing is rare and kept apart.
  [[gnu::always_inline]] void add(Index i, float w) {
    if (size_ == capacity_) [[unlikely]]
      grow();
    index_[size_] = i;
    weight_[size_] = w;
    ++size_;
  }
  std::size_t size() const { return size_; }
  std::span<const Index> index() const { return {index_, size_}; }
  std::span<const float> weight() const { return {weight_, size_}; }
  Index index(std::size_t i) const { return index_[i]; }
  float& weight(std::size_t i) { return weight_[i]; }
  float weight(std::size_t i) const { return weight_[i]; }

 private:
  [[gnu::noinline]] void grow() {
    capacity_ *= 2;
    std::vector<Index> index(capacity_);
    std::vector<float> weight(capacity_);
    std::copy(index_, index_ + size_, index.begin());
    std::copy(weight_, weight_ + size_, weight.begin());
    heap_index_.swap(index);
    heap_weight_.swap(weight);
    index_ = heap_index_.data();
    weight_ = heap_weight_.data();
  }
  static constexpr std::size_t kInline = 64;
  Index inline_index_[kInline];
  float inline_weight_[kInline];
  std::vector<Index> heap_index_;
  std::vector<float> heap_weight_;
  Index* index_ = inline_index_;
  float* weight_ = inline_weight_;
  std::size_t size_ = 0, capacity_ = kInline;
};

//! A property array, with its channel view resolved once: host channels (the common case)
//! blend through detail::blend_element directly, other arrays through interpolate().
struct Target {
  PropertyArray* array = nullptr;
  ChannelArray* channel = nullptr;  // the same array when it is a channel: a direct, inlinable call
  bool internal = false;
};

//! std::vector<bool> packs elements into shared words: such arrays must be written by one
//! thread only.
unsigned threads_for(const std::vector<Target>& all, unsigned threads);

std::vector<Target> targets(PropertyContainer& c);

// Inline: it runs once per element and array, inside the stencil loops.
inline void blend(const Target& t, std::size_t to, std::span<const Index> index, std::span<const float> weight) {
  if (t.channel)
    detail::blend_element(*t.channel, index, weight, t.channel->element(to));
  else
    t.array->interpolate(to, index, weight);
}

// Half-edge h (edge e, side s) is cut at the edge point into first(h) (from its origin to
// the edge point) and second(h) (from the edge point to its target). The halves of edge e are
// new edges 2e (at vertex(e, 1), the origin of side 0) and 2e + 1.
constexpr Halfedge first_half(Halfedge h) { return Halfedge((h.idx() & 1u) ? 2 * h.idx() + 1 : 2 * h.idx()); }
constexpr Halfedge second_half(Halfedge h) { return Halfedge((h.idx() & 1u) ? 2 * h.idx() - 1 : 2 * h.idx() + 2); }

//! Throws when a step's result would have more elements than 32-bit indices can number.
void check_index_range(std::size_t vertices, std::size_t edges, std::size_t faces);

//! Number of corners of f, walking the loop directly (hot: called for every face).
inline Index face_size(const Mesh& m, Face f) {
  const Halfedge start = m.halfedge(f);
  Index n = 1;
  for (Halfedge h = m.next(start); h != start; h = m.next(h)) ++n;
  return n;
}

// The formulas stay inline so that tabulated() computes its table where it is instantiated.
inline double loop_beta_formula(std::size_t n) {
  const double c = 3.0 / 8.0 + 0.25 * std::cos(2.0 * std::numbers::pi / double(n));
  return (5.0 / 8.0 - c * c) / double(n);
}

//! Kobbelt's alpha(n) = (4 - 2 cos(2 pi / n)) / 9, the weight a √3 vertex gives its ring.
inline double sqrt3_alpha_formula(std::size_t n) {
  return (4.0 - 2.0 * std::cos(2.0 * std::numbers::pi / double(n))) / 9.0;
}

//! Formula(n), common valences from a table made once (no cosine per vertex).
template <double (*Formula)(std::size_t)>
double tabulated(std::size_t n) {
  static const auto table = [] {
    std::array<double, 33> t{};
    for (std::size_t k = 1; k < t.size(); ++k) t[k] = Formula(k);
    return t;
  }();
  return n < table.size() ? table[n] : Formula(n);
}

//! Loop's beta(n) = (5/8 - (3/8 + cos(2 pi / n) / 4)^2) / n.
inline double loop_beta(std::size_t n) { return tabulated<loop_beta_formula>(n); }

//! New vertices of a step: old vertices keep their indices, added vertices follow at
//! V, V+1, ... Stencils index old vertices (< V) by their old values and added vertices by
//! their new ones, so added vertices are computed in `phases` (ranges of added indices, in
//! order) before the old vertices' stencils that may read them.
struct VertexRule {
  Index V = 0, added = 0;
  std::vector<std::pair<Index, Index>> phases;  // [begin, end) of added indices
};

//! Positions and vertex properties of a step. added(k, stencil) and even(v, stencil) fill the
//! stencils of added vertex k and old vertex v.
template <class Added, class Even>
void refine_vertices(const Mesh& m, Mesh& out, const VertexRule& rule, unsigned threads, Added added, Even even) {
  const Index V = rule.V, N = rule.added;
  const std::vector<Point>& old_p = m.positions();
  std::vector<Point>& p = out.positions();
  auto position = [&](const Stencil& s) {
    float x = 0, y = 0, z = 0;
    for (std::size_t i = 0; i < s.size(); ++i) {
      const Index j = s.index(i);
      const Point& q = j < V ? old_p[j] : p[j];
      const float w = s.weight(i);
      x += w * q[0];
      y += w * q[1];
      z += w * q[2];
    }
    return Point{{x, y, z}};
  };
  // Properties: slots [0, V) old values, [V, V + N) the added vertices, [V + N, 2V + N) the old
  // vertices' new values; the final order is a gather.
  PropertyContainer props = m.vertex_properties();
  std::vector<Target> all;
  if (props.count()) {
    props.resize(std::size_t(2) * V + N);
    all = targets(props);
  }
  // Each stencil is made once and feeds the position and the properties, unless the
  // properties must be written by one thread (then they take a pass of their own).
  auto pass = [&](bool positions, bool properties, unsigned t) {
    for (const auto& phase : rule.phases)
      parallel_for(phase.second - phase.first, t, [&, b = phase.first](std::size_t lo, std::size_t hi) {
        Stencil s;
        for (std::size_t k = b + lo; k < b + hi; ++k) {
          s.clear();
          added(Index(k), s);
          if (positions) p[V + k] = position(s);
          if (properties)
            for (const Target& x : all)
              if (!x.internal) blend(x, V + k, s.index(), s.weight());  // new vertices: no bookkeeping
        }
      });
    parallel_for(V, t, [&](std::size_t lo, std::size_t hi) {
      Stencil s;
      for (std::size_t v = lo; v < hi; ++v) {
        s.clear();
        even(Vertex(Index(v)), s);
        // A vertex that stays is copied, bit for bit (a blend would turn -0 into +0).
        const bool stays = s.size() == 1 && s.index(0) == v && s.weight(0) == 1.0f;
        if (positions) p[v] = stays ? old_p[v] : position(s);
        if (properties)
          for (const Target& x : all) {
            if (x.internal || stays)
              x.array->copy_element(v, V + N + v);
            else
              blend(x, V + N + v, s.index(), s.weight());
          }
      }
    });
  };
  const unsigned property_threads = threads_for(all, threads);
  if (all.empty() || property_threads == threads) {
    pass(true, !all.empty(), threads);
  } else {
    pass(true, false, threads);
    pass(false, true, property_threads);
  }

  if (!all.empty()) {
    std::vector<Index> order(std::size_t(V) + N);
    for (Index v = 0; v < V; ++v) order[v] = V + N + v;
    for (Index k = 0; k < N; ++k) order[V + k] = V + k;
    props.permute(order);
  } else {
    props.resize(std::size_t(V) + N);
  }
  out.vertex_properties() = std::move(props);
}

//! Corner properties: slots [0, H) the old corners, then `extra` slots filled by fill(slot
//! offset, array) for blended corners; the new half-edges gather from `map`.
template <class Fill>
void refine_corners(const Mesh& m, Mesh& out, std::size_t extra, const std::vector<Index>& map, unsigned threads,
                    Fill fill) {
  PropertyContainer props = m.halfedge_properties();
  if (props.count()) {
    const std::size_t H = m.halfedges_size();
    props.resize(H + extra + 1);  // the last slot keeps the defaults (boundary corners)
    std::vector<Target> all = targets(props);
    std::vector<Target> blended;
    for (const Target& t : all)
      if (!t.internal) blended.push_back(t);
    if (!blended.empty()) fill(blended, threads_for(blended, threads));
    props.permute(map);
  } else {
    props.resize(out.halfedges_size());
  }
  out.halfedge_properties() = std::move(props);
}

//! The mesh a step writes (V2 vertices, E2 edges, F2 faces, every field still unset) and
//! its maps back to the input: a new half-edge's corner slot (refine_corners), a new edge's
//! old edge, a child face's parent. A map is empty when the input has no properties of its kind.
struct StepOutput {
  Mesh out;
  bool corner_props, edge_props, face_props;
  std::vector<Index> hmap, emap, fmap;

  StepOutput(const Mesh& m, Index V2, Index E2, Index F2)
      : corner_props(m.halfedge_properties().count() > 0),
        edge_props(m.edge_properties().count() > 0),
        face_props(m.face_properties().count() > 0),
        hmap(corner_props ? std::size_t(2) * E2 : 0),
        emap(edge_props ? E2 : 0),
        fmap(face_props ? F2 : 0) {
    out.resize(V2, E2, F2);
  }
};

//! Makes `loop` (half-edges in order) the loop of face t: each one's next and face.
inline void link_loop(Mesh& out, Face t, std::span<const Halfedge> loop) {
  const Halfedge* h = loop.data();
  const std::size_t n = loop.size();
  for (std::size_t i = 0; i < n; ++i) {
    out.set_next(h[i], h[i + 1 == n ? 0 : i + 1]);
    out.set_face(h[i], t);
  }
}
inline void link_loop(Mesh& out, Face t, std::initializer_list<Halfedge> loop) {
  link_loop(out, t, std::span<const Halfedge>(loop.begin(), loop.size()));
}

//! Edge or face properties of a step: each new element copies its parent's (`map`), slot
//! `default_slot` the defaults; `size` new elements when there are no properties.
void copy_parents(PropertyContainer from, PropertyContainer& to, std::size_t default_slot,
                  const std::vector<Index>& map, std::size_t size);

// ---- selection_only ---------------------------------------------------------------------------

//! What one step may change with selection_only (subdivide.h, selection.h). Empty: everything
//! (a run without selection_only), and every test below is true.
struct Region {
  std::vector<std::uint8_t> face;    //!< per face: selected, so refined
  std::vector<std::uint8_t> vertex;  //!< per vertex: every face around it selected, so it may move
  //! Per edge: no unselected face on either side, nor on a copy that extract() welds with it,
  //! so it may be split, flipped or cut. The others are the border and what lies outside it.
  std::vector<std::uint8_t> edge;

  bool all() const { return face.empty(); }
  bool refines(Face f) const { return face.empty() || face[f.idx()]; }
  bool moves(Vertex v) const { return vertex.empty() || vertex[v.idx()]; }
  bool opens(Edge e) const { return edge.empty() || edge[e.idx()]; }
};

//! The region of m's "selected" faces (all flags zero when it has none).
Region selected_region(const Mesh& m);

//! A step with a Region leaves the elements it did not make (the points of unsplit edges, the
//! second halves of unsplit edges, the pieces of unselected faces) with invalid connectivity:
//! removes them, keeping the others in order. Added vertices (index `old_vertices` and up)
//! without a half-edge, edges whose side 0 has no vertex and faces without a half-edge go;
//! `crease` (per edge, empty for none) follows the edges.
void drop_unlinked(Mesh& m, Index old_vertices, std::vector<bool>& crease);

// ---- creases ----------------------------------------------------------------------------------

//! Creases of the input (subdivide.h): interior edges whose faces' normals differ by more than
//! `degrees`. Degenerate faces (zero normal) bend nothing.
std::vector<bool> detect_creases(const Mesh& m, double degrees);

//! The sharp edges at v: its boundary edges and creases (`crease` per edge of m, not empty).
//! How many, and the first two of them as half-edges leaving v.
struct SharpEdges {
  int count = 0;
  Halfedge out[2];
};

inline SharpEdges sharp_edges(const Mesh& m, const std::vector<bool>& crease, Vertex v) {
  SharpEdges sharp;
  for (Halfedge h : m.outgoing(v))
    if (m.is_boundary(Mesh::edge(h)) || crease[Mesh::edge(h).idx()]) {
      if (sharp.count < 2) sharp.out[sharp.count] = h;
      ++sharp.count;
    }
  return sharp;
}

//! After a split step: the two halves of a crease stay creases; interior edges are new and smooth.
std::vector<bool> split_creases(const std::vector<bool>& crease, std::size_t edges_after);

// ---- the steps: each reads m and returns the refined mesh ------------------------------------

//! Loop, Catmull–Clark and midpoint (subdivide_split.cpp): every edge split at an edge point,
//! every face split 1 -> 4 or into quads. `crease`: per edge of m, empty for none (then the
//! rules are exactly the crease-free ones). `region` not all(): only its edges are split and
//! its faces refined (closed as subdivide.h says); the result then needs drop_unlinked().
Mesh split_step(const Mesh& m, SubdivisionScheme scheme, const std::vector<bool>& crease, const Region& region,
                unsigned threads, Progress& progress, double from, double to);

//! √3 (subdivide_sqrt3.cpp): a vertex per face, then every interior old edge flipped; every
//! second step (`trisect`) cuts boundary edges and creases in three. `crease`: per edge of m,
//! empty for none; on return per edge of the result. `region` not all(): only its faces are
//! split and its edges flipped or cut; the result then needs drop_unlinked().
Mesh sqrt3_step(const Mesh& m, bool trisect, std::vector<bool>& crease, const Region& region, unsigned threads,
                Progress& progress, double from, double to);

}  // namespace hedge::subdivision
