// The fill_holes operation: Liepa's hole filling (optimal triangulation, refinement to the
// surrounding density, bi-Laplacian fairing), one boundary loop at a time.
#include "hedge/fill_holes.h"

#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <deque>
#include <limits>
#include <numbers>
#include <span>
#include <unordered_map>
#include <utility>
#include <vector>

#include "binding.h"
#include "hedge/error.h"
#include "hedge/limits.h"
#include "hedge/provenance.h"
#include "hedge/topology.h"
#include "selection.h"

namespace hedge {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

// ---- attributes ---------------------------------------------------------------------------

// Whether a triangle on the corners of the three-edge hole at `start` exists already: the
// only way to fill the hole would give a second face on the same vertices. Where build()
// kept two edges between one pair of vertices, that is not only the lone face across the
// hole. (A triangle that only the weld of copies would make the same is extract()'s to
// keep apart.)
bool triangle_exists(const Mesh& mesh, Halfedge start) {
  const Vertex a = mesh.from_vertex(start), b = mesh.to_vertex(start), c = mesh.to_vertex(mesh.next(start));
  for (Face f : mesh.faces(a)) {
    if (!f.is_valid() || mesh.valence(f) != 3) continue;
    int found = 0;
    for (Vertex v : mesh.vertices(f)) found += v == a || v == b || v == c;
    if (found == 3) return true;
  }
  return false;
}

// build()'s provenance ("hedge:*" arrays) says where elements came from; patch elements
// came from nowhere, so they keep the arrays' defaults (reset_internal), and blends and
// copies leave those arrays alone.
template <class T>
bool reset_typed(PropertyArray& a, Index i) {
  auto* t = dynamic_cast<TypedArray<T>*>(&a);
  if (!t) return false;
  t->vector()[i] = t->default_value();
  return true;
}

void reset_internal(PropertyContainer& c, Index i) {
  for (std::size_t k = 0; k < c.count(); ++k) {
    PropertyArray& a = c.at(k);
    if (!a.is_internal()) continue;
    (void)(reset_typed<bool>(a, i) || reset_typed<std::uint8_t>(a, i) || reset_typed<std::int8_t>(a, i) ||
           reset_typed<std::uint16_t>(a, i) || reset_typed<std::int16_t>(a, i) || reset_typed<std::uint32_t>(a, i) ||
           reset_typed<std::int32_t>(a, i) || reset_typed<std::uint64_t>(a, i) || reset_typed<std::int64_t>(a, i) ||
           reset_typed<float>(a, i) || reset_typed<double>(a, i) || reset_typed<Vec3f>(a, i) ||
           reset_typed<Vec3d>(a, i) || reset_typed<Vec2f>(a, i));
  }
}

void interpolate_attributes(PropertyContainer& c, Index to, std::span<const Index> from,
                            std::span<const float> weights) {
  for (std::size_t k = 0; k < c.count(); ++k)
    if (!c.at(k).is_internal()) c.at(k).interpolate(to, from, weights);
}

void copy_attributes(PropertyContainer& c, Index from, Index to) {
  for (std::size_t k = 0; k < c.count(); ++k)
    if (!c.at(k).is_internal()) c.at(k).copy_element(from, to);
  reset_internal(c, to);
}

// ---- geometry ---------------------------------------------------------------------------

Vec3d position(const Mesh& mesh, Vertex v) { return to_double(mesh.position(v)); }

//! Unit normal of a face (Newell, fan from corner 0), zero when degenerate or invalid.
Vec3d unit_normal(const Mesh& mesh, Face f) {
  if (!f.is_valid()) return {};
  Halfedge h0 = mesh.halfedge(f);
  Vec3d p0 = position(mesh, mesh.to_vertex(h0));
  Vec3d n{};
  for (Halfedge h = mesh.next(h0); mesh.next(h) != h0; h = mesh.next(h))
    n += cross(position(mesh, mesh.to_vertex(h)) - p0, position(mesh, mesh.to_vertex(mesh.next(h))) - p0);
  double length = norm(n);
  return length > 0 ? n / length : Vec3d{};
}

double triangle_area(const Vec3d& a, const Vec3d& b, const Vec3d& c) { return 0.5 * norm(cross(b - a, c - a)); }

// 1 - cos of the dihedral angle between two unit normals (0 = flat, 2 = folded back); no
// constraint when a neighbour has no normal (a hole's edge, a degenerate face).
double bend(const Vec3d& a, const Vec3d& b) {
  if (sqrnorm(b) == 0 || sqrnorm(a) == 0) return 0;
  return 1 - dot(a, b);
}

// ---- the filler ---------------------------------------------------------------------------

// Liepa's weight: the largest dihedral angle first, then the area. Angles closer than this
// (in 1 - cos, about 0.1 degree) count as equal so that float noise on flat holes does
// not decide: the area does.
constexpr double kBendTolerance = 1e-6;

struct Weight {
  double bend = 0, area = 0;
  bool valid() const { return area < kInfinity; }
  bool better_than(const Weight& o) const {
    if (bend < o.bend - kBendTolerance) return true;
    if (bend > o.bend + kBendTolerance) return false;
    return area < o.area;
  }
};

class HoleFiller {
 public:
  HoleFiller(Mesh& mesh, const FillHolesOptions& options, FillHolesReport& report, Progress& progress)
      : mesh_(mesh), options_(options), report_(report), progress_(progress) {
    PropertyContainer& corners = mesh_.halfedge_properties();
    for (std::size_t k = 0; k < corners.count(); ++k)
      if (auto* channel = dynamic_cast<ChannelArray*>(&corners.at(k))) {
        corner_channels_.push_back(channel);
        corner_values_.emplace_back(channel->name(), channel->scalar(), channel->components());
      }
  }

