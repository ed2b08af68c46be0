// Subdivision surfaces (subdivide.h). Every step writes the refined mesh into fresh arrays:
// each child half-edge, edge and face has an index computed from its parent's, so building
// the connectivity needs no search and no Euler operation, and the stencils run on two threads.
#include "hedge/subdivide.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <exception>
#include <limits>
#include <numbers>
#include <string>
#include <thread>
#include <tuple>
#include <typeinfo>
#include <vector>

#include "binding.h"
#include "hedge/error.h"
#include "hedge/limits.h"
#include "hedge/normals.h"
#include "hedge/provenance.h"
#include "hedge/topology.h"
#include "parallel.h"
#include "welded_copies.h"

namespace hedge {
namespace {

// ---- tools --------------------------------------------------------------------------------

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

void blend(const Target& t, std::size_t to, std::span<const Index> index, std::span<const float> weight) {
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

void check_index_range(std::size_t vertices, std::size_t edges, std::size_t faces) {
  const std::size_t limit = std::numeric_limits<Index>::max() - 1;
  if (vertices > limit || 2 * edges > limit || faces > limit)
    throw Error("subdivide: the result would have more elements than 32-bit indices can number");
}

double loop_beta_formula(std::size_t n) {
  const double c = 3.0 / 8.0 + 0.25 * std::cos(2.0 * std::numbers::pi / double(n));
  return (5.0 / 8.0 - c * c) / double(n);
}

//! Kobbelt's alpha(n) = (4 - 2 cos(2 pi / n)) / 9, the weight a √3 vertex gives its ring.
double sqrt3_alpha_formula(std::size_t n) { return (4.0 - 2.0 * std::cos(2.0 * std::numbers::pi / double(n))) / 9.0; }

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
double loop_beta(std::size_t n) { return tabulated<loop_beta_formula>(n); }

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
        if (positions) p[v] = position(s);
        if (properties)
          for (const Target& x : all) {
            if (x.internal)
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

// ---- Loop, Catmull–Clark, midpoint: split every edge, split every face ----------------------

//! Number of corners of f, walking the loop directly (hot: called for every face).
inline Index face_size(const Mesh& m, Face f) {
  const Halfedge start = m.halfedge(f);
  Index n = 1;
  for (Halfedge h = m.next(start); h != start; h = m.next(h)) ++n;
  return n;
}

//! How each face splits: triangles of Loop and midpoint 1 -> 4 at the edge points; faces of
//! Catmull–Clark and polygons of midpoint into one quad per corner around a face point.
//! On a mesh of triangles split 1 -> 4 (every Loop step) the offsets are arithmetic and no
//! table is built.
struct SplitPlan {
  bool uniform = false;  // all faces are triangles split 1 -> 4
  std::vector<Index>
      face_point;  // per face: index of its face point among the added vertices after the edge points, or invalid
  std::vector<Index> inner_edge;  // per face: first of its new interior edges (counted after the 2E halves)
  std::vector<Index> child_face;  // per face: first child face
  std::vector<Index> face_of_point;
  Index inner_edges = 0, child_faces = 0;

  Index first_inner_edge(Index f) const { return uniform ? 3 * f : inner_edge[f]; }
  Index first_child(Index f) const { return uniform ? 4 * f : child_face[f]; }
  Index point_of_face(Index f) const { return uniform ? kInvalidIndex : face_point[f]; }
};

SplitPlan plan_split(const Mesh& m, SubdivisionScheme scheme) {
  const std::size_t F = m.faces_size();
  SplitPlan plan;
  if (scheme != SubdivisionScheme::catmull_clark) {
    bool any_polygon = false;
    for (Index f = 0; f < F && !any_polygon; ++f) {
      const Halfedge h = m.halfedge(Face(f));
      any_polygon = m.next(m.next(m.next(h))) != h;
    }
    plan.uniform = !any_polygon;
  }
  if (plan.uniform) {
    check_index_range(m.vertices_size() + m.edges_size(), 2 * m.edges_size() + 3 * F, 4 * F);
    plan.inner_edges = Index(3 * F);
    plan.child_faces = Index(4 * F);
    return plan;
  }
  plan.face_point.resize(F);
  plan.inner_edge.resize(F);
  plan.child_face.resize(F);
  std::size_t inner = 0, children = 0;
  for (Index f = 0; f < F; ++f) {
    const std::size_t n = face_size(m, Face(f));
    const bool quads = scheme == SubdivisionScheme::catmull_clark || n != 3;
    plan.inner_edge[f] = Index(inner);
    plan.child_face[f] = Index(children);
    if (quads) {
      plan.face_point[f] = Index(plan.face_of_point.size());
      plan.face_of_point.push_back(f);
      inner += n;
      children += n;
    } else {
      plan.face_point[f] = kInvalidIndex;
      inner += 3;
      children += 4;
    }
  }
  check_index_range(m.vertices_size() + m.edges_size() + plan.face_of_point.size(), 2 * m.edges_size() + inner,
                    children);
  plan.inner_edges = Index(inner);
  plan.child_faces = Index(children);
  return plan;
}

//! Creases of the input (subdivide.h): interior edges whose faces' normals differ by more than
//! `degrees`. Degenerate faces (zero normal) bend nothing.
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

//! The sharp edges at v: its boundary edges and creases (`crease` per edge of m, not empty).
//! How many, and the first two of them as half-edges leaving v.
struct SharpEdges {
  int count = 0;
  Halfedge out[2];
};

SharpEdges sharp_edges(const Mesh& m, const std::vector<bool>& crease, Vertex v) {
  SharpEdges sharp;
  for (Halfedge h : m.outgoing(v))
    if (m.is_boundary(Mesh::edge(h)) || crease[Mesh::edge(h).idx()]) {
      if (sharp.count < 2) sharp.out[sharp.count] = h;
      ++sharp.count;
    }
  return sharp;
}

//! After a split step: the two halves of a crease stay creases; interior edges are new and smooth.
std::vector<bool> split_creases(const std::vector<bool>& crease, std::size_t edges_after) {
  std::vector<bool> next(edges_after, false);
  for (std::size_t e = 0; e < crease.size(); ++e) next[2 * e] = next[2 * e + 1] = crease[e];
  return next;
}

//! `crease`: per edge of m, empty for none (then the rules are exactly the crease-free ones).
Mesh split_step(const Mesh& m, SubdivisionScheme scheme, const std::vector<bool>& crease, unsigned threads,
                Progress& progress, double from, double to) {
  const Index V = Index(m.vertices_size()), E = Index(m.edges_size()), F = Index(m.faces_size());
  const Index H = 2 * E;
  const SplitPlan plan = plan_split(m, scheme);
  const Index FP = Index(plan.face_of_point.size());
  const Index V2 = V + E + FP, E2 = 2 * E + plan.inner_edges, F2 = plan.child_faces;

  Mesh out;
  out.resize(V2, E2, F2);
  const bool corner_props = m.halfedge_properties().count() > 0;
  const bool edge_props = m.edge_properties().count() > 0;
  const bool face_props = m.face_properties().count() > 0;
  // New half-edge -> corner slot (see refine_corners), new edge -> old edge, child -> parent face.
  std::vector<Index> hmap(corner_props ? std::size_t(2) * E2 : 0), emap(edge_props ? E2 : 0), fmap(face_props ? F2 : 0);
  const Index centroid_slot = 2 * H, default_corner = 2 * H + FP;

  // Faces: the halves of their half-edges, the interior edges and the child faces.
  // h[i] points to corner c_i; m_i is the edge point of h[i] (between c_{i-1} and c_i).
  auto split_face = [&](Index f, const Halfedge* h, Index n) {
    const Index ff = plan.first_child(f), ie = 2 * E + plan.first_inner_edge(f);
    auto inner = [&](Index k, unsigned side) { return Halfedge(2 * (ie + k % n) + side); };
    for (Index i = 0; i < n; ++i) {
      out.set_vertex(first_half(h[i]), Vertex(V + Mesh::edge(h[i]).idx()));
      out.set_vertex(second_half(h[i]), m.to_vertex(h[i]));
      if (corner_props) {
        hmap[second_half(h[i]).idx()] = h[i].idx();
        hmap[first_half(h[i]).idx()] = H + h[i].idx();
      }
    }
    const Index point = plan.point_of_face(f);
    if (point == kInvalidIndex) {
      // Corner triangle i: c_i, m_{i+1}, m_i; centre triangle m_0, m_1, m_2. Interior edge i
      // joins m_{i+1} and m_i; its side 0 lies in corner triangle i, side 1 in the centre.
      const Face centre(ff + 3);
      for (Index i = 0; i < 3; ++i) {
        const Index j = i == 2 ? 0 : i + 1;
        const Halfedge a = second_half(h[i]), b = first_half(h[j]), c = inner(i, 0), d = inner(i, 1);
        const Face t(ff + i);
        out.set_next(a, b);
        out.set_next(b, c);
        out.set_next(c, a);
        out.set_face(a, t);
        out.set_face(b, t);
        out.set_face(c, t);
        out.set_halfedge(t, a);
        out.set_vertex(c, Vertex(V + Mesh::edge(h[i]).idx()));
        out.set_vertex(d, Vertex(V + Mesh::edge(h[j]).idx()));
        out.set_face(d, centre);
        out.set_next(d, inner(j, 1));
        if (corner_props) {
          hmap[c.idx()] = H + h[i].idx();
          hmap[d.idx()] = H + h[j].idx();
        }
      }
      out.set_halfedge(centre, inner(2, 1));
      if (face_props)
        for (Index c = 0; c < 4; ++c) fmap[ff + c] = f;
    } else {
      // Quad i: c_i, m_{i+1}, face point, m_i. Interior edge k joins the face point and m_k;
      // its side 0 runs face point -> m_k.
      const Vertex fp(V + E + point);
      for (Index i = 0; i < n; ++i) {
        const Halfedge a = second_half(h[i]), b = first_half(h[(i + 1) % n]), c = inner(i + 1, 1), d = inner(i, 0);
        const Face t(ff + i);
        out.set_next(a, b);
        out.set_next(b, c);
        out.set_next(c, d);
        out.set_next(d, a);
        out.set_face(a, t);
        out.set_face(b, t);
        out.set_face(c, t);
        out.set_face(d, t);
        out.set_halfedge(t, a);
        out.set_vertex(d, Vertex(V + Mesh::edge(h[i]).idx()));
        out.set_vertex(inner(i, 1), fp);
        if (corner_props) {
          hmap[d.idx()] = H + h[i].idx();
          hmap[inner(i, 1).idx()] = centroid_slot + point;
        }
        if (face_props) fmap[ff + i] = f;
      }
      out.set_halfedge(fp, inner(0, 0));
    }
    if (edge_props)
      for (Index k = 0; k < (point == kInvalidIndex ? 3 : n); ++k) emap[ie + k] = E;  // interior edges: defaults
  };
  parallel_for(F, threads, [&](std::size_t lo, std::size_t hi) {
    std::vector<Halfedge> loop;
    for (Index f = Index(lo); f < hi; ++f) {
      const Halfedge h0 = m.halfedge(Face(f)), h1 = m.next(h0), h2 = m.next(h1);
      if (m.next(h2) == h0) {
        const Halfedge h[3] = {h0, h1, h2};
        split_face(f, h, 3);
      } else {
        loop.clear();
        for (Halfedge x : m.halfedges(Face(f))) loop.push_back(x);
        split_face(f, loop.data(), Index(loop.size()));
      }
    }
  });
  progress.update(from + 0.3 * (to - from), "subdividing: connectivity");

  // Edges: boundary half-edges split in two along their hole; edge points' half-edges.
  parallel_for(E, threads, [&](std::size_t lo, std::size_t hi) {
    for (Index e = Index(lo); e < hi; ++e) {
      const Vertex mid(V + e);
      for (unsigned side = 0; side < 2; ++side) {
        const Halfedge h = Mesh::halfedge(Edge(e), side);
        if (!m.is_boundary(h)) continue;
        out.set_vertex(first_half(h), mid);
        out.set_vertex(second_half(h), m.to_vertex(h));
        out.set_next(first_half(h), second_half(h));
        out.set_next(second_half(h), first_half(m.next(h)));
        if (corner_props) {
          hmap[first_half(h).idx()] = default_corner;
          hmap[second_half(h).idx()] = h.idx();
        }
      }
      const Halfedge h0 = Mesh::halfedge(Edge(e), 0), h1 = Mesh::halfedge(Edge(e), 1);
      out.set_halfedge(mid, second_half(m.is_boundary(h1) ? h1 : h0));
      if (edge_props) emap[2 * e] = emap[2 * e + 1] = e;
    }
  });
  for (Index v = 0; v < V; ++v) {
    const Halfedge h = m.halfedge(Vertex(v));
    out.set_halfedge(Vertex(v), h.is_valid() ? first_half(h) : Halfedge());
  }

  // Stencils. Added vertices: edge points 0..E-1, then face points E..E+FP-1.
  VertexRule rule;
  rule.V = V;
  rule.added = E + FP;
  rule.phases = {{E, E + FP}, {0, E}};  // edge points of Catmull–Clark read face points
  auto face_point_index = [&](Face f) { return V + E + plan.point_of_face(f.idx()); };
  auto added = [&](Index k, Stencil& s) {
    if (k >= E) {
      const Face f(plan.face_of_point[k - E]);
      const float w = 1.0f / float(face_size(m, f));
      for (Vertex c : m.vertices(f)) s.add(c.idx(), w);
      return;
    }
    const Halfedge h0 = Mesh::halfedge(Edge(k), 0), h1 = Mesh::halfedge(Edge(k), 1);
    const Index a = m.to_vertex(h0).idx(), b = m.to_vertex(h1).idx();
    if (scheme == SubdivisionScheme::midpoint || m.is_boundary(Edge(k)) || (!crease.empty() && crease[k])) {
      s.add(a, 0.5f);
      s.add(b, 0.5f);
    } else if (scheme == SubdivisionScheme::loop) {
      s.add(a, 0.375f);
      s.add(b, 0.375f);
      s.add(m.to_vertex(m.next(h0)).idx(), 0.125f);
      s.add(m.to_vertex(m.next(h1)).idx(), 0.125f);
    } else {
      s.add(a, 0.25f);
      s.add(b, 0.25f);
      s.add(face_point_index(m.face(h0)), 0.25f);
      s.add(face_point_index(m.face(h1)), 0.25f);
    }
  };
  auto even = [&](Vertex v, Stencil& s) {
    const Halfedge out_h = m.halfedge(v);
    if (scheme == SubdivisionScheme::midpoint || !out_h.is_valid()) {
      s.add(v.idx(), 1.0f);
      return;
    }
    if (!crease.empty()) {
      // Hoppe et al. 1994 / DeRose et al. 1998, boundary edges counting as creases: a corner
      // (3 or more) stays, two interior creases give the curve rule along them, a dart (one)
      // falls through to the smooth rule, a plain boundary vertex to the boundary rule.
      const SharpEdges sharp = sharp_edges(m, crease, v);
      if (sharp.count >= 3) {
        s.add(v.idx(), 1.0f);
        return;
      }
      if (sharp.count == 2 && !m.is_boundary(out_h)) {
        s.add(v.idx(), 0.75f);
        s.add(m.to_vertex(sharp.out[0]).idx(), 0.125f);
        s.add(m.to_vertex(sharp.out[1]).idx(), 0.125f);
        return;
      }
    }
    if (m.is_boundary(out_h)) {
      // Cubic B-spline on the boundary curve: the two boundary neighbours 1/8 each.
      s.add(v.idx(), 0.75f);
      s.add(m.to_vertex(out_h).idx(), 0.125f);
      s.add(m.from_vertex(m.prev(out_h)).idx(), 0.125f);
      return;
    }
    // One walk around v gathers the ring; the weights depend on its size, set afterwards.
    s.add(v.idx(), 0.0f);
    if (scheme == SubdivisionScheme::loop) {
      for (Halfedge h : m.outgoing(v)) s.add(m.to_vertex(h).idx(), 0.0f);
      const std::size_t n = s.size() - 1;
      const float beta = float(loop_beta(n));
      s.weight(0) = float(1.0 - double(n) * double(beta));
      for (std::size_t i = 1; i <= n; ++i) s.weight(i) = beta;
    } else {
      // (Q + 2R + (n - 3) S) / n with Q the mean face point, R the mean edge midpoint: the
      // vertex keeps (n - 2) / n, each neighbour and face point 1 / n^2.
      for (Halfedge h : m.outgoing(v)) {
        s.add(m.to_vertex(h).idx(), 0.0f);
        s.add(face_point_index(m.face(h)), 0.0f);
      }
      const std::size_t n = (s.size() - 1) / 2;
      s.weight(0) = float(n - 2) / float(n);
      for (std::size_t i = 1; i <= 2 * n; ++i) s.weight(i) = 1.0f / float(n * n);
    }
  };
  refine_vertices(m, out, rule, threads, added, even);
  progress.update(from + 0.8 * (to - from), "subdividing: attributes");

  // Corners: a midpoint corner per old inner half-edge h (between h's and prev(h)'s corners),
  // then a centroid corner per face point.
  refine_corners(m, out, std::size_t(H) + FP, hmap, threads, [&](const std::vector<Target>& all, unsigned t) {
    parallel_for(H, t, [&](std::size_t lo, std::size_t hi) {
      for (Index h = Index(lo); h < hi; ++h) {
        if (m.is_boundary(Halfedge(h))) continue;
        const Index sources[2] = {m.prev(Halfedge(h)).idx(), h};
        const float half[2] = {0.5f, 0.5f};
        for (const Target& x : all) blend(x, H + h, sources, half);
      }
    });
    parallel_for(FP, t, [&](std::size_t lo, std::size_t hi) {
      std::vector<Index> sources;
      std::vector<float> w;
      for (Index k = Index(lo); k < hi; ++k) {
        sources.clear();
        for (Halfedge x : m.halfedges(Face(plan.face_of_point[k]))) sources.push_back(x.idx());
        w.assign(sources.size(), 1.0f / float(sources.size()));
        for (const Target& x : all) blend(x, centroid_slot + k, sources, w);
      }
    });
  });
  if (edge_props)
    copy_parents(m.edge_properties(), out.edge_properties(), E, emap, E2);
  else
    out.edge_properties().resize(E2);
  if (face_props)
    copy_parents(m.face_properties(), out.face_properties(), F, fmap, F2);
  else
    out.face_properties().resize(F2);
  return out;
}

// ---- √3: a vertex per face, then every interior old edge flipped -----------------------------

// Kobbelt's boundary rule: every second step (`trisect`) cuts each boundary edge A -> B in
// three at Q1, Q2, and the boundary triangle's slot (A, B, P_f) becomes (A, Q1, P_f),
// (Q1, Q2, P_f), (Q2, B, P_f); positions follow the univariate ternary scheme, so two steps
// refine the boundary curve 1 -> 3 as the interior is refined 1 -> 9. A crease (`crease`, per
// edge of m, empty for none) is a boundary seen from both sides: it is never flipped, and on
// the same steps it is cut in three, each of its two triangles splitting like a boundary one.
//
// What a trisecting step adds: boundary edge k (in edge order) vertices V + F + 2k (Q1) and
// + 1 (Q2), edges E + 3F + 4k + {0: Q1-Q2, 1: Q2-B, 2: Q1-P_f, 3: Q2-P_f} (side 0 from the
// first named vertex) and faces 3F + 2k + {0, 1}; the old edge keeps A-Q1. Then crease c (in
// edge order), A -> B its side-0 half-edge: vertices V + F + 2B + 2c + {0: Q1, 1: Q2}, edges
// E + 3F + 4B + 6c + {0: Q1-Q2, 1: Q2-B} and, for its side s, + 2 + 2s (the spoke from the Q
// nearer that side's origin to its face point) and + 3 + 2s (from the other Q), and faces
// 3F + 2B + 4c + 2s + {0, 1}. On return `crease` is per edge of the result.
Mesh sqrt3_step(const Mesh& m, bool trisect, std::vector<bool>& crease, unsigned threads, Progress& progress,
                double from, double to) {
  const Index V = Index(m.vertices_size()), E = Index(m.edges_size()), F = Index(m.faces_size());
  const Index H = 2 * E;
  const bool creases = !crease.empty();
  std::vector<Index> boundary_number;    // edge -> k for boundary edges that are cut
  std::vector<Halfedge> boundary_inner;  // k -> the edge's half-edge inside its face
  std::vector<Index> crease_number;      // edge -> c for creases (all are cut)
  std::vector<Edge> cut_creases;         // c -> the edge
  if (trisect) {
    // Seams of split non-manifold edges stay as they are: the input's surface goes on there,
    // and their two sides must stay alike to weld back.
    const std::vector<bool> seam = split_seam_edges(m);
    boundary_number.assign(E, kInvalidIndex);
    for (Index e = 0; e < E; ++e)
      for (unsigned side = 0; side < 2; ++side)
        if (m.is_boundary(Mesh::halfedge(Edge(e), side)) && (seam.empty() || !seam[e])) {
          boundary_number[e] = Index(boundary_inner.size());
          boundary_inner.push_back(Mesh::halfedge(Edge(e), 1 - side));
        }
    if (creases) {
      crease_number.assign(E, kInvalidIndex);
      for (Index e = 0; e < E; ++e)
        if (crease[e]) {
          crease_number[e] = Index(cut_creases.size());
          cut_creases.push_back(Edge(e));
        }
    }
  }
  const std::size_t B = boundary_inner.size(), C = cut_creases.size();
  check_index_range(std::size_t(V) + F + 2 * B + 2 * C, std::size_t(E) + 3 * std::size_t(F) + 4 * B + 6 * C,
                    3 * std::size_t(F) + 2 * B + 4 * C);
  const Index V2 = Index(V + F + 2 * B + 2 * C), E2 = Index(E + 3 * F + 4 * B + 6 * C);
  const Index F2 = Index(3 * F + 2 * B + 4 * C);
  // Where the creases' additions start: vertices, edges, faces, corner slots.
  const Index crease_vertex0 = Index(V + F + 2 * B), crease_edge0 = Index(E + 3 * F + 4 * B);
  const Index crease_face0 = Index(3 * F + 2 * B), crease_slot0 = Index(H + F + 2 * B);
  auto extra_halfedge = [&](Index k, Index which, unsigned side) {
    return Halfedge(2 * (E + 3 * F + 4 * k + which) + side);
  };
  auto crease_halfedge = [&](Index c, Index which, unsigned side) {
    return Halfedge(2 * (crease_edge0 + 6 * c + which) + side);
  };
  auto is_crease = [&](Edge e) { return creases && crease[e.idx()]; };
  // An interior edge that extract()'s weld makes one with another (a split non-manifold
  // edge) is not flipped either, nor cut: flipping one copy would leave the others' faces
  // on an edge that no longer exists, and its ends with fans that no longer meet.
  std::vector<bool> welded;
  if (const detail::WeldedCopies copies(m); copies.any()) {
    welded.assign(E, false);
    for (Edge e : m.edges())
      welded[e.idx()] = !m.is_boundary(e) && copies.edge_elsewhere(m, m.vertex(e, 0), m.vertex(e, 1), e);
  }
  auto is_welded = [&](Edge e) { return !welded.empty() && welded[e.idx()]; };
  // is_cut(g): g's edge is a boundary edge cut on this step. boundary_out(g), for a boundary
  // half-edge g: the half-edge that then leaves g's origin B along the boundary (B -> Q2), g
  // itself when its edge is not cut.
  auto is_cut = [&](Halfedge g) { return trisect && boundary_number[Mesh::edge(g).idx()] != kInvalidIndex; };
  auto boundary_out = [&](Halfedge g) {
    return is_cut(g) ? extra_halfedge(boundary_number[Mesh::edge(g).idx()], 1, 1) : g;
  };

  // Corner number of every inner half-edge in its triangle (halfedge(f) is corner 0).
  std::vector<std::uint8_t> corner(H, 0);
  parallel_for(F, threads, [&](std::size_t lo, std::size_t hi) {
    for (Index f = Index(lo); f < hi; ++f) {
      Halfedge h = m.halfedge(Face(f));
      for (std::uint8_t i = 0; i < 3; ++i, h = m.next(h)) corner[h.idx()] = i;
    }
  });

  Mesh out;
  out.resize(V2, E2, F2);
  const bool corner_props = m.halfedge_properties().count() > 0;
  const bool edge_props = m.edge_properties().count() > 0;
  const bool face_props = m.face_properties().count() > 0;
  std::vector<Index> hmap(corner_props ? std::size_t(2) * E2 : 0), emap(edge_props ? E2 : 0), fmap(face_props ? F2 : 0);

  // Spoke (f, i) joins face point P_f and corner c_i; side 0 runs P_f -> c_i. The old inner
  // half-edge h = h_i of f (pointing to c_i) keeps its index: when its edge is interior it
  // becomes P_f -> P_g (g the face across), and triangle 3f + i is (c_i, P_f, P_g); on the
  // boundary or a crease it stays, and triangle 3f + i is (c_{i-1}, c_i, P_f).
  auto spoke = [&](Index f, Index i, unsigned side) { return Halfedge(2 * (E + 3 * f + i % 3) + side); };

  // The cut of the side of an edge A -> B that lies in face f (h its half-edge there, corner
  // i): `first`, `mid` and `last` run A -> near -> far -> B, x and y are the spokes near ->
  // P_f and far -> P_f, and triangle 3f + i becomes (A, near, P_f), t1 (near, far, P_f) and
  // t2 (far, B, P_f); the corner slots hold the corners at near and far.
  struct CutSide {
    Halfedge first, mid, last, x, y;
    Vertex near, far;
    Face t1, t2;
    Index near_slot, far_slot;
  };
  auto cut_side = [&](Index f, Index i, Halfedge h, const CutSide& c) {
    const Vertex pf(V + f);
    const Halfedge to_a = spoke(f, i + 2, 0), a = spoke(f, i, 1);  // P_f -> A, B -> P_f
    out.set_vertex(c.first, c.near);
    out.set_vertex(c.mid, c.far);
    out.set_vertex(c.last, m.to_vertex(h));
    out.set_vertex(c.x, pf);
    out.set_vertex(Mesh::opposite(c.x), c.near);
    out.set_vertex(c.y, pf);
    out.set_vertex(Mesh::opposite(c.y), c.far);
    const Halfedge loops[3][3] = {
        {c.first, c.x, to_a}, {c.mid, c.y, Mesh::opposite(c.x)}, {c.last, a, Mesh::opposite(c.y)}};
    const Face faces[3] = {Face(3 * f + i), c.t1, c.t2};
    for (int j = 0; j < 3; ++j) {
      for (int l = 0; l < 3; ++l) {
        out.set_next(loops[j][l], loops[j][(l + 1) % 3]);
        out.set_face(loops[j][l], faces[j]);
      }
      out.set_halfedge(faces[j], loops[j][0]);
      if (face_props) fmap[faces[j].idx()] = f;
    }
    if (corner_props) {
      hmap[c.first.idx()] = c.near_slot;
      hmap[c.x.idx()] = H + f;
      hmap[to_a.idx()] = m.prev(h).idx();
      hmap[c.mid.idx()] = c.far_slot;
      hmap[c.y.idx()] = H + f;
      hmap[Mesh::opposite(c.x).idx()] = c.near_slot;
      hmap[c.last.idx()] = h.idx();
      hmap[a.idx()] = H + f;
      hmap[Mesh::opposite(c.y).idx()] = c.far_slot;
    }
    if (edge_props) emap[Mesh::edge(c.x).idx()] = emap[Mesh::edge(c.y).idx()] = emap[E + 3 * f + i] = E;
  };

  parallel_for(F, threads, [&](std::size_t lo, std::size_t hi) {
    for (Index f = Index(lo); f < hi; ++f) {
      const Vertex pf(V + f);
      Halfedge h = m.halfedge(Face(f));
      for (Index i = 0; i < 3; ++i, h = m.next(h)) {
        const Face t(3 * f + i);
        out.set_vertex(spoke(f, i, 0), m.to_vertex(h));
        out.set_vertex(spoke(f, i, 1), pf);
        const Halfedge g = Mesh::opposite(h);
        const Edge e = Mesh::edge(h);
        const Halfedge a = spoke(f, i, 1);
        const bool boundary = m.is_boundary(g), sharp = boundary || is_crease(e) || is_welded(e);
        if (boundary && is_cut(g)) {
          const Index k = boundary_number[e.idx()];
          const Vertex q1(V + F + 2 * k), q2(V + F + 2 * k + 1);
          const Halfedge s1 = extra_halfedge(k, 0, 0), s2 = extra_halfedge(k, 1, 0);
          const Index slot = H + F + 2 * k;
          cut_side(f, i, h,
                   {h, s1, s2, extra_halfedge(k, 2, 0), extra_halfedge(k, 3, 0), q1, q2, Face(3 * F + 2 * k),
                    Face(3 * F + 2 * k + 1), slot, slot + 1});
          // Along the boundary: B -> Q2 -> Q1 -> A (g keeps Q1 -> A; the edge loop links g on).
          out.set_vertex(Mesh::opposite(s1), q1);
          out.set_vertex(Mesh::opposite(s2), q2);
          out.set_next(Mesh::opposite(s2), Mesh::opposite(s1));
          out.set_next(Mesh::opposite(s1), g);
          out.set_halfedge(q1, g);
          out.set_halfedge(q2, Mesh::opposite(s1));
          if (corner_props) hmap[Mesh::opposite(s1).idx()] = hmap[Mesh::opposite(s2).idx()] = g.idx();  // defaults
          if (edge_props) emap[Mesh::edge(s1).idx()] = emap[Mesh::edge(s2).idx()] = e.idx();
          continue;
        }
        if (trisect && is_crease(e)) {
          // A crease: its side 0 runs A -> Q1 -> Q2 -> B, side 1 B -> Q2 -> Q1 -> A.
          const Index c = crease_number[e.idx()];
          const unsigned side = h == Mesh::halfedge(e, 0) ? 0 : 1;
          const Vertex q1(crease_vertex0 + 2 * c), q2(crease_vertex0 + 2 * c + 1);
          const Halfedge x = crease_halfedge(c, 2 + 2 * side, 0), y = crease_halfedge(c, 3 + 2 * side, 0);
          const Face t1(crease_face0 + 4 * c + 2 * side), t2(crease_face0 + 4 * c + 2 * side + 1);
          const Index slot = crease_slot0 + 4 * c + 2 * side;
          if (side == 0) {
            cut_side(f, i, h,
                     {h, crease_halfedge(c, 0, 0), crease_halfedge(c, 1, 0), x, y, q1, q2, t1, t2, slot, slot + 1});
            // The elements both sides share, written once.
            out.set_halfedge(q1, x);
            out.set_halfedge(q2, y);
            if (edge_props) emap[crease_edge0 + 6 * c] = emap[crease_edge0 + 6 * c + 1] = e.idx();
          } else {
            cut_side(f, i, h,
                     {crease_halfedge(c, 1, 1), crease_halfedge(c, 0, 1), h, x, y, q2, q1, t1, t2, slot, slot + 1});
          }
          continue;
        }
        Halfedge b, c;
        if (sharp) {
          out.set_vertex(h, m.to_vertex(h));
          b = spoke(f, i + 2, 0);  // P_f -> c_{i-1}
          c = h;
          out.set_halfedge(t, h);
          if (corner_props) {
            hmap[h.idx()] = h.idx();
            hmap[b.idx()] = m.prev(h).idx();
          }
        } else {
          const Index fg = m.face(g).idx();
          out.set_vertex(h, Vertex(V + fg));
          b = h;
          c = spoke(fg, corner[m.prev(g).idx()], 0);  // P_g -> c_i
          out.set_halfedge(t, c);
          if (corner_props) {
            hmap[h.idx()] = H + fg;  // the centroid corner of g
            hmap[c.idx()] = h.idx();
          }
        }
        // a: c_i -> P_f, then b, then c back to a's origin.
        out.set_next(a, b);
        out.set_next(b, c);
        out.set_next(c, a);
        out.set_face(a, t);
        out.set_face(b, t);
        out.set_face(c, t);
        if (corner_props) hmap[a.idx()] = H + f;
        if (face_props) fmap[t.idx()] = f;
        if (edge_props) emap[E + 3 * f + i] = E;
      }
      out.set_halfedge(pf, spoke(f, 0, 0));
    }
  });
  progress.update(from + 0.3 * (to - from), "subdividing: connectivity");
  parallel_for(E, threads, [&](std::size_t lo, std::size_t hi) {
    for (Index e = Index(lo); e < hi; ++e) {
      for (unsigned side = 0; side < 2; ++side) {
        const Halfedge h = Mesh::halfedge(Edge(e), side);
        if (!m.is_boundary(h)) continue;
        out.set_vertex(h, m.to_vertex(h));
        out.set_next(h, boundary_out(m.next(h)));
        if (corner_props) hmap[h.idx()] = h.idx();
      }
      if (edge_props) emap[e] = e;
    }
  });
  // Old vertices: boundary ones keep their boundary half-edge; interior ones leave along a
  // spoke, since their old edges were flipped away.
  for (Index v = 0; v < V; ++v) {
    const Halfedge h = m.halfedge(Vertex(v));
    if (!h.is_valid() || m.is_boundary(h)) {
      out.set_halfedge(Vertex(v), h.is_valid() ? boundary_out(h) : h);
    } else {
      const Halfedge in = m.prev(h);  // points to v inside face(h)
      out.set_halfedge(Vertex(v), spoke(m.face(h).idx(), corner[in.idx()], 1));
    }
  }

  VertexRule rule;
  rule.V = V;
  rule.added = Index(F + 2 * B + 2 * C);
  rule.phases = {{0, rule.added}};
  auto added = [&](Index n, Stencil& s) {
    if (n < F) {
      for (Vertex c : m.vertices(Face(n))) s.add(c.idx(), 1.0f / 3.0f);
      return;
    }
    // The ternary rule: the point a third of the way from A to B is (10 B + 16 A + A') / 27,
    // A' being A's other neighbour along the boundary or crease.
    const bool on_boundary = n < F + 2 * B;
    const Index j = on_boundary ? n - F : n - F - Index(2 * B);
    const Halfedge h = on_boundary ? boundary_inner[j / 2] : Mesh::halfedge(cut_creases[j / 2], 0);
    const bool near_a = j % 2 == 0;
    const Vertex near = near_a ? m.from_vertex(h) : m.to_vertex(h), far = near_a ? m.to_vertex(h) : m.from_vertex(h);
    Vertex beyond;
    if (!creases) {
      const Halfedge g = Mesh::opposite(h);
      beyond = near_a ? m.to_vertex(m.next(g)) : m.from_vertex(m.prev(g));
    } else {
      const SharpEdges sharp = sharp_edges(m, crease, near);
      if (sharp.count != 2) {
        // A corner or a dart ends the curve there: the linear rule, as for a reflected A'.
        s.add(near.idx(), 2.0f / 3);
        s.add(far.idx(), 1.0f / 3);
        return;
      }
      beyond = m.to_vertex(sharp.out[Mesh::edge(sharp.out[0]) == Mesh::edge(h) ? 1 : 0]);
    }
    s.add(beyond.idx(), 1.0f / 27);
    s.add(near.idx(), 16.0f / 27);
    s.add(far.idx(), 10.0f / 27);
  };
  auto even = [&](Vertex v, Stencil& s) {
    if (creases && m.halfedge(v).is_valid()) {
      // As for Loop: a corner (three or more sharp edges) stays, a vertex on two follows the
      // curve rule along them (here the boundary's), a dart (one) the smooth rule.
      const SharpEdges sharp = sharp_edges(m, crease, v);
      auto cut = [&](Halfedge h) { return is_cut(h) || (trisect && is_crease(Mesh::edge(h))); };
      if (sharp.count >= 3 || (sharp.count == 2 && (!cut(sharp.out[0]) || !cut(sharp.out[1])))) {
        s.add(v.idx(), 1.0f);
        return;
      }
      if (sharp.count == 2) {
        s.add(m.to_vertex(sharp.out[0]).idx(), 4.0f / 27);
        s.add(v.idx(), 19.0f / 27);
        s.add(m.to_vertex(sharp.out[1]).idx(), 4.0f / 27);
        return;
      }
    }
    if (m.is_boundary(v)) {
      const Halfedge out_h = m.halfedge(v);  // boundary: v -> next along the boundary
      // The boundary curve waits for the next step; isolated vertices and seams stay.
      if (!out_h.is_valid() || !is_cut(out_h) || !is_cut(m.prev(out_h))) {
        s.add(v.idx(), 1.0f);
        return;
      }
      s.add(m.from_vertex(m.prev(out_h)).idx(), 4.0f / 27);
      s.add(v.idx(), 19.0f / 27);
      s.add(m.to_vertex(out_h).idx(), 4.0f / 27);
      return;
    }
    // One walk around v gathers the ring; the weights depend on its size, set afterwards.
    s.add(v.idx(), 0.0f);
    for (Vertex w : m.vertices(v)) s.add(w.idx(), 0.0f);
    const std::size_t n = s.size() - 1;
    const double alpha = tabulated<sqrt3_alpha_formula>(n);
    s.weight(0) = float(1.0 - alpha);
    for (std::size_t i = 1; i <= n; ++i) s.weight(i) = float(alpha / double(n));
  };
  refine_vertices(m, out, rule, threads, added, even);
  progress.update(from + 0.8 * (to - from), "subdividing: attributes");

  refine_corners(m, out, F + 2 * B + 4 * C, hmap, threads, [&](const std::vector<Target>& all, unsigned t) {
    parallel_for(F, t, [&](std::size_t lo, std::size_t hi) {
      const float third[3] = {1.0f / 3, 1.0f / 3, 1.0f / 3};
      for (Index f = Index(lo); f < hi; ++f) {
        const Halfedge h = m.halfedge(Face(f));
        const Index sources[3] = {h.idx(), m.next(h).idx(), m.prev(h).idx()};
        for (const Target& x : all) blend(x, H + f, sources, third);
      }
    });
    // Corners at Q1 and Q2 lie on the edge A -> B of their face: a third and two thirds along.
    const float near_a[2] = {2.0f / 3, 1.0f / 3}, near_b[2] = {1.0f / 3, 2.0f / 3};
    auto blend_cut = [&](Halfedge h, std::size_t slot) {
      const Index sources[2] = {m.prev(h).idx(), h.idx()};  // the corners at A and B
      for (const Target& x : all) {
        blend(x, slot, sources, near_a);
        blend(x, slot + 1, sources, near_b);
      }
    };
    parallel_for(B, t, [&](std::size_t lo, std::size_t hi) {
      for (std::size_t k = lo; k < hi; ++k) blend_cut(boundary_inner[k], H + F + 2 * k);
    });
    parallel_for(C, t, [&](std::size_t lo, std::size_t hi) {
      for (std::size_t c = lo; c < hi; ++c)
        for (unsigned side = 0; side < 2; ++side)
          blend_cut(Mesh::halfedge(cut_creases[c], side), crease_slot0 + 4 * c + 2 * side);
    });
  });
  if (edge_props)
    copy_parents(m.edge_properties(), out.edge_properties(), E, emap, E2);
  else
    out.edge_properties().resize(E2);
  if (face_props)
    copy_parents(m.face_properties(), out.face_properties(), F, fmap, F2);
  else
    out.face_properties().resize(F2);
  if (creases) {
    // The old edges keep their flags (interior ones were flipped only if smooth); a cut
    // crease's two new pieces are creases, the spokes are not.
    std::vector<bool> next(E2, false);
    for (Index e = 0; e < E; ++e) next[e] = crease[e];
    for (std::size_t c = 0; c < C; ++c) next[crease_edge0 + 6 * c] = next[crease_edge0 + 6 * c + 1] = true;
    crease = std::move(next);
  }
  return out;
}

//! On non-manifold input, build() split edges into copies of one input edge. Each copy gets
//! its own edge point (vertex V + e of a split step); giving them one new source lets
//! extract() weld them, so the host's surface keeps the input's edge and gets no crack
//! (the welded point takes the first copy's position). New sources are numbered after the
//! largest one in use, in the order of the welded edges they sit on.
void weld_split_edge_points(const Mesh& before, Mesh& after) {
  const auto* old_source = before.vertex_properties().get<std::uint32_t>(provenance::kVertexSource);
  auto* source = after.vertex_properties().get<std::uint32_t>(provenance::kVertexSource);
  if (!old_source || !source) return;
  const Index V = Index(before.vertices_size());
  std::uint64_t next = 0;
  for (std::uint32_t s : old_source->vector())
    if (s != kInvalidIndex) next = std::max<std::uint64_t>(next, std::uint64_t(s) + 1);
  auto welded = [&](Vertex v) -> std::uint64_t {
    const std::uint32_t s = old_source->vector()[v.idx()];
    return s != kInvalidIndex ? s : (std::uint64_t(1) << 32) + v.idx();  // unique when it has none
  };
  std::vector<std::tuple<std::uint64_t, std::uint64_t, Index>> edges;  // (welded ends, edge)
  for (Edge e : before.edges()) {
    const std::uint64_t a = welded(before.vertex(e, 0)), b = welded(before.vertex(e, 1));
    edges.emplace_back(std::min(a, b), std::max(a, b), e.idx());
  }
  std::sort(edges.begin(), edges.end());
  auto same = [&](std::size_t i, std::size_t j) {
    return std::get<0>(edges[i]) == std::get<0>(edges[j]) && std::get<1>(edges[i]) == std::get<1>(edges[j]);
  };
  for (std::size_t i = 0; i < edges.size();) {
    std::size_t j = i + 1;
    while (j < edges.size() && same(i, j)) ++j;
    // Copies on one face (a face that visits both ends twice) keep their points apart:
    // welded, they would make that face's pieces one face twice over.
    std::vector<std::vector<Index>> classes;
    for (std::size_t k = i; k < j && j - i > 1; ++k) {
      const Edge e(std::get<2>(edges[k]));
      auto shares_face = [&](Index other) {
        for (unsigned a = 0; a < 2; ++a)
          for (unsigned b = 0; b < 2; ++b)
            if (Face f = before.face(e, a); f.is_valid() && f == before.face(Edge(other), b)) return true;
        return false;
      };
      auto fits = std::find_if(classes.begin(), classes.end(),
                               [&](const auto& c) { return std::none_of(c.begin(), c.end(), shares_face); });
      if (fits == classes.end()) fits = classes.insert(classes.end(), std::vector<Index>{});
      fits->push_back(e.idx());
    }
    for (const auto& c : classes) {
      if (c.size() < 2) continue;
      if (next >= kInvalidIndex) return;  // out of numbers: leave the rest unwelded
      for (Index e : c) source->vector()[V + e] = std::uint32_t(next);
      ++next;
    }
    i = j;
  }
}

//! Faces by kind, in one pass: what the refusals and the size forecast need.
struct FaceCensus {
  std::size_t faces = 0, triangles = 0, corners = 0;
  //! What a trisecting sqrt3 step cuts (count_sqrt3_cuts): boundary edges but seams, creases.
  std::size_t boundary_edges = 0, crease_edges = 0;
};

FaceCensus face_census(const Mesh& mesh) {
  FaceCensus c;
  for (Face f : mesh.faces()) {
    const Index n = face_size(mesh, f);
    ++c.faces;
    c.triangles += n == 3;
    c.corners += n;
  }
  return c;
}

//! Fills in what sqrt3 cuts on its even steps (sqrt3_step): boundary edges other than the seams
//! of split non-manifold edges, and the `crease_edges` creases. Others need no such count.
void count_sqrt3_cuts(const Mesh& mesh, const SubdivideOptions& options, std::size_t crease_edges, FaceCensus& c) {
  if (options.scheme != SubdivisionScheme::sqrt3 || options.iterations < 2) return;
  c.crease_edges = crease_edges;
  for (Edge e : mesh.edges()) c.boundary_edges += mesh.is_boundary(e) ? 1 : 0;
  if (c.boundary_edges == 0) return;
  const std::vector<bool> seam = split_seam_edges(mesh);
  c.boundary_edges -= std::size_t(std::count(seam.begin(), seam.end(), true));
}

//! Corner normals were blended inside each face (hard edges stay hard): back to unit length.
void normalize_corner_normals(Mesh& mesh) {
  ChannelArray* c = mesh.halfedge_properties().get_channel("normal");
  if (!c || c->scalar() != ScalarType::f32 || c->components() != 3) return;
  for (std::size_t i = 0; i < c->size(); ++i) {
    Vec3f n;
    std::memcpy(&n, c->element(i), sizeof n);
    n = normalize(n);
    std::memcpy(c->element(i), &n, sizeof n);
  }
}

std::size_t forecast_faces(const FaceCensus& c, const SubdivideOptions& options) {
  if (options.iterations <= 0 || c.faces == 0) return c.faces;
  // Doubles, so that absurd requests compare as huge instead of wrapping around.
  double first = 0;
  switch (options.scheme) {
    case SubdivisionScheme::loop:
      first = 4.0 * double(c.faces);
      break;
    case SubdivisionScheme::sqrt3:
      first = 3.0 * double(c.faces);
      break;
    case SubdivisionScheme::catmull_clark:
      first = double(c.corners);
      break;
    case SubdivisionScheme::midpoint:
      first = 4.0 * double(c.triangles) + double(c.corners - 3 * c.triangles);
      break;
  }
  if (options.scheme == SubdivisionScheme::sqrt3 && (c.boundary_edges || c.crease_edges)) {
    // Every second step cuts each boundary edge in three, adding two triangles for each, and
    // each crease, adding two on either side.
    double faces = double(c.faces), boundary = double(c.boundary_edges), creases = double(c.crease_edges);
    for (int it = 0; it < options.iterations && faces < 1e18; ++it) {
      faces *= 3;
      if (it % 2 == 1) {
        faces += 2 * boundary + 4 * creases;
        boundary *= 3;
        creases *= 3;
      }
    }
    return faces >= 1e18 ? std::size_t(1e18) : std::size_t(faces);
  }
  const double factor = options.scheme == SubdivisionScheme::sqrt3 ? 3.0 : 4.0;
  const double total = first * std::pow(factor, options.iterations - 1);
  return total >= 1e18 ? std::size_t(1e18) : std::size_t(total);
}

//! Refuses, before starting, subdivisions whose vertices, half-edges or faces would not fit
//! the 32-bit indices (whatever max_faces allows): the counts of every step, in doubles so
//! that nothing wraps. Each step of loop, midpoint and catmull_clark splits every edge and
//! adds an edge per corner inside each face; sqrt3 keeps the edges and adds 3 per triangle,
//! and every second step cuts boundary edges and creases in three (sqrt3_step).
void check_index_limits(const Mesh& mesh, const FaceCensus& census, const SubdivideOptions& options, const char* name) {
  double v = double(mesh.n_vertices()), e = double(mesh.n_edges()), f = double(census.faces);
  double t = double(census.triangles), c = double(census.corners);
  double boundary = double(census.boundary_edges), creases = double(census.crease_edges);
  for (int it = 1; it <= options.iterations; ++it) {
    switch (options.scheme) {
      case SubdivisionScheme::loop:
      case SubdivisionScheme::midpoint:
      case SubdivisionScheme::catmull_clark: {
        const bool quads = options.scheme == SubdivisionScheme::catmull_clark;
        const double polygons = f - t;
        v += e + (quads ? f : polygons);
        e = 2 * e + c;
        const double new_triangles = quads ? 0 : 4 * t;
        f = quads ? c : new_triangles + (c - 3 * t);
        c = quads ? 4 * c : 3 * new_triangles + 4 * (c - 3 * t);
        t = new_triangles;
        break;
      }
      case SubdivisionScheme::sqrt3:
        v += f;
        e += 3 * f;
        f *= 3;
        if (it % 2 == 0) {
          v += 2 * (boundary + creases);
          e += 4 * boundary + 6 * creases;
          f += 2 * boundary + 4 * creases;
          boundary *= 3;
          creases *= 3;
        }
        t = f;
        c = 3 * f;
        break;
    }
    const char* what = nullptr;
    double count = 0, limit = 0;
    if (2 * e > double(kMaxHalfedges)) {
      what = "half-edges", count = 2 * e, limit = double(kMaxHalfedges);
    } else if (v > double(kMaxElements)) {
      what = "vertices", count = v, limit = double(kMaxElements);
    } else if (f > double(kMaxElements)) {
      what = "faces", count = f, limit = double(kMaxElements);
    }
    if (what)
      throw Error("subdivide: " + std::to_string(options.iterations) + " iterations of " + name + " would need " +
                  with_commas(count >= 1e19 ? std::uint64_t(1e19) : std::uint64_t(count)) + " " + what + " at step " +
                  std::to_string(it) + ", but hedge's 32-bit indices hold at most " +
                  with_commas(std::uint64_t(limit)) + " " + what + "; " +
                  (it == 1 ? std::string("this mesh is too large to subdivide with this scheme")
                           : "use at most " + std::to_string(it - 1) + (it == 2 ? " iteration" : " iterations")));
  }
}

}  // namespace

const char* subdivision_scheme_name(SubdivisionScheme scheme) {
  switch (scheme) {
    case SubdivisionScheme::loop:
      return "loop";
    case SubdivisionScheme::catmull_clark:
      return "catmull_clark";
    case SubdivisionScheme::sqrt3:
      return "sqrt3";
    case SubdivisionScheme::midpoint:
      return "midpoint";
  }
  return "unknown";
}

std::size_t subdivided_face_count(const Mesh& mesh, const SubdivideOptions& options) {
  FaceCensus census = face_census(mesh);
  std::size_t crease_edges = 0;
  if (options.scheme == SubdivisionScheme::sqrt3 && options.crease_angle < 180) {
    const std::vector<bool> crease = detect_creases(mesh, options.crease_angle);
    crease_edges = std::size_t(std::count(crease.begin(), crease.end(), true));
  }
  count_sqrt3_cuts(mesh, options, crease_edges, census);
  return forecast_faces(census, options);
}

SubdivideReport subdivide(Mesh& mesh, const SubdivideOptions& options, Progress& progress) {
  const char* name = subdivision_scheme_name(options.scheme);
  if (options.iterations < 1) throw Error("subdivide: iterations must be 1 or more");
  if (!(options.crease_angle >= 0 && options.crease_angle <= 180))
    throw Error("subdivide: crease_angle must be from 0 to 180 degrees");
  const bool triangles_only = options.scheme == SubdivisionScheme::loop || options.scheme == SubdivisionScheme::sqrt3;
  const FaceCensus faces = face_census(mesh);
  const std::size_t faces_before = mesh.n_faces();
  if (triangles_only) {
    if (std::size_t polygons = faces.faces - faces.triangles)
      throw Error(std::string("subdivide: the ") + name + " scheme works on triangle meshes, and " +
                  std::to_string(polygons) + (polygons == 1 ? " face has" : " faces have") +
                  " more than 3 corners; triangulate first, or use catmull_clark or midpoint");
  }

  // The steps read `current` and write a fresh mesh; the input is replaced only at the end,
  // so an error or a cancellation leaves it as it was.
  Mesh compacted;
  const Mesh* current = &mesh;
  if (mesh.has_garbage()) {
    compacted = mesh;
    compacted.garbage_collect();
    current = &compacted;
  }
  // Creases are found once, on the input; later steps carry them to the pieces of their edges.
  // (midpoint's rules are linear before they look at creases: found only for the report.)
  std::vector<bool> crease;
  std::size_t crease_edges = 0;
  if (options.crease_angle < 180) {
    crease = detect_creases(*current, options.crease_angle);
    crease_edges = std::size_t(std::count(crease.begin(), crease.end(), true));
    if (crease_edges == 0) crease.clear();
  }
  FaceCensus census = faces;
  count_sqrt3_cuts(*current, options, crease_edges, census);
  check_index_limits(*current, census, options, name);
  const std::size_t predicted = forecast_faces(census, options);
  if (predicted > options.max_faces)
    throw Error("subdivide: " + std::to_string(options.iterations) + " iterations of " + name + " would make " +
                std::to_string(predicted) + " faces, more than the limit of " + std::to_string(options.max_faces) +
                "; use fewer iterations");
  Mesh result;
  for (int it = 0; it < options.iterations; ++it) {
    const double from = double(it) / options.iterations, to = double(it + 1) / options.iterations;
    progress.update(from, "subdividing: step " + std::to_string(it + 1) + " of " + std::to_string(options.iterations));
    Mesh next;
    if (options.scheme == SubdivisionScheme::sqrt3) {
      next = sqrt3_step(*current, it % 2 == 1, crease, options.threads, progress, from, to);
    } else {
      next = split_step(*current, options.scheme, crease, options.threads, progress, from, to);
      weld_split_edge_points(*current, next);
      if (!crease.empty()) crease = split_creases(crease, next.edges_size());
    }
    result = std::move(next);
    current = &result;
  }
  mesh = std::move(result);
  refresh_normal_channels(mesh, true, true);
  normalize_corner_normals(mesh);

  SubdivideReport report;
  report.faces_before = faces_before;
  report.vertices = mesh.n_vertices();
  report.edges = mesh.n_edges();
  report.faces = mesh.n_faces();
  report.iterations = options.iterations;
  report.crease_edges = crease_edges;
  return report;
}

Operation subdivide_operation() {
  const char* help =
      "Refines the surface: every step replaces each face by smaller ones and moves the vertices toward a smooth "
      "limit surface. Schemes: loop (Loop 1987; triangles 1 to 4, smooth, for triangle meshes), catmull_clark "
      "(Catmull & Clark 1978; every n-gon becomes n quads, for any polygon mesh), sqrt3 (Kobbelt 2000; a vertex "
      "per triangle and the old edges flipped, the face count triples per step, for triangle meshes), midpoint "
      "(no smoothing: triangles 1 to 4 at the edge midpoints, other polygons into quads around their centroid). "
      "loop and sqrt3 refuse meshes with polygons: run Triangulate first. Boundaries: loop and catmull_clark "
      "refine boundary curves with the cubic B-spline rule; sqrt3 follows Kobbelt's rule, cutting boundary edges "
      "in three on every second iteration of a run (use an even number of iterations on open meshes). "
      "Creases: with a crease angle below 180, edges where the surface bends more sharply stay sharp under loop "
      "and catmull_clark (Hoppe et al. 1994; DeRose et al. 1998): they are refined as curves and the corners "
      "where three or more meet stay put; sqrt3 keeps them like boundaries (never flipped, cut in three on every "
      "second iteration); midpoint has no smoothing to undo. "
      "Attributes: vertex attributes are blended with the scheme's own weights, corner attributes (UVs) linearly "
      "inside each old face so seams stay seams, face attributes (materials) are copied to the child faces; normals "
      "are recomputed for the new shape. "
      "Results above 200 million faces are refused before starting.";
  using O = SubdivideOptions;
  using R = SubdivideReport;
  return Binding<O, R>("subdivide", "Subdivide", Category::remeshing, help, subdivide)
      .choice(&O::scheme, "scheme", "Scheme",
              {SubdivisionScheme::loop, SubdivisionScheme::catmull_clark, SubdivisionScheme::sqrt3,
               SubdivisionScheme::midpoint},
              subdivision_scheme_name,
              "loop and sqrt3 for triangle meshes, catmull_clark for any polygons (makes quads), "
              "midpoint to refine without smoothing")
      .option(&O::iterations, "iterations", "Iterations", between(1, 6),
              "refinement steps; each multiplies the face count by 4 (sqrt3: 3)")
      .option(&O::crease_angle, "crease_angle", "Crease angle", between(0, 180),
              "degrees: edges where the two faces' normals differ by more than this stay sharp (creases "
              "and corners, e.g. a cube's edges at 60); 180 smooths everything")
      .result(
          "scheme",
          [](const O& o, const R&) -> std::optional<Value> { return std::string(subdivision_scheme_name(o.scheme)); })
      .result(&R::iterations, "iterations")
      .result("crease_edges",
              [](const O& o, const R& r) -> std::optional<Value> {
                if (o.crease_angle >= 180) return std::nullopt;
                return field_value(r.crease_edges);
              })
      .result(&R::faces_before, "faces_before")
      .result(&R::vertices, "vertices")
      .result(&R::edges, "edges")
      .result(&R::faces, "faces");
}

}  // namespace hedge