  //! Triangulates, refines and fairs f, a face just put on a hole; `fraction` is the
  //! progress so far.
  void fill(Face f, double fraction);

 private:
  void grow() {
    if (sigma_.size() < mesh_.vertices_size()) {
      sigma_.resize(mesh_.vertices_size(), 0);
      slot_.resize(mesh_.vertices_size(), kInvalidIndex);
      corner_of_.resize(mesh_.vertices_size(), kInvalidIndex);
    }
    if (in_patch_.size() < mesh_.faces_size()) in_patch_.resize(mesh_.faces_size(), 0);
  }
  void add_patch_face(Face f) {
    grow();
    if (in_patch_[f.idx()]) return;
    in_patch_[f.idx()] = 1;
    patch_.push_back(f);
  }
  bool is_patch_edge(Edge e) const {
    Face f0 = mesh_.face(e, 0), f1 = mesh_.face(e, 1);
    return f0.is_valid() && f1.is_valid() && in_patch_[f0.idx()] && in_patch_[f1.idx()];
  }
  Index new_slot() {
    for (ChannelArray& c : corner_values_) c.push_back();
    return slot_count_++;
  }
  //! A new vertex at p whose attributes blend those of `from` with equal weights.
  Vertex new_vertex(const Vec3d& p, std::span<const Vertex> from);

  void triangulate(Face f);
  bool triangulate_optimal(Face f);
  void cut_and_triangulate(Face f);
  void fan(Face f);
  void refine();
  bool relax(Edge e);
  void relax_all();
  void fair();
  bool solve_fairing(bool cotangent);
  void finish_attributes();

  Mesh& mesh_;
  const FillHolesOptions& options_;
  FillHolesReport& report_;
  Progress& progress_;
  double fraction_ = 0;

  // The current hole.
  std::vector<Halfedge> loop_;  //!< its border half-edges, now inside the patch
  std::vector<Vertex> border_;  //!< from_vertex of loop_
  std::vector<Face> patch_;     //!< faces of the patch
  std::vector<Vertex> new_vertices_;

  // Per vertex / face scratch, grown with the mesh and cleaned after each hole.
  std::vector<double> sigma_;     //!< Liepa's density: the edge length wanted around a vertex
  std::vector<Index> slot_;       //!< corner value slot of a patch vertex
  std::vector<Index> corner_of_;  //!< corner index while triangulating one polygon
  std::vector<char> in_patch_;

  // Corner attributes: the patch has no seams, so each patch vertex has one value per
  // corner channel, kept in these arrays (one element per slot) until the patch is done.
  std::vector<ChannelArray*> corner_channels_;
  std::vector<ChannelArray> corner_values_;
  Index slot_count_ = 0;
};

Vertex HoleFiller::new_vertex(const Vec3d& p, std::span<const Vertex> from) {
  Vertex v = mesh_.new_vertex();
  mesh_.position(v) = to_float(p);
  grow();
  std::vector<Index> indices, slots;
  double sigma = 0;
  for (Vertex u : from) {
    indices.push_back(u.idx());
    slots.push_back(slot_[u.idx()]);
    sigma += sigma_[u.idx()];
  }
  std::vector<float> weights(from.size(), 1.0f / float(from.size()));
  interpolate_attributes(mesh_.vertex_properties(), v.idx(), indices, weights);
  Index slot = new_slot();
  for (ChannelArray& c : corner_values_) c.interpolate(slot, slots, weights);
  slot_[v.idx()] = slot;
  sigma_[v.idx()] = sigma / double(from.size());
  new_vertices_.push_back(v);
  return v;
}

void HoleFiller::fill(Face f, double fraction) {
  fraction_ = fraction;
  loop_.clear();
  border_.clear();
  patch_.clear();
  new_vertices_.clear();
  slot_count_ = 0;
  for (ChannelArray& c : corner_values_) c.resize(0);
  grow();

  for (Halfedge b : mesh_.halfedges(f)) loop_.push_back(b);
  for (Halfedge b : loop_) {
    Vertex v = mesh_.from_vertex(b);
    border_.push_back(v);
    // The density Liepa interpolates into the patch: the mean length of the edges at v.
    double sum = 0;
    std::size_t count = 0;
    for (Halfedge o : mesh_.outgoing(v)) {
      sum += distance(position(mesh_, v), position(mesh_, mesh_.to_vertex(o)));
      ++count;
    }
    sigma_[v.idx()] = count ? sum / double(count) : 0;
    // The corner of v in the face across b (opposite(b) points to v inside that face), or
    // across the side before b where b is the edge that cut a piece off a loop.
    Halfedge corner = mesh_.opposite(b);
    if (mesh_.is_boundary(corner)) corner = mesh_.prev(mesh_.opposite(mesh_.prev(b)));
    Index slot = new_slot();
    for (std::size_t k = 0; k < corner_channels_.size(); ++k)
      std::memcpy(corner_values_[k].element(slot), corner_channels_[k]->element(corner.idx()),
                  corner_values_[k].stride());
    slot_[v.idx()] = slot;
  }
  // A border vertex whose edges have (almost) no length would ask for triangles of no size:
  // refinement would fan ever smaller triangles into it up to the vertex cap, and the fan
  // makes the fairing system dense. Its density is kept within a tenth of the border's mean.
  double mean_sigma = 0;
  for (Vertex v : border_) mean_sigma += sigma_[v.idx()];
  mean_sigma /= double(border_.size());
  for (Vertex v : border_) sigma_[v.idx()] = std::max(sigma_[v.idx()], 0.1 * mean_sigma);

  add_patch_face(f);
  triangulate(f);
  if (options_.refine) refine();
  if (options_.fair && !new_vertices_.empty()) fair();
  finish_attributes();

  for (Vertex v : border_) slot_[v.idx()] = kInvalidIndex;
  for (Vertex v : new_vertices_) slot_[v.idx()] = kInvalidIndex;
  for (Face p : patch_) in_patch_[p.idx()] = 0;
}

void HoleFiller::triangulate(Face f) {
  if (loop_.size() <= options_.max_optimal_edges) {
    if (!triangulate_optimal(f)) fan(f);
  } else {
    cut_and_triangulate(f);
  }
}

// Liepa's dynamic programme over the polygon's corners: W(i,k) is the best triangulation
// of corners i..k closed by the edge k -> i; the weight is (largest dihedral angle, area),
// angles measured against the faces across the polygon's sides too, so the patch meets the
// surface as flatly as it can. Diagonals that already exist as edges elsewhere are refused
// (they would make a multi-edge). Returns false when no triangulation avoids them.
bool HoleFiller::triangulate_optimal(Face f) {
  std::vector<Halfedge> e;
  for (Halfedge h : mesh_.halfedges(f)) e.push_back(h);
  const std::size_t n = e.size();
  if (n <= 3) return true;
  std::vector<Vertex> c(n);
  std::vector<Vec3d> p(n), across(n);
  for (std::size_t m = 0; m < n; ++m) {
    c[m] = mesh_.from_vertex(e[m]);
    p[m] = position(mesh_, c[m]);
    across[m] = unit_normal(mesh_, mesh_.face(mesh_.opposite(e[m])));
  }

  grow();
  std::vector<char> forbidden(n * n, 0);
  for (std::size_t m = 0; m < n; ++m) corner_of_[c[m].idx()] = Index(m);
  for (std::size_t m = 0; m < n; ++m)
    for (Vertex u : mesh_.vertices(c[m])) {
      Index j = corner_of_[u.idx()];
      if (j == kInvalidIndex || j == (m + 1) % n || j == (m + n - 1) % n) continue;
      forbidden[m * n + j] = forbidden[j * n + m] = 1;
    }
  for (std::size_t m = 0; m < n; ++m) corner_of_[c[m].idx()] = kInvalidIndex;

  std::vector<Weight> w(n * n);
  std::vector<std::uint32_t> split(n * n, 0);
  std::vector<Vec3d> top(n * n);  // unit normal of the triangle on edge (i,k) in W(i,k)
  for (std::size_t d = 2; d < n; ++d) {
    for (std::size_t i = 0; i + d < n; ++i) {
      const std::size_t k = i + d;
      const bool closing = i == 0 && k == n - 1;
      Weight best{kInfinity, kInfinity};
      if (forbidden[i * n + k] && !closing) {
        w[i * n + k] = best;
        continue;
      }
      std::size_t best_m = 0;
      Vec3d best_normal{};
      for (std::size_t m = i + 1; m < k; ++m) {
        const Weight& left = w[i * n + m];
        const Weight& right = w[m * n + k];
        if (!left.valid() || !right.valid()) continue;
        Vec3d normal = cross(p[m] - p[i], p[k] - p[i]);
        double twice_area = norm(normal);
        double b = 2;  // a degenerate triangle: the worst angle, so it is used only when forced
        if (twice_area > 0) {
          normal /= twice_area;
          b = std::max(bend(normal, m == i + 1 ? across[i] : top[i * n + m]),
                       bend(normal, k == m + 1 ? across[m] : top[m * n + k]));
          if (closing) b = std::max(b, bend(normal, across[n - 1]));
        } else {
          normal = {};
        }
        Weight candidate{std::max({left.bend, right.bend, b}), left.area + right.area + 0.5 * twice_area};
        if (candidate.better_than(best)) {
          best = candidate;
          best_m = m;
          best_normal = normal;
        }
      }
      w[i * n + k] = best;
      split[i * n + k] = std::uint32_t(best_m);
      top[i * n + k] = best_normal;
    }
  }
  if (!w[n - 1].valid()) return false;

  // Cut the polygon along the chosen diagonals. A piece (i, k, z) is the polygon of corners
  // i..k closed by the half-edge z from k to i; e[m - 1] points to corner m inside it.
  struct Piece {
    std::size_t i, k;
    Halfedge z;
  };
  std::vector<Piece> stack{{0, n - 1, e[n - 1]}};
  while (!stack.empty()) {
    Piece piece = stack.back();
    stack.pop_back();
    const std::size_t i = piece.i, k = piece.k;
    if (k - i < 2) continue;
    const std::size_t m = split[i * n + k];
    Halfedge into_m = e[m - 1];
    if (m > i + 1) {
      Halfedge diagonal = mesh_.insert_edge(piece.z, e[m - 1]);  // i -> m
      add_patch_face(mesh_.face(diagonal));
      add_patch_face(mesh_.face(mesh_.opposite(diagonal)));
      stack.push_back({i, m, mesh_.opposite(diagonal)});
      into_m = diagonal;
    }
    if (k > m + 1) {
      Halfedge diagonal = mesh_.insert_edge(into_m, e[k - 1]);  // m -> k
      add_patch_face(mesh_.face(diagonal));
      add_patch_face(mesh_.face(mesh_.opposite(diagonal)));
      stack.push_back({m, k, mesh_.opposite(diagonal)});
    }
  }
  return true;
}

// For loops too long for the O(n³) programme: cut by the shortest diagonal that leaves at
// least a third of the corners on each side (so the depth is logarithmic), until the pieces
// are small, then triangulate each piece optimally.
void HoleFiller::cut_and_triangulate(Face f) {
  std::vector<Face> stack{f};
  std::size_t cuts = 0;
  while (!stack.empty()) {
    Face g = stack.back();
    stack.pop_back();
    std::vector<Halfedge> e;
    for (Halfedge h : mesh_.halfedges(g)) e.push_back(h);
    const std::size_t n = e.size();
    if (n <= std::max<std::size_t>(options_.piece_edges, 3)) {
      if (!triangulate_optimal(g)) fan(g);
      continue;
    }
    if (++cuts % 64 == 0) progress_.update(fraction_, "filling holes");
    std::vector<Vertex> c(n);
    std::vector<Vec3d> p(n);
    for (std::size_t m = 0; m < n; ++m) {
      c[m] = mesh_.from_vertex(e[m]);
      p[m] = position(mesh_, c[m]);
    }
    // Existing edges between corners cannot become diagonals.
    grow();
    std::vector<std::uint64_t> joined;
    for (std::size_t m = 0; m < n; ++m) corner_of_[c[m].idx()] = Index(m);
    for (std::size_t m = 0; m < n; ++m)
      for (Vertex u : mesh_.vertices(c[m]))
        if (Index j = corner_of_[u.idx()]; j != kInvalidIndex) joined.push_back(std::uint64_t(m) << 32 | j);
    for (std::size_t m = 0; m < n; ++m) corner_of_[c[m].idx()] = kInvalidIndex;
    std::sort(joined.begin(), joined.end());
    auto is_joined = [&](std::size_t a, std::size_t b) {
      return std::binary_search(joined.begin(), joined.end(), std::uint64_t(a) << 32 | b);
    };

    std::size_t best_i = 0, best_j = 0;
    double best = kInfinity;
    for (std::size_t least : {n / 3, std::size_t(2)}) {
      for (std::size_t i = 0; i < n; ++i)
        for (std::size_t j = i + least; j < n && j - i <= n - least; ++j) {
          double d = sqrnorm(p[j] - p[i]);
          if (d < best && !is_joined(i, j)) {
            best = d;
            best_i = i;
            best_j = j;
          }
        }
      if (best < kInfinity) break;
    }
    if (!(best < kInfinity)) {
      fan(g);
      continue;
    }
    Halfedge diagonal = mesh_.insert_edge(e[(best_i + n - 1) % n], e[best_j - 1]);
    add_patch_face(mesh_.face(diagonal));
    add_patch_face(mesh_.face(mesh_.opposite(diagonal)));
    stack.push_back(mesh_.face(diagonal));
    stack.push_back(mesh_.face(mesh_.opposite(diagonal)));
  }
}

// The last resort: a fan around a new vertex at the centroid. It needs no diagonal, so it
// works when every diagonal exists already.
void HoleFiller::fan(Face f) {
  std::vector<Vertex> corners;
  Vec3d centroid{};
  for (Vertex v : mesh_.vertices(f)) {
    corners.push_back(v);
    centroid += position(mesh_, v);
  }
  centroid /= double(corners.size());
  Vertex v = new_vertex(centroid, corners);
  mesh_.split_face(f, v);
  for (Face g : mesh_.faces(v)) add_patch_face(g);
}

// Liepa's flip test for an interior patch edge: swap it when the two angles facing it sum
// to more than pi (not locally Delaunay). Returns true when flipped.
bool HoleFiller::relax(Edge e) {
  if (!is_patch_edge(e)) return false;
  Halfedge h = mesh_.halfedge(e, 0), o = mesh_.halfedge(e, 1);
  if (mesh_.next(mesh_.next(mesh_.next(h))) != h || mesh_.next(mesh_.next(mesh_.next(o))) != o) return false;
  Vec3d a = position(mesh_, mesh_.to_vertex(h)), b = position(mesh_, mesh_.to_vertex(o));
  Vec3d c = position(mesh_, mesh_.to_vertex(mesh_.next(h))), d = position(mesh_, mesh_.to_vertex(mesh_.next(o)));
  if (angle_at(c, a, b) + angle_at(d, a, b) <= std::numbers::pi + 1e-9) return false;
  if (!mesh_.is_flip_ok(e)) return false;
  mesh_.flip(e);
  return true;
}

void HoleFiller::relax_all() {
  std::deque<Edge> queue;
  for (Face f : patch_)
    for (Edge e : mesh_.edges(f))
      if (is_patch_edge(e)) queue.push_back(e);
  // Each flip makes the patch more Delaunay; the cap only guards against cycling on
  // strongly curved patches where the 3D angle test is not a strict order.
  std::size_t budget = 20 * queue.size() + 100;
  while (!queue.empty() && budget > 0) {
    Edge e = queue.front();
    queue.pop_front();
    if (!relax(e)) continue;
    --budget;
    Halfedge h = mesh_.halfedge(e, 0), o = mesh_.halfedge(e, 1);
    for (Halfedge x : {mesh_.next(h), mesh_.prev(h), mesh_.next(o), mesh_.prev(o)}) queue.push_back(mesh_.edge(x));
  }
}

// Liepa's refinement: split a patch triangle at its centroid when the centroid is farther
// (times sqrt 2) from every corner than the density wanted there and at that corner, relax
// the edges, repeat until nothing splits. Densities are the border's mean edge lengths,
// interpolated inward, so the patch matches the sampling around it.
void HoleFiller::refine() {
  const double alpha = std::numbers::sqrt2;
  const std::size_t cap = std::max<std::size_t>(options_.max_new_vertices_per_hole, 1);

  // Too many vertices for the cap: scale the wanted density (a hole of 10,000 edges would
  // otherwise take ~20 million triangles).
  double area = 0, sigma2 = 0;
  for (Face f : patch_) {
    Halfedge h = mesh_.halfedge(f);
    area += triangle_area(position(mesh_, mesh_.to_vertex(h)), position(mesh_, mesh_.to_vertex(mesh_.next(h))),
                          position(mesh_, mesh_.to_vertex(mesh_.prev(h))));
  }
  for (Vertex v : border_) sigma2 += sigma_[v.idx()] * sigma_[v.idx()];
  sigma2 /= double(border_.size());
  if (sigma2 > 0) {
    // Vertices of an equilateral mesh of edge sigma over the area; the estimate runs low
    // (the border grades the density), so aim at half the cap.
    double expected = area / (std::sqrt(3.0) / 4 * sigma2) / 2;
    if (expected > 0.5 * double(cap)) {
      double scale = std::sqrt(expected / (0.5 * double(cap)));
      for (Vertex v : border_) sigma_[v.idx()] *= scale;
      report_.messages.push_back("a hole of " + std::to_string(border_.size()) + " edges was filled with triangles " +
                                 std::to_string(scale).substr(0, 4) +
                                 " times larger than its border's edges, to stay within " + std::to_string(cap) +
                                 " new vertices");
    }
  }
  for (Vertex v : new_vertices_) {  // vertices of a fan: as wanted as their neighbours
    double sum = 0;
    std::size_t k = 0;
    for (Vertex u : mesh_.vertices(v)) sum += sigma_[u.idx()], ++k;
    if (k) sigma_[v.idx()] = sum / double(k);
  }

  relax_all();
  for (int pass = 0; pass < 200; ++pass) {
    bool split = false;
    const std::size_t count = patch_.size();
    for (std::size_t q = 0; q < count && new_vertices_.size() < cap; ++q) {
      Face f = patch_[q];
      Halfedge h = mesh_.halfedge(f);
      Vertex corner[3] = {mesh_.to_vertex(h), mesh_.to_vertex(mesh_.next(h)), mesh_.to_vertex(mesh_.prev(h))};
      if (mesh_.next(mesh_.next(mesh_.next(h))) != h) continue;
      Vec3d p[3], centroid{};
      double sigma = 0;
      for (int k = 0; k < 3; ++k) {
        p[k] = position(mesh_, corner[k]);
        centroid += p[k];
        sigma += sigma_[corner[k].idx()];
      }
      centroid /= 3.0;
      sigma /= 3.0;
      bool wanted = true;
      for (int k = 0; k < 3 && wanted; ++k) {
        double d = alpha * distance(centroid, p[k]);
        wanted = d > sigma && d > sigma_[corner[k].idx()];
      }
      if (!wanted) continue;
      Edge sides[3] = {mesh_.edge(h), mesh_.edge(mesh_.next(h)), mesh_.edge(mesh_.prev(h))};
      Vertex v = new_vertex(centroid, corner);
      sigma_[v.idx()] = sigma;
      mesh_.split_face(f, v);
      for (Face g : mesh_.faces(v)) add_patch_face(g);
      for (Edge e : sides) relax(e);
      split = true;
    }
    if (!split) break;
    relax_all();
    progress_.update(fraction_, "refining hole patches");
  }
}

// Fairing: the new vertices minimise sum_j A_j |Δx_j|² over every vertex j whose Laplacian
// involves them (the patch and its border, whose outer neighbours are fixed), which is the
// discrete Δ²x = 0 with the surrounding two rings as boundary condition. The normal
// equations are symmetric positive definite; a sparse Cholesky factorisation solves them.
void HoleFiller::fair() {
  // Cotangent weights need triangles around every row's vertex, and a shape to measure:
  // the flat patch would give weights of a flat disc, so a uniform solve shapes it first.
  bool cotangent = options_.weights == FairingWeights::cotangent;
  if (cotangent)
    for (Vertex v : border_)
      for (Face f : mesh_.faces(v))
        if (mesh_.valence(f) != 3) cotangent = false;
  bool ok = solve_fairing(false);
  if (ok && cotangent) ok = solve_fairing(true);
  if (!ok) ++report_.fairing_failures;
}

bool HoleFiller::solve_fairing(bool cotangent) {
  grow();
  std::vector<Index>& free_index = corner_of_;  // reused: vertex -> unknown number
  for (std::size_t i = 0; i < new_vertices_.size(); ++i) free_index[new_vertices_[i].idx()] = Index(i);

  const std::size_t n = new_vertices_.size();
  std::vector<Eigen::Triplet<double>> triplets;
  Eigen::MatrixX3d rhs = Eigen::MatrixX3d::Zero(Eigen::Index(n), 3);
  std::vector<std::pair<Index, double>> row;  // (free index, weight)

  auto add_row = [&](Vertex j) {
    row.clear();
    Vec3d fixed{};
    double diagonal = 0, area = 0;
    const Vec3d pj = position(mesh_, j);
    for (Halfedge h : mesh_.outgoing(j)) {
      Vertex k = mesh_.to_vertex(h);
      double weight = 1;
      if (cotangent) {
        // (cot alpha + cot beta) / 2 for the angles facing the edge; clamped so that
        // slivers cannot make it explode.
        weight = 0;
        const Vec3d pk = position(mesh_, k);
        for (Halfedge g : {h, mesh_.opposite(h)}) {
          if (mesh_.is_boundary(g)) continue;
          const Vec3d po = position(mesh_, mesh_.to_vertex(mesh_.next(g)));
          Vec3d u = pj - po, v = pk - po;
          double s = norm(cross(u, v));
          weight += 0.5 * std::clamp(dot(u, v) / std::max(s, 1e-300), -1e3, 1e3);
        }
        if (!mesh_.is_boundary(h)) area += triangle_area(pj, pk, position(mesh_, mesh_.to_vertex(mesh_.next(h)))) / 3;
      }
      diagonal += weight;
      if (Index i = free_index[k.idx()]; i != kInvalidIndex)
        row.emplace_back(i, weight);
      else
        fixed += weight * position(mesh_, k);
    }
    if (Index i = free_index[j.idx()]; i != kInvalidIndex)
      row.emplace_back(i, -diagonal);
    else
      fixed -= diagonal * pj;
    if (row.empty()) return;
    // Uniform: the umbrella operator (weights 1/valence), every row counted once.
    // Cotangent: Δ = (1 / A) sum w (x_k - x_j), counted with area A, i.e. weight 1/A.
    double scale = 1;
    if (cotangent)
      scale = 1 / std::max(area, 1e-300);
    else
      scale = 1 / (diagonal * diagonal);
    for (auto [a, wa] : row) {
      for (auto [b, wb] : row) triplets.emplace_back(Eigen::Index(a), Eigen::Index(b), scale * wa * wb);
      for (int d = 0; d < 3; ++d) rhs(Eigen::Index(a), d) -= scale * wa * fixed[d];
    }
  };
  for (Vertex v : new_vertices_) add_row(v);
  for (Vertex v : border_) add_row(v);
  for (Vertex v : new_vertices_) free_index[v.idx()] = kInvalidIndex;

  const auto size = static_cast<Eigen::Index>(n);
  Eigen::SparseMatrix<double> matrix(size, size);
  matrix.setFromTriplets(triplets.begin(), triplets.end());
  triplets = {};
  progress_.update(fraction_, "fairing hole patches");
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver(matrix);
  bool ok = solver.info() == Eigen::Success;
  Eigen::MatrixX3d x;
  if (ok) {
    x = solver.solve(rhs);
    ok = solver.info() == Eigen::Success && x.allFinite();
  }
  if (!ok) return false;
  for (std::size_t i = 0; i < n; ++i)
    mesh_.position(new_vertices_[i]) =
        to_float(Vec3d{{x(Eigen::Index(i), 0), x(Eigen::Index(i), 1), x(Eigen::Index(i), 2)}});
  return true;
}

// Face attributes come from the nearest face across the border (breadth-first through the
// patch), corner attributes from each vertex's corner value, and internal bookkeeping
// takes its defaults (but for the orientation flag).
void HoleFiller::finish_attributes() {
  // in_patch_ is 1 for a patch face waiting for its attributes, 2 once it has them.
  // build()'s "hedge:flipped" is the exception to the defaults: extract() turns flipped
  // faces back as the host had them, and the patch must turn with its neighbours to stay
  // consistently oriented in the host's eyes.
  TypedArray<bool>* flipped = mesh_.face_properties().get<bool>(provenance::kFlipped);
  std::vector<std::pair<Face, Face>> queue;  // (patch face, face to copy from)
  std::size_t head = 0;
  for (Halfedge b : loop_)
    if (Face across = mesh_.face(mesh_.opposite(b)); across.is_valid()) queue.emplace_back(mesh_.face(b), across);
  for (Face f : patch_) in_patch_[f.idx()] = 1;
  while (head < queue.size()) {
    auto [f, from] = queue[head++];
    if (in_patch_[f.idx()] != 1) continue;
    in_patch_[f.idx()] = 2;  // attributes set
    copy_attributes(mesh_.face_properties(), from.idx(), f.idx());
    if (flipped) flipped->vector()[f.idx()] = bool(flipped->vector()[from.idx()]);
    for (Halfedge h : mesh_.halfedges(f)) {
      Face g = mesh_.face(mesh_.opposite(h));
      if (g.is_valid() && g.idx() < in_patch_.size() && in_patch_[g.idx()] == 1) queue.emplace_back(g, from);
    }
  }
  for (Face f : patch_) {
    in_patch_[f.idx()] = 1;
    for (Halfedge h : mesh_.halfedges(f)) {
      Index slot = slot_[mesh_.to_vertex(h).idx()];
      for (std::size_t k = 0; k < corner_channels_.size(); ++k)
        std::memcpy(corner_channels_[k]->element(h.idx()), corner_values_[k].element(slot), corner_values_[k].stride());
      reset_internal(mesh_.halfedge_properties(), h.idx());
      if (is_patch_edge(mesh_.edge(h))) reset_internal(mesh_.edge_properties(), mesh_.edge(h).idx());
    }
  }
  // The border half-edges were boundary (holding zeros) and are patch corners now, set
  // above; the faces and corners outside the patch are left as they were.
}

// A hole: `edges` consecutive half-edges of a boundary loop from `start`. Most holes are a
// whole loop; a piece (cut) is a stretch of a loop that comes back to the input vertex it
// left, a copy apart in the mesh: its polygon is the stretch's corners, closed by a new
// edge from the last one to the first that pairs with the stretch's last edge.
struct Hole {
  Halfedge start;
  std::size_t edges;
  bool cut = false;
};

std::vector<Halfedge> border_halfedges(const Mesh& mesh, const Hole& hole) {
  std::vector<Halfedge> border;
  for (Halfedge b = hole.start; border.size() < hole.edges; b = mesh.next(b)) border.push_back(b);
  return border;
}

// The pieces of the loop at `start` (which has split seam edges, and other edges): each
// stretch of non-seam edges that comes back, welded, to the vertex it left, shortest first.
// Returns how many non-seam edges no piece takes.
std::size_t cut_pieces(const Mesh& mesh, Halfedge start, const std::vector<bool>& seam,
                       const std::vector<std::uint64_t>& welded, std::vector<Hole>& pieces) {
  std::vector<Halfedge> loop;
  for (Halfedge b : mesh.loop(start)) loop.push_back(b);
  auto is_seam = [&](Halfedge b) { return bool(seam[Mesh::edge(b).idx()]); };
  std::rotate(loop.begin(), std::find_if(loop.begin(), loop.end(), is_seam), loop.end());
  std::size_t open = 0;
  std::unordered_map<std::uint64_t, std::size_t> left;  // welded vertex -> position leaving it
  for (std::size_t k = 0; k < loop.size(); ++k) {
    const Halfedge b = loop[k];
    if (is_seam(b)) {
      left.clear();
      continue;
    }
    ++open;
    if (left.empty()) left.emplace(welded[mesh.from_vertex(b).idx()], k);
    const std::uint64_t w = welded[mesh.to_vertex(b).idx()];
    const auto [back, first_visit] = left.emplace(w, k + 1);
    if (first_visit) continue;
    const std::size_t a = back->second, edges = k + 1 - a;
    if (edges >= 3 && !mesh.find_halfedge(mesh.from_vertex(b), mesh.from_vertex(loop[a])).is_valid()) {
      pieces.push_back({loop[a], edges, true});
      open -= edges;
    }
    left.clear();
    left.emplace(w, k + 1);
  }
  return open;
}

using WeldedTriangle = std::array<std::uint64_t, 3>;

// The welded ids of three vertices, sorted: the same triangle whichever copies it joins.
WeldedTriangle welded_triangle(const std::vector<std::uint64_t>& welded, Vertex a, Vertex b, Vertex c) {
  WeldedTriangle t{welded[a.idx()], welded[b.idx()], welded[c.idx()]};
  std::sort(t.begin(), t.end());
  return t;
}

// The triangles of `mesh` by their welded corners (each sorted), in order.
std::vector<WeldedTriangle> welded_triangles(const Mesh& mesh, const std::vector<std::uint64_t>& welded) {
  std::vector<WeldedTriangle> triangles;
  for (Face f : mesh.faces()) {
    if (mesh.valence(f) != 3) continue;
    const Halfedge h = mesh.halfedge(f);
    triangles.push_back(
        welded_triangle(welded, mesh.to_vertex(h), mesh.to_vertex(mesh.next(h)), mesh.to_vertex(mesh.prev(h))));
  }
  std::sort(triangles.begin(), triangles.end());
  return triangles;
}

// Puts one face on a piece: a face over its whole loop, split by the edge from the piece's
// last corner to its first, and the rest of the loop opened again.
Face cut_off(Mesh& mesh, const Hole& piece) {
  Halfedge last = piece.start;
  for (std::size_t i = 2; i < piece.edges; ++i) last = mesh.next(last);
  const Halfedge before = mesh.prev(piece.start);
  mesh.fill_hole(piece.start);
  const Halfedge closing = mesh.insert_edge(last, before);
  mesh.delete_face(mesh.face(Mesh::opposite(closing)));
  return mesh.face(closing);
}

}  // namespace

FillHolesReport fill_holes(Mesh& input, const FillHolesOptions& options, Progress& progress) {
  FillHolesReport report;
  progress.update(0, "finding holes");

  // Find the boundary loops first: filling one never changes another.
  std::vector<Hole> holes;
  {
    std::vector<char> seen(input.halfedges_size(), 0);
    for (Halfedge h : input.halfedges()) {
      if (!input.is_boundary(h) || seen[h.idx()]) continue;
      std::size_t edges = 0;
      for (Halfedge b : input.loop(h)) {
        seen[b.idx()] = 1;
        ++edges;
      }
      holes.push_back({h, edges});
    }
  }
  // Loops along edges that build() split apart (non-manifold input) are no holes: in the
  // input the surface goes on across every one of their edges. Where a loop has such edges
  // and others, its holes are the stretches of the others that come back to the input
  // vertex they left; what is left of it stays open, since a patch would give the split
  // edges another face.
  const std::vector<bool> seam = split_seam_edges(input);
  const std::vector<std::uint64_t> welded = welded_vertex_ids(input);
  std::vector<Hole> pieces;
  if (!seam.empty())
    std::erase_if(holes, [&](const Hole& hole) {
      std::size_t seams = 0;
      for (Halfedge b : input.loop(hole.start)) seams += seam[Mesh::edge(b).idx()];
      if (seams == 0) return false;
      if (seams == hole.edges)
        ++report.split_seams;
      else if (cut_pieces(input, hole.start, seam, welded, pieces))
        ++report.holes_on_seams;
      return true;
    });
  holes.insert(holes.end(), pieces.begin(), pieces.end());
  report.holes_found = holes.size() + report.holes_on_seams;

  std::vector<Hole> to_fill;
  std::size_t total_edges = 0;
  const std::vector<std::uint8_t> selected =
      options.selection_only ? detail::selected_vertices(input) : std::vector<std::uint8_t>();
  std::vector<WeldedTriangle> triangles;  // welded_triangles(), once a piece needs them
  for (const Hole& hole : holes) {
    const std::vector<Halfedge> border = border_halfedges(input, hole);
    if (!selected.empty()) {
      bool all = true;
      for (Halfedge b : border) all = all && selected[input.from_vertex(b).idx()];
      if (!all) {
        ++report.holes_not_selected;
        continue;
      }
    }
    if (options.max_hole_edges && hole.edges > options.max_hole_edges) {
      ++report.holes_too_large;
      report.largest_skipped_edges = std::max(report.largest_skipped_edges, hole.edges);
      continue;
    }
    if (hole.edges < 3) {  // two edges joining the same two vertices: no triangle fits
      ++report.slits;
      continue;
    }
    // The border of a lone polygon: filling it would only add the same face backwards.
    Face only = input.face(Mesh::opposite(hole.start));
    bool lone = true;
    for (Halfedge b : border)
      if (input.face(Mesh::opposite(b)) != only) lone = false;
    bool doubled = false;
    if (hole.edges == 3 && !hole.cut) doubled = triangle_exists(input, hole.start);
    if (hole.edges == 3 && hole.cut) {  // the same test through the weld
      if (triangles.empty()) triangles = welded_triangles(input, welded);
      const WeldedTriangle t = welded_triangle(welded, input.from_vertex(border[0]), input.from_vertex(border[1]),
                                               input.from_vertex(border[2]));
      doubled = std::binary_search(triangles.begin(), triangles.end(), t);
    }
    if (lone || doubled) {
      ++report.lone_faces;
      continue;
    }
    to_fill.push_back(hole);
    total_edges += hole.edges;
  }
  report.holes_skipped =
      report.holes_too_large + report.lone_faces + report.slits + report.holes_not_selected + report.holes_on_seams;
  if (report.holes_too_large)
    report.messages.push_back(std::to_string(report.holes_too_large) + " holes with more than " +
                              std::to_string(options.max_hole_edges) + " edges left open (the largest has " +
                              std::to_string(report.largest_skipped_edges) + ")");
  if (report.lone_faces)
    report.messages.push_back(std::to_string(report.lone_faces) +
                              " holes left open that a face on the same corners would fill (a single face's "
                              "other side): filling would only double that face");
  if (report.split_seams)
    report.messages.push_back(std::to_string(report.split_seams) +
                              " boundary loops along non-manifold edges left open (the input's surface is "
                              "closed there; building split the edges to work on them)");
  if (report.holes_on_seams)
    report.messages.push_back(std::to_string(report.holes_on_seams) +
                              " holes left open whose border runs in part along non-manifold edges (building "
                              "split them apart): a patch would give those edges another face");
  if (report.slits)
    report.messages.push_back(std::to_string(report.slits) +
                              " holes of two edges left open (no triangle fits them; repair removes them)");
  if (to_fill.empty()) return report;

  // Work on a copy so that a failure or a cancel leaves the input as it was.
  Mesh mesh = input;
  const std::size_t vertices_before = mesh.n_vertices(), faces_before = mesh.n_faces();
  HoleFiller filler(mesh, options, report, progress);
  std::size_t done_edges = 0;
  for (const Hole& hole : to_fill) {
    const double fraction = double(done_edges) / double(total_edges);
    progress.update(fraction, "filling holes");
    filler.fill(hole.cut ? cut_off(mesh, hole) : mesh.fill_hole(hole.start), fraction);
    done_edges += hole.edges;
    ++report.holes_filled;
  }
  report.vertices_added = mesh.n_vertices() - vertices_before;
  report.triangles_added = mesh.n_faces() - faces_before;
  if (mesh.has_garbage()) mesh.compact();  // the faces cut_off() opened again
  if (report.fairing_failures)
    report.messages.push_back(std::to_string(report.fairing_failures) +
                              " patches could not be faired (singular system) and keep their refined shape");
  input = std::move(mesh);
  progress.update(1, "holes filled");
  return report;
}

Operation fill_holes_operation() {
  const char* help =
      "Closes the holes of a surface (Liepa, \"Filling holes in meshes\", SGP 2003). Each boundary loop is "
      "triangulated by dynamic programming, minimising the largest dihedral angle and then the area "
      "(Barequet-Sharir weight), so the patch meets the surface as flatly as possible; loops longer than 300 "
      "edges are first cut by short diagonals into pieces. 'refine' splits and relaxes the patch until its "
      "triangles are sized like those around the hole; 'fair' then solves the bi-Laplacian (cotangent "
      "weights, two rings of the surface as boundary condition) for the new vertices so the patch continues "
      "the surface's curvature. Every boundary loop "
      "within the size limit is filled, as MeshLab's Close Holes does, including the single border of an "
      "open sheet; a lone face's border is not. New vertices interpolate the vertex attributes (colour, "
      "quality, normals...), new faces copy those of the nearest face across the hole, and per-corner "
      "attributes such as UVs are carried in from the border. Use it to make a scan watertight before "
      "printing, booleans or volume measures.";
  using O = FillHolesOptions;
  using R = FillHolesReport;
  return Binding<O, R>("fill_holes", "Fill Holes", Category::cleaning, help, fill_holes)
      .option(&O::max_hole_edges, "max_hole_edges", "Max hole size (edges)", between(0, kMaxCorners),
              "Holes with more boundary edges are left open and reported; 0 fills every hole.")
      .option(&O::refine, "refine", "Refine patch",
              "Split and relax the new triangles until they are sized like their surroundings.")
      .option(&O::fair, "fair", "Fair patch",
              "Move the new vertices so the patch is smooth and blends with the surface "
              "(bi-Laplacian, Δ²x = 0).")
      .selection(&O::selection_only, "Only holes whose border is selected are filled (every border vertex).")
      .result(&R::holes_found, "holes_found")
      .result(&R::holes_filled, "holes_filled")
      .result(&R::holes_skipped, "holes_skipped")
      .result(&R::holes_too_large, "holes_too_large")
      .result("holes_not_selected",
              [](const O& o, const R& r) -> std::optional<Value> {
                if (!o.selection_only) return std::nullopt;
                return field_value(r.holes_not_selected);
              })
      .result(&R::lone_faces, "lone_faces_left_open")
      .result(&R::slits, "two_edge_slits_left_open")
      .result(&R::holes_on_seams, "holes_on_non_manifold_edges_left_open")
      .result(&R::split_seams, "non_manifold_seams_left_open")
      .result(&R::triangles_added, "triangles_added")
      .result(&R::vertices_added, "vertices_added")
      .messages(&R::messages);
}

}  // namespace hedge
