// Isotropic remeshing (Botsch & Kobbelt 2004, "A remeshing approach to multiresolution
// modeling"): the algorithm of remesh.h and its catalogue entry.
#include "hedge/remesh.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <numbers>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "binding.h"
#include "hedge/distance.h"
#include "hedge/error.h"
#include "hedge/geometry.h"
#include "hedge/provenance.h"
#include "hedge/threads.h"
#include "parallel.h"
#include "selection.h"
#include "spatial_order.h"
#include "welded_copies.h"

namespace hedge {
namespace {

// Edge flags.
constexpr std::uint8_t kFeature = 1;  // only split: never collapsed, never flipped
constexpr std::uint8_t kCurve = 2;    // a crease or a free boundary: its vertices slide along it
constexpr std::uint8_t kPinned = 4;   // preserved boundary or attribute seam: its vertices stay put
constexpr std::uint8_t kFrozen = 8;   // with selection_only, on a face outside the selection: not even split

// What a vertex may do.
enum class Kind : std::uint8_t { free, sliding, fixed };

// Smoothing steps per iteration before projecting; one is Botsch & Kobbelt's choice, two
// give more edges near the target (dragon_res2: 92% in band against 90%) for little time.
constexpr int kSmoothingSteps = 2;

// A flip for valence may not make the smallest angle of its two triangles smaller than it
// was when that leaves an angle below this (degrees).
constexpr double kFlipMinAngleDegrees = 10;

// Adaptive sizing: the chord error allowed per target length, and the bounds of the sizes.
constexpr double kAdaptiveTolerance = 0.05;
constexpr double kAdaptiveMin = 0.25, kAdaptiveMax = 2.0;

// Rounds of the split pass per iteration (each halves the edges still too long); edges longer
// than 2^kMaxSplitRounds times the target wait for the next iteration.
constexpr int kMaxSplitRounds = 16;

// No collapse merges two vertices whose valences add up to more than this (see may_collapse).
constexpr std::int32_t kMaxCollapseValence = 40;

// The collapse and flip passes in regions (Remesher::run_in_regions): from this many faces
// on, in kPhases phases of regions of about kRegionVertices vertices, at least kMinRegions.
constexpr std::size_t kRegionsMinFaces = 50000;
constexpr std::size_t kRegionVertices = 16384;
constexpr std::size_t kMinRegions = 32;
constexpr int kPhases = 2;
constexpr std::uint16_t kNoRegion = detail::RegionPartitions::kNone;

// The area of the surface, polygons as fans of their vector area, in double precision (float
// squares overflow near 1e19 and underflow near 1e-19).
double surface_area(const Mesh& mesh) {
  double area = 0;
  for (Face f : mesh.faces()) {
    Vec3d first{}, previous{}, normal{};
    int k = 0;
    for (Vertex v : mesh.vertices(f)) {
      const Vec3d p = to_double(mesh.position(v));
      if (k == 0)
        first = p;
      else if (k >= 2)
        normal += cross(previous - first, p - first);
      previous = p;
      ++k;
    }
    area += 0.5 * norm(normal);
  }
  return area;
}

// The per-vertex passes: threads (hedge::thread_count()) pay off from 16384 vertices.
template <class F>
void parallel_for(std::size_t n, F&& work) {
  hedge::parallel_for(n, 0, std::forward<F>(work), 8192);
}

class Remesher {
 public:
  Remesher(Mesh& mesh, const Mesh& input, const RemeshOptions& options, Progress& progress)
      : mesh_(mesh), input_(input), options_(options), progress_(progress), copies_(mesh) {}

  RemeshReport run();

 private:
  // ---- setup ----
  void classify();
  void compute_sizing();
  bool sharp_turn(Vertex v, double cos_feature) const;
  Kind kind_of_new_vertex(std::uint8_t edge_flags) const {
    return (edge_flags & kPinned) ? Kind::fixed : (edge_flags & kCurve) ? Kind::sliding : Kind::free;
  }

  // ---- the four steps ----
  void split_long_edges();
  void collapse_short_edges();
  void equalize_valences();
  // The collapse and flip passes: every edge once, then the edges near each change.
  enum class Pass : std::uint8_t { collapse, flip };
  // A pass's loop state: the whole mesh's, or one region's during a phase.
  struct Worker {
    std::uint16_t region = kNoRegion;  // changes only inside it; kNoRegion: anywhere
    std::vector<Edge> pending;         // edges near a change, to visit again
    std::vector<Edge> deferred;        // a region's: edges whose neighbourhood leaves it
    Mesh::Deletions tally;
    std::size_t changes = 0;
  };
  std::size_t run_pass(Pass pass);  // returns the number of changes
  void run_in_regions(Pass pass);
  bool is_candidate(Pass pass, Edge e) const;
  void visit(Pass pass, Edge e, Worker& w);  // e, then the edges its changes put on w.pending
  bool in_region(Vertex v, std::uint16_t region) const { return region_[v.idx()] == region && !copies_.is_copy(v); }
  bool rings_inside(Vertex a, Vertex b, std::uint16_t region) const;
  bool is_short(Edge e) const {  // live, no feature, and below 4/5 of its target length
    if (mesh_.is_deleted(e) || (edge_flags_[e.idx()] & kFeature)) return false;
    const Vertex a = mesh_.vertex(e, 0), b = mesh_.vertex(e, 1);
    const double lo = 0.8 * size(a, b);
    return length_sq(a, b) < lo * lo;
  }
  bool collapse_if_short(Edge e, Worker& w);
  bool flip_if_better(Edge e, Worker& w);
  bool is_cap(Edge e) const;  // an angle at e's opposite corners near 180 degrees
  bool open_cap(Edge e);
  void open_caps();
  void smooth_and_project();
  void resample_attributes();

  double size(Vertex a, Vertex b) const {
    return sizing_.empty() ? length_ : 0.5 * (sizing_[a.idx()] + sizing_[b.idx()]);
  }
  double length_sq(Vertex a, Vertex b) const {
    return sqrnorm(to_double(mesh_.position(a)) - to_double(mesh_.position(b)));
  }
  bool star_ok(Vertex v, Vertex other, const Vec3d& target) const;
  bool may_collapse(Halfedge h, const Vec3d& target) const;
  bool makes_twin_triangle(Halfedge h) const;
  void grow_vertex_arrays();

  // The input halfedges whose targets are the corners of surface triangle t, in the order
  // the tree holds them (polygons are fanned from corner 0).
  std::array<Halfedge, 3> input_corners(Index t) const;

  Mesh& mesh_;
  const Mesh& input_;
  const RemeshOptions& options_;
  Progress& progress_;
  const detail::WeldedCopies copies_;  // build()'s copies: no flip, split or collapse may meet their weld
  RemeshReport report_;
  double length_ = 0;  // the target edge length L

  TriangleTree surface_;               // the input surface, for projection
  TriangleTree curves_;                // the input's sliding curves (creases, free boundary) as degenerate triangles
  std::vector<Index> first_triangle_;  // input face -> its first triangle in surface_

  std::vector<std::uint8_t> edge_flags_;
  std::vector<Kind> kind_;
  struct Degree {
    std::int32_t valence = 0, target = 6;  // target: 6 inside, 4 on the boundary
  };
  std::vector<Degree> degree_;
  std::vector<Edge> work_;  // pending edges of the cap-opening sweep
  std::vector<Index> surface_hint_, curve_hint_;
  std::vector<double> sizing_;                    // per vertex, adaptive only
  std::vector<double> input_sizing_;              // per input vertex, adaptive only
  std::vector<Point> scratch_;                    // smoothed positions
  std::vector<Index> move_order_, order_starts_;  // smooth_and_project()'s order of the vertices
  std::vector<PropertyArray*> vertex_arrays_;     // blended on splits (non-internal)
  std::vector<PropertyArray*> corner_arrays_;     // continued on collapses (non-internal)
  const std::uint16_t* region_ = nullptr;         // during a phase: each vertex's region
  std::vector<Worker> workers_;                   // one per region
  std::vector<Edge> deferred_;                    // the candidates no region could take
  std::vector<std::vector<Edge>> offered_;        // a phase's edges, per part and region
  std::vector<std::vector<Edge>> carried_;        // per part: its candidates across borders
  detail::RegionPartitions partitions_;           // made by the first run_in_regions()
};

std::array<Halfedge, 3> Remesher::input_corners(Index t) const {
  Face f = surface_.face(t);
  Halfedge h0 = input_.halfedge(f);
  Halfedge hk = input_.next(h0);
  for (Index k = first_triangle_[f.idx()]; k < t; ++k) hk = input_.next(hk);
  return {h0, hk, input_.next(hk)};
}

void Remesher::grow_vertex_arrays() {
  const std::size_t n = mesh_.vertices_size();
  kind_.resize(n, Kind::free);
  degree_.resize(n);
  surface_hint_.resize(n, kInvalidIndex);
  curve_hint_.resize(n, kInvalidIndex);
  if (options_.adaptive) sizing_.resize(n, length_);
}

// Features, boundaries, seams, and what each vertex may do.
void Remesher::classify() {
  const double cos_feature = std::cos(options_.feature_angle * std::numbers::pi / 180.0);
  const bool detect_features = options_.feature_angle < 180.0;
  edge_flags_.assign(mesh_.edges_size(), 0);

  // Attribute seams: edges across which a face channel, or a corner channel at either end,
  // changes. Keeping them (pinned) keeps texture charts, materials and hard normals intact.
  std::vector<const ChannelArray*> corner_channels, face_channels;
  for (std::size_t i = 0; i < mesh_.halfedge_properties().count(); ++i) {
    const PropertyArray& a = mesh_.halfedge_properties().at(i);
    if (a.type() == typeid(ChannelArray) && !a.is_internal())
      corner_channels.push_back(static_cast<const ChannelArray*>(&a));
  }
  for (std::size_t i = 0; i < mesh_.face_properties().count(); ++i) {
    const PropertyArray& a = mesh_.face_properties().at(i);
    if (a.type() == typeid(ChannelArray) && !a.is_internal())
      face_channels.push_back(static_cast<const ChannelArray*>(&a));
  }
  auto same = [](const ChannelArray* c, Index a, Index b) { return c->same(a, b); };

  const std::vector<std::uint8_t> selected =
      options_.selection_only ? detail::selected_faces(mesh_) : std::vector<std::uint8_t>();
  auto outside = [&](Halfedge h) { return !mesh_.is_boundary(h) && !selected[mesh_.face(h).idx()]; };
  for (Edge e : mesh_.edges()) {
    Halfedge h0 = Mesh::halfedge(e, 0), h1 = Mesh::halfedge(e, 1);
    std::uint8_t& flags = edge_flags_[e.idx()];
    if (!selected.empty() && (outside(h0) || outside(h1))) {
      flags = kFeature | kPinned | kFrozen;  // its vertices are pinned too, so the border stays
      continue;
    }
    if (mesh_.is_boundary(e)) {
      flags = options_.preserve_boundary ? (kFeature | kPinned) : kCurve;
      continue;
    }
    Face f0 = mesh_.face(h0), f1 = mesh_.face(h1);
    bool seam = false;
    for (const ChannelArray* c : face_channels) seam = seam || !same(c, f0.idx(), f1.idx());
    for (const ChannelArray* c : corner_channels)
      seam = seam || !same(c, h0.idx(), mesh_.prev(h1).idx()) || !same(c, h1.idx(), mesh_.prev(h0).idx());
    if (seam) {
      flags = kFeature | kPinned;
      continue;
    }
    if (detect_features) {
      Vec3d a = to_double(mesh_.position(mesh_.to_vertex(h1))), b = to_double(mesh_.position(mesh_.to_vertex(h0)));
      Vec3d c = to_double(mesh_.position(mesh_.to_vertex(mesh_.next(h0))));
      Vec3d d = to_double(mesh_.position(mesh_.to_vertex(mesh_.next(h1))));
      Vec3d n0 = cross(b - a, c - a), n1 = cross(a - b, d - b);
      double l0 = norm(n0), l1 = norm(n1);
      if (l0 > 0 && l1 > 0 && dot(n0, n1) < cos_feature * l0 * l1) flags = kFeature | kCurve;
    }
  }

  // Vertices: on a pinned edge or where other than two curves meet, fixed; on exactly two
  // curve edges, sliding. Copies of one source vertex (split by build() at a non-manifold
  // spot) must stay together to be welded back, so they are fixed too.
  const std::size_t nv = mesh_.vertices_size();
  kind_.assign(nv, Kind::free);
  degree_.assign(nv, Degree{});
  std::vector<std::uint32_t> copies;
  const TypedArray<std::uint32_t>* source = mesh_.vertex_properties().get<std::uint32_t>(provenance::kVertexSource);
  if (source) {
    std::uint32_t max_source = 0;
    for (std::uint32_t s : source->vector())
      if (s != kInvalidIndex) max_source = std::max(max_source, s);
    copies.assign(std::size_t(max_source) + 1, 0);
    for (Vertex v : mesh_.vertices())
      if (std::uint32_t s = source->vector()[v.idx()]; s != kInvalidIndex) ++copies[s];
  }
  for (Vertex v : mesh_.vertices()) {
    int curve = 0, pinned = 0, valence = 0;
    for (Halfedge h : mesh_.outgoing(v)) {
      std::uint8_t f = edge_flags_[Mesh::edge(h).idx()];
      curve += (f & kCurve) ? 1 : 0;
      pinned += (f & kPinned) ? 1 : 0;
      ++valence;
    }
    degree_[v.idx()] = {valence, mesh_.is_boundary(v) ? 4 : 6};
    Kind k = Kind::free;
    if (mesh_.is_isolated(v) || pinned > 0 || (curve != 0 && curve != 2))
      k = Kind::fixed;
    else if (curve == 2)
      k = sharp_turn(v, cos_feature) ? Kind::fixed : Kind::sliding;
    if (source) {
      std::uint32_t s = source->vector()[v.idx()];
      if (s != kInvalidIndex && copies[s] > 1) k = Kind::fixed;
    }
    kind_[v.idx()] = k;
    if (k == Kind::fixed) ++report_.fixed_vertices;
  }
  for (std::uint8_t f : edge_flags_)
    if ((f & kFeature) && !(f & kPinned)) ++report_.feature_edges;

  // The curves sliding vertices are projected back onto, as degenerate triangles (a, b, b).
  std::vector<std::array<Index, 3>> segments;
  for (Edge e : mesh_.edges())
    if (edge_flags_[e.idx()] & kCurve) {
      Index a = mesh_.vertex(e, 0).idx(), b = mesh_.vertex(e, 1).idx();
      segments.push_back({a, b, b});
    }
  if (!segments.empty()) curves_ = TriangleTree(mesh_.positions(), segments);
}

// Whether the curve through v (its two curve edges) turns by more than the feature angle:
// the corner of a square boundary stays where it is.
bool Remesher::sharp_turn(Vertex v, double cos_feature) const {
  const Vec3d p = to_double(mesh_.position(v));
  Vec3d d[2];
  int n = 0;
  for (Halfedge h : mesh_.outgoing(v))
    if ((edge_flags_[Mesh::edge(h).idx()] & kCurve) && n < 2)
      d[n++] = to_double(mesh_.position(mesh_.to_vertex(h))) - p;
  if (n != 2) return true;
  double l0 = norm(d[0]), l1 = norm(d[1]);
  if (!(l0 > 0 && l1 > 0)) return true;
  // Straight on: d0 = -d1. The turn is the angle between d0 and -d1.
  return -dot(d[0], d[1]) < cos_feature * l0 * l1;
}

// Curvature-driven sizes on the input (adaptive mode): from the largest principal
// curvature k and a chord tolerance e, the edge length sqrt(6 e / k - 3 e^2) keeps the
// surface within e (pmp-library's adaptive remeshing), bounded around the target.
void Remesher::compute_sizing() {
  const std::size_t nv = mesh_.vertices_size();
  std::vector<double> area(nv, 0), angle_sum(nv, 0), kappa(nv, -1);
  std::vector<Vec3d> laplace(nv, Vec3d{});
  for (Face f : mesh_.faces()) {
    Halfedge h = mesh_.halfedge(f);
    Vertex v[3] = {mesh_.to_vertex(h), mesh_.to_vertex(mesh_.next(h)), mesh_.to_vertex(mesh_.prev(h))};
    Vec3d p[3];
    for (int k = 0; k < 3; ++k) p[k] = to_double(mesh_.position(v[k]));
    double a2 = norm(cross(p[1] - p[0], p[2] - p[0]));
    for (int k = 0; k < 3; ++k) {
      int i = k, j = (k + 1) % 3, l = (k + 2) % 3;
      Vec3d e1 = p[j] - p[i], e2 = p[l] - p[i];
      double s = norm(cross(e1, e2)), c = dot(e1, e2);
      angle_sum[v[i].idx()] += std::atan2(s, c);
      double cot = s > 0 ? std::clamp(c / s, -1e3, 1e3) : 0.0;
      laplace[v[j].idx()] += (p[l] - p[j]) * cot;
      laplace[v[l].idx()] += (p[j] - p[l]) * cot;
      area[v[i].idx()] += a2 / 6.0;
    }
  }
  for (Vertex v : mesh_.vertices()) {
    const Index i = v.idx();
    if (mesh_.is_boundary(v) || !(area[i] > 0)) continue;
    double h = norm(laplace[i]) / (4.0 * area[i]);  // |mean curvature normal| / 2
    double k = (2 * std::numbers::pi - angle_sum[i]) / area[i];
    kappa[i] = std::abs(h) + std::sqrt(std::max(0.0, h * h - k));
  }
  // Scans are noisy: average over the one-ring twice (vertices without an estimate, on
  // the boundary, take their neighbours' mean).
  std::vector<double> next(nv);
  for (int pass = 0; pass < 3; ++pass) {
    for (Vertex v : mesh_.vertices()) {
      double sum = kappa[v.idx()] >= 0 ? kappa[v.idx()] : 0;
      int n = kappa[v.idx()] >= 0 ? 1 : 0;
      for (Vertex w : mesh_.vertices(v))
        if (kappa[w.idx()] >= 0) sum += kappa[w.idx()], ++n;
      next[v.idx()] = n ? sum / n : -1;
    }
    kappa.swap(next);
  }
  const double e = kAdaptiveTolerance * length_;
  input_sizing_.assign(nv, length_);
  for (Vertex v : mesh_.vertices()) {
    double k = kappa[v.idx()];
    double s = kAdaptiveMax * length_;
    if (k > 0) {
      double q = 6 * e / k - 3 * e * e;
      s = q > 0 ? std::sqrt(q) : 0;
    }
    input_sizing_[v.idx()] = std::clamp(s, kAdaptiveMin * length_, kAdaptiveMax * length_);
  }
  sizing_ = input_sizing_;
}

void Remesher::split_long_edges() {
  // In rounds, as pmp does: each round halves every edge that is still too long, once. Splitting
  // one edge again and again until short instead, new edges included, fans every split out to
  // the same far corner and multiplies slivers: a coarse mesh far above the target (a single
  // polygon of a few hundred corners) then grew to millions of triangles in the first pass.
  // Rounds refine evenly, about 4x per round, so the pass ends near area / L^2 triangles.
  // A split moves no vertex, so an edge that was short enough stays so: the first round
  // measures every edge (on all threads), the next ones only the edges the last round made
  // or left too long. Each round takes its edges in index order, as one sweep would.
  auto too_long = [&](Index i) {
    const Edge e(i);
    if (mesh_.is_deleted(e) || (edge_flags_[i] & kFrozen)) return false;
    const Vertex a = mesh_.vertex(e, 0), b = mesh_.vertex(e, 1);
    const double hi = 4.0 / 3.0 * size(a, b);
    return length_sq(a, b) > hi * hi;  // not with a NaN size
  };
  std::vector<Index> edges;
  {
    const std::size_t n = mesh_.edges_size();
    const std::size_t parts = std::max<std::size_t>(1, std::min<std::size_t>(thread_count(), n / 16384));
    std::vector<std::vector<Index>> found(parts);
    hedge::parallel_for(
        parts, 0,
        [&](std::size_t begin, std::size_t end) {
          for (std::size_t k = begin; k < end; ++k)
            for (std::size_t i = n * k / parts; i < n * (k + 1) / parts; ++i)
              if (too_long(Index(i))) found[k].push_back(Index(i));
        },
        1);
    for (const std::vector<Index>& f : found) edges.insert(edges.end(), f.begin(), f.end());
  }
  std::vector<Index> again;
  for (int round = 0; round < kMaxSplitRounds && !edges.empty(); ++round) {
    bool split = false;
    const Index n = static_cast<Index>(mesh_.edges_size());
    again.clear();
    for (Index i : edges) {
      if (!too_long(i)) continue;
      again.push_back(i);  // split in two, or skipped: measured again next round
      const Edge e(i);
      Halfedge h0 = Mesh::halfedge(e, 0), h1 = Mesh::halfedge(e, 1);
      Vertex a = mesh_.to_vertex(h1), b = mesh_.to_vertex(h0);
      Vertex c = mesh_.is_boundary(h0) ? Vertex() : mesh_.to_vertex(mesh_.next(h0));
      Vertex d = mesh_.is_boundary(h1) ? Vertex() : mesh_.to_vertex(mesh_.next(h1));
      // Two triangles on the same third corner (a pillow, left by build() at non-manifold
      // spots) cannot be split: the new vertex would be joined to that corner twice. The
      // same holds for two copies of one corner, which the weld makes one; and an edge the
      // weld makes one with another (a split non-manifold edge) would have the new vertex on
      // one copy only.
      if (c.is_valid() && d.is_valid() && copies_.same(c, d)) continue;
      if (copies_.any() && copies_.edge_elsewhere(mesh_, a, b, e)) continue;

      Vertex v = mesh_.add_vertex(to_float((to_double(mesh_.position(a)) + to_double(mesh_.position(b))) * 0.5));
      if (partitions_.size()) partitions_.append_like(a.idx());
      const Index from[2] = {a.idx(), b.idx()};
      const float half[2] = {0.5f, 0.5f};
      for (PropertyArray* p : vertex_arrays_) p->interpolate(v.idx(), from, half);
      mesh_.split_edge_triangles(e, v);

      const std::uint8_t flags = edge_flags_[i];
      edge_flags_.resize(mesh_.edges_size(), 0);
      edge_flags_[Mesh::edge(mesh_.find_halfedge(v, b)).idx()] = flags;
      grow_vertex_arrays();
      kind_[v.idx()] = kind_of_new_vertex(flags);
      degree_[v.idx()] = {2 + (c.is_valid() ? 1 : 0) + (d.is_valid() ? 1 : 0), c.is_valid() && d.is_valid() ? 6 : 4};
      if (c.is_valid()) ++degree_[c.idx()].valence;
      if (d.is_valid()) ++degree_[d.idx()].valence;
      surface_hint_[v.idx()] = surface_hint_[a.idx()];
      curve_hint_[v.idx()] = curve_hint_[a.idx()] != kInvalidIndex ? curve_hint_[a.idx()] : curve_hint_[b.idx()];
      if (!sizing_.empty()) sizing_[v.idx()] = 0.5 * (sizing_[a.idx()] + sizing_[b.idx()]);
      ++report_.splits;
      split = true;
    }
    if (!split) break;
    for (Index i = n; i < mesh_.edges_size(); ++i) again.push_back(i);
    std::swap(edges, again);
  }
}

// Whether moving v (one end of an edge whose other end is `other`) to `target` keeps
// every edge at v below 4/3 of its target length and every triangle at v facing the same
// way. The triangles on the edge itself disappear in the collapse and are skipped.
bool Remesher::star_ok(Vertex v, Vertex other, const Vec3d& target) const {
  const Vec3d p = to_double(mesh_.position(v));
  int joins = 0;
  for (Halfedge g : mesh_.outgoing(v)) {
    Vertex w = mesh_.to_vertex(g);
    // A second edge to the other end (build() makes such twins when it splits a
    // non-manifold edge) would become a loop: Mesh::is_collapse_ok does not catch it.
    if (w == other && ++joins > 1) return false;
    if (w == other) continue;
    Vec3d pw = to_double(mesh_.position(w));
    double hi = 4.0 / 3.0 * size(v, w);
    if (sqrnorm(pw - target) > hi * hi) return false;
    if (mesh_.is_boundary(g)) continue;
    Vertex u = mesh_.to_vertex(mesh_.next(g));
    if (u == other) continue;
    Vec3d pu = to_double(mesh_.position(u));
    if (!(dot(cross(pw - p, pu - p), cross(pw - target, pu - target)) > 0)) return false;
  }
  return true;
}

// Whether collapsing h would give a triangle of from_vertex(h) the corners of one that
// to_vertex(h) has already: a second face on the same three vertices. Mesh::is_collapse_ok()
// catches this around the edge's own triangles; near build()'s split non-manifold edges it
// can happen one ring further out.
bool Remesher::makes_twin_triangle(Halfedge h) const {
  const Vertex v0 = mesh_.from_vertex(h), v1 = mesh_.to_vertex(h);
  for (Halfedge g : mesh_.outgoing(v0)) {
    if (mesh_.is_boundary(g)) continue;
    const Vertex x = mesh_.to_vertex(g), y = mesh_.to_vertex(mesh_.next(g));
    if (x == v1 || y == v1) continue;
    for (Halfedge k : mesh_.outgoing(v1)) {
      if (mesh_.is_boundary(k)) continue;
      const Vertex a = mesh_.to_vertex(k), b = mesh_.to_vertex(mesh_.next(k));
      if ((a == x && b == y) || (a == y && b == x)) return true;
    }
  }
  return false;
}

// Whether from_vertex(h) may be removed by collapsing h, the kept vertex going to `target`.
bool Remesher::may_collapse(Halfedge h, const Vec3d& target) const {
  const Vertex v0 = mesh_.from_vertex(h), v1 = mesh_.to_vertex(h);
  // Every check below walks both stars. Around a corner of very high valence (a polygon of
  // 100,000 corners triangulated: one corner joined to nearly all the others) each collapse
  // there would cost O(valence), and merging such stars makes them larger still: quadratic,
  // minutes for one polygon. Such vertices are thinned out by the flips instead.
  if (degree_[v0.idx()].valence + degree_[v1.idx()].valence > kMaxCollapseValence) return false;
  const Kind k0 = kind_[v0.idx()];
  if (k0 == Kind::fixed) return false;
  // A sliding vertex may only move along its curve, onto the next vertex of it.
  if (k0 == Kind::sliding && !(edge_flags_[Mesh::edge(h).idx()] & kCurve)) return false;
  if (!star_ok(v0, v1, target)) return false;
  if (!(target == to_double(mesh_.position(v1))) && !star_ok(v1, v0, target)) return false;
  return mesh_.is_collapse_ok(h) && !copies_.meets_collapse(mesh_, h) && !makes_twin_triangle(h);
}

// One pass over all edges, then the edges at each vertex a collapse moved, until none is
// short and collapsible (every collapse removes a vertex, so it ends).
void Remesher::collapse_short_edges() { report_.collapses += run_pass(Pass::collapse); }

// One pass over all edges, then the four edges around each flip, until no flip helps.
// Every flip lowers the sum of squared valence deviations, so it ends.
void Remesher::equalize_valences() { report_.flips += run_pass(Pass::flip); }

// Edges in index order, each followed by the edges its change puts on `pending`. On a large
// mesh the regions do most of it first, on all threads, and this loop visits only the edges
// they left.
std::size_t Remesher::run_pass(Pass pass) {
  mesh_.prepare_deletion_marks();
  Worker all;
  if (mesh_.n_faces() >= kRegionsMinFaces) {
    run_in_regions(pass);
    for (Edge e : deferred_) visit(pass, e, all);
    for (Worker& w : workers_) all.changes += std::exchange(w.changes, 0);
  } else {
    for (Index i = 0; i < mesh_.edges_size(); ++i) visit(pass, Edge(i), all);
  }
  mesh_.add_deletions(all.tally);
  return all.changes;
}

bool Remesher::is_candidate(Pass pass, Edge e) const {
  if (pass == Pass::collapse) return is_short(e);
  return !mesh_.is_deleted(e) && !(edge_flags_[e.idx()] & kFeature) && !mesh_.is_boundary(e);
}

void Remesher::visit(Pass pass, Edge e, Worker& w) {
  w.pending.assign(1, e);
  while (!w.pending.empty()) {
    const Edge x = w.pending.back();
    w.pending.pop_back();
    if (pass == Pass::collapse ? collapse_if_short(x, w) : flip_if_better(x, w)) ++w.changes;
  }
}

// Whether the one-rings of a and b lie in `region` and hold no vertex the weld joins with
// another: then collapsing their edge reads and changes only faces whose corners all lie in
// the region, which no other region's changes read or change.
bool Remesher::rings_inside(Vertex a, Vertex b, std::uint16_t region) const {
  for (Vertex v : {a, b}) {
    if (!in_region(v, region)) return false;
    for (Halfedge g : mesh_.outgoing(v))
      if (!in_region(mesh_.to_vertex(g), region)) return false;
  }
  return true;
}

// The regions of a partition of the vertices (spatial_order.h), each on its own thread,
// visit their candidate edges in index order, changing only faces whose corners all lie
// inside them: regions never meet, and the result does not depend on the number of threads.
// An edge whose change would reach out of its region waits for the next phase, whose
// partition has its borders elsewhere; those left after the last phase go to deferred_.
void Remesher::run_in_regions(Pass pass) {
  // The partitions are made once, of the vertices there are then; every vertex a split adds
  // later joins one of its edge's ends (split_long_edges).
  if (partitions_.regions() == 0) {
    const std::size_t nv = mesh_.vertices_size();
    const detail::Frame frame = detail::normalized_frame(mesh_);
    partitions_ =
        detail::RegionPartitions(mesh_, frame.center, 1 / frame.scale, std::max(nv / kRegionVertices, kMinRegions), 0);
  }
  const std::size_t regions = partitions_.regions();
  workers_.resize(regions);
  for (std::size_t r = 0; r < regions; ++r) workers_[r].region = std::uint16_t(r);
  const unsigned threads = thread_count();
  for (int phase = 0; phase < kPhases; ++phase) {
    region_ = partitions_.phase(phase);
    // The first phase offers every edge, the next those the last deferred: the candidates
    // go to their region's list, or to `carried` when their ends lie in two. On all
    // threads, each part a run of the edges, so that every list is in edge order.
    const std::size_t n = phase == 0 ? mesh_.edges_size() : deferred_.size();
    const std::size_t parts = std::max<std::size_t>(1, std::min<std::size_t>(threads, n / 16384));
    offered_.resize(parts * regions);
    carried_.resize(parts);
    for (std::vector<Edge>& list : offered_) list.clear();
    for (std::vector<Edge>& list : carried_) list.clear();
    hedge::parallel_for(
        parts, threads,
        [&](std::size_t begin, std::size_t end) {
          for (std::size_t k = begin; k < end; ++k)
            for (std::size_t j = n * k / parts; j < n * (k + 1) / parts; ++j) {
              const Edge e = phase == 0 ? Edge(Index(j)) : deferred_[j];
              if (!is_candidate(pass, e)) continue;
              const std::uint16_t r = region_[mesh_.vertex(e, 0).idx()];
              (r == region_[mesh_.vertex(e, 1).idx()] ? offered_[k * regions + r] : carried_[k]).push_back(e);
            }
        },
        1);
    // The regions, each thread taking the next one left.
    std::atomic<std::size_t> next{0};
    hedge::parallel_for(
        threads, threads,
        [&](std::size_t begin, std::size_t end) {
          for (std::size_t t = begin; t < end; ++t)
            for (std::size_t r; (r = next.fetch_add(1)) < regions;)
              for (std::size_t k = 0; k < parts; ++k)
                for (Edge e : offered_[k * regions + r]) visit(pass, e, workers_[r]);
        },
        1);
    deferred_.clear();
    for (const std::vector<Edge>& list : carried_) deferred_.insert(deferred_.end(), list.begin(), list.end());
    for (Worker& w : workers_) {
      mesh_.add_deletions(std::exchange(w.tally, {}));
      deferred_.insert(deferred_.end(), w.deferred.begin(), w.deferred.end());
      w.deferred.clear();
    }
    std::sort(deferred_.begin(), deferred_.end());
    deferred_.erase(std::unique(deferred_.begin(), deferred_.end()), deferred_.end());
  }
  region_ = nullptr;
}

// Botsch & Kobbelt's collapse of e when it is shorter than 4/5 of its target length and may
// go; the edges at the kept vertex go on w.pending.
bool Remesher::collapse_if_short(Edge e, Worker& w) {
  const Index i = e.idx();
  Halfedge h = Mesh::halfedge(e, 0), o = Mesh::halfedge(e, 1);
  Vertex a = mesh_.from_vertex(h), b = mesh_.to_vertex(h);
  if (!is_short(e)) return false;
  if (w.region != kNoRegion && !rings_inside(a, b, w.region)) {
    w.deferred.push_back(e);
    return false;
  }
  // Botsch & Kobbelt collapse to the midpoint, which leaves shorter edges than keeping
  // an end; an end that may not move (fixed, or sliding off its curve) is kept instead.
  const bool curve_edge = edge_flags_[i] & kCurve;
  auto movable = [&](Vertex v) {
    return kind_[v.idx()] == Kind::free || (kind_[v.idx()] == Kind::sliding && curve_edge);
  };
  const Vec3d pa = to_double(mesh_.position(a)), pb = to_double(mesh_.position(b));
  const bool midpoint = movable(a) && movable(b);
  const Vec3d mid = (pa + pb) * 0.5;
  // Remove the vertex of lower valence when both ways are possible (pmp-library's
  // choice): try that way first, the other only when it fails.
  const bool a_first = degree_[a.idx()].valence <= degree_[b.idx()].valence;
  const Halfedge first = a_first ? h : o, second = a_first ? o : h;
  const Vec3d& first_target = midpoint ? mid : (a_first ? pb : pa);
  const Vec3d& second_target = midpoint ? mid : (a_first ? pa : pb);
  Halfedge h_gone;
  if (may_collapse(first, first_target))
    h_gone = first;
  else if (may_collapse(second, second_target))
    h_gone = second;
  else
    return false;
  const Halfedge co = Mesh::opposite(h_gone);
  const Vertex gone = mesh_.from_vertex(h_gone), kept = mesh_.to_vertex(h_gone);

  // The two triangles at the edge collapse: each merges its other two edges into the
  // one at the kept vertex, which inherits the flags of the one that goes.
  Vertex left = mesh_.is_boundary(h_gone) ? Vertex() : mesh_.to_vertex(mesh_.next(h_gone));
  Vertex right = mesh_.is_boundary(co) ? Vertex() : mesh_.to_vertex(mesh_.next(co));
  Edge left_kept, left_gone, right_kept, right_gone;
  if (left.is_valid()) left_kept = Mesh::edge(mesh_.next(h_gone)), left_gone = Mesh::edge(mesh_.prev(h_gone));
  if (right.is_valid()) right_kept = Mesh::edge(mesh_.prev(co)), right_gone = Mesh::edge(mesh_.next(co));
  // Corners of the removed vertex's other faces move to the kept vertex: they take the
  // kept vertex's corner of a collapsing triangle (same chart: the edge is no seam).
  // Done before the collapse, which moves some of them onto surviving half-edges.
  if (!corner_arrays_.empty()) {
    const Halfedge source = left.is_valid() ? h_gone : mesh_.prev(co);
    for (Halfedge g : mesh_.outgoing(gone)) {
      Halfedge in = Mesh::opposite(g);
      if (mesh_.is_boundary(in) || in == mesh_.prev(h_gone) || in == co) continue;
      for (PropertyArray* p : corner_arrays_) p->copy_element(source.idx(), in.idx());
    }
  }
  if (midpoint) {
    const Index from[2] = {kept.idx(), gone.idx()};
    const float half[2] = {0.5f, 0.5f};
    for (PropertyArray* p : vertex_arrays_) p->interpolate(kept.idx(), from, half);
    if (!sizing_.empty()) sizing_[kept.idx()] = 0.5 * (sizing_[kept.idx()] + sizing_[gone.idx()]);
  }

  mesh_.collapse_unchecked(h_gone, w.tally);  // may_collapse() has just run is_collapse_ok()
  if (midpoint) mesh_.position(kept) = to_float(mid);
  if (left.is_valid()) edge_flags_[left_kept.idx()] |= edge_flags_[left_gone.idx()];
  if (right.is_valid()) edge_flags_[right_kept.idx()] |= edge_flags_[right_gone.idx()];
  int valence = 0;
  for (Halfedge g : mesh_.outgoing(kept)) {
    ++valence;
    w.pending.push_back(Mesh::edge(g));
  }
  degree_[kept.idx()].valence = valence;
  degree_[kept.idx()].target = std::min(degree_[kept.idx()].target, degree_[gone.idx()].target);
  if (left.is_valid()) --degree_[left.idx()].valence;
  if (right.is_valid()) --degree_[right.idx()].valence;
  return true;
}

// Whether flipping e brings the valences of its four vertices closer to their targets (6
// inside, 4 on the boundary) and keeps the surface from folding; flips it if so.
bool Remesher::flip_if_better(Edge e, Worker& w) {
  const Index i = e.idx();
  if (mesh_.is_deleted(e) || (edge_flags_[i] & kFeature) || mesh_.is_boundary(e)) return false;
  Halfedge h0 = Mesh::halfedge(e, 0), h1 = Mesh::halfedge(e, 1);
  Vertex a = mesh_.to_vertex(h0), b = mesh_.to_vertex(h1);
  Vertex c = mesh_.to_vertex(mesh_.next(h0)), d = mesh_.to_vertex(mesh_.next(h1));
  // In a region, the quad's corners must lie in it: the flip changes only its two faces.
  if (w.region != kNoRegion &&
      !(in_region(a, w.region) && in_region(b, w.region) && in_region(c, w.region) && in_region(d, w.region))) {
    w.deferred.push_back(e);
    return false;
  }
  Degree& da = degree_[a.idx()];
  Degree& db = degree_[b.idx()];
  Degree& dc = degree_[c.idx()];
  Degree& dd = degree_[d.idx()];
  auto sq = [](int x) { return x * x; };
  int before =
      sq(da.valence - da.target) + sq(db.valence - db.target) + sq(dc.valence - dc.target) + sq(dd.valence - dd.target);
  int after = sq(da.valence - 1 - da.target) + sq(db.valence - 1 - db.target) + sq(dc.valence + 1 - dc.target) +
              sq(dd.valence + 1 - dd.target);
  if (after >= before) return false;
  // The quad a c b d must stay a surface after the flip: both new triangles facing the
  // way the old ones did.
  Vec3d pa = to_double(mesh_.position(a)), pb = to_double(mesh_.position(b));
  Vec3d pc = to_double(mesh_.position(c)), pd = to_double(mesh_.position(d));
  Vec3d old_normal = cross(pa - pb, pc - pb) + cross(pb - pa, pd - pa);
  Vec3d n1 = cross(pc - pa, pd - pa), n2 = cross(pb - pc, pd - pc);
  if (!(dot(n1, n2) > 0 && dot(n1, old_normal) > 0 && dot(n2, old_normal) > 0)) return false;
  // Nor may it leave a sliver the smoothing cannot open again: a triangle along a feature
  // curve (a, v, b with v on the curve between a and b) passes the facing test by rounding.
  const double new_min = std::min(triangle_min_angle(pa, pc, pd), triangle_min_angle(pc, pb, pd));
  if (new_min < kFlipMinAngleDegrees &&
      new_min < std::min(triangle_min_angle(pb, pa, pc), triangle_min_angle(pa, pb, pd)))
    return false;
  if (!mesh_.is_flip_ok(e) || copies_.meets_flip(mesh_, e)) return false;
  mesh_.flip(e);
  --da.valence, --db.valence, ++dc.valence, ++dd.valence;
  for (unsigned side = 0; side < 2; ++side) {
    const Halfedge h = Mesh::halfedge(e, side);
    w.pending.push_back(Mesh::edge(mesh_.next(h)));
    w.pending.push_back(Mesh::edge(mesh_.prev(h)));
  }
  return true;
}

// The last smoothing and projection can leave caps: a vertex pushed onto (or near) the
// edge opposite it, an angle near 180 degrees. Flipping that edge, where the surface allows
// it, opens them: the flip must raise the smallest angle of the two triangles.
bool Remesher::is_cap(Edge e) const {
  if (mesh_.is_deleted(e) || (edge_flags_[e.idx()] & kFeature) || mesh_.is_boundary(e)) return false;
  const Halfedge h0 = Mesh::halfedge(e, 0), h1 = Mesh::halfedge(e, 1);
  const Vec3d pa = to_double(mesh_.position(mesh_.to_vertex(h0))), pb = to_double(mesh_.position(mesh_.to_vertex(h1)));
  constexpr double kCapCos = -0.8660254037844386;  // cos 150 degrees
  auto cap_at = [&](Halfedge h) {
    const Vec3d apex = to_double(mesh_.position(mesh_.to_vertex(mesh_.next(h))));
    const double l = norm(pa - apex) * norm(pb - apex);
    return (l > 0 ? dot(pa - apex, pb - apex) / l : -1.0) < kCapCos;
  };
  return cap_at(h0) || cap_at(h1);
}

bool Remesher::open_cap(Edge e) {
  if (!is_cap(e)) return false;
  Halfedge h0 = Mesh::halfedge(e, 0), h1 = Mesh::halfedge(e, 1);
  Vertex a = mesh_.to_vertex(h0), b = mesh_.to_vertex(h1);
  Vertex c = mesh_.to_vertex(mesh_.next(h0)), d = mesh_.to_vertex(mesh_.next(h1));
  Vec3d pa = to_double(mesh_.position(a)), pb = to_double(mesh_.position(b));
  Vec3d pc = to_double(mesh_.position(c)), pd = to_double(mesh_.position(d));
  Vec3d old_normal = cross(pa - pb, pc - pb) + cross(pb - pa, pd - pa);
  Vec3d n1 = cross(pc - pa, pd - pa), n2 = cross(pb - pc, pd - pc);
  if (!(dot(n1, n2) > 0 && dot(n1, old_normal) > 0 && dot(n2, old_normal) > 0)) return false;
  const double before = std::min(triangle_min_angle(pb, pa, pc), triangle_min_angle(pa, pb, pd));
  const double after = std::min(triangle_min_angle(pa, pc, pd), triangle_min_angle(pc, pb, pd));
  if (!(after > before) || !mesh_.is_flip_ok(e) || copies_.meets_flip(mesh_, e)) return false;
  mesh_.flip(e);
  --degree_[a.idx()].valence, --degree_[b.idx()].valence, ++degree_[c.idx()].valence, ++degree_[d.idx()].valence;
  ++report_.flips;
  return true;
}

void Remesher::open_caps() {
  // A flip moves no vertex and changes the triangles of its own quad's edges only, which it
  // puts on `pending`: the sweep needs to visit only the caps there are at the start (found
  // on all threads) and the edges put on `pending` since.
  const std::size_t n = mesh_.edges_size();
  std::vector<std::uint8_t> visit(n);
  parallel_for(n, [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) visit[i] = is_cap(Edge(static_cast<Index>(i)));
  });
  std::vector<Edge>& pending = work_;
  pending.clear();
  auto push_quad = [&](Edge e) {
    for (unsigned side = 0; side < 2; ++side) {
      Halfedge h = Mesh::halfedge(e, side);
      for (Edge x : {Mesh::edge(mesh_.next(h)), Mesh::edge(mesh_.prev(h))}) pending.push_back(x), visit[x.idx()] = 1;
    }
  };
  // Every flip raises the smallest angle of its pair; the budget only guards the loop.
  std::size_t budget = n;
  for (Index i = 0; i < n && budget; ++i) {
    if (visit[i] && open_cap(Edge(i))) push_quad(Edge(i)), --budget;
    while (!pending.empty() && budget) {
      Edge e = pending.back();
      pending.pop_back();
      if (open_cap(e)) push_quad(e), --budget;
    }
  }
}

void Remesher::smooth_and_project() {
  const std::size_t nv = mesh_.vertices_size();
  scratch_.resize(nv);
  const bool adaptive = !sizing_.empty();

  // The vertices that move, in the surface tree's order of the triangles they were last
  // projected onto (a counting sort by runs of 32): near ones come together, so each
  // vertex mostly reads neighbours and tree branches the one before brought into cache
  // (both the mesh and the tree are far larger than the cache).
  std::vector<Index>& order = move_order_;
  {
    constexpr int kRun = 5;
    std::vector<Index>& starts = order_starts_;
    starts.assign((surface_.n_triangles() >> kRun) + 2, 0);
    auto run_of = [&](std::size_t i) -> std::size_t {
      const Index hint = surface_hint_[i];
      return hint < surface_.n_triangles() ? (surface_.tree_order(hint) >> kRun) + 1 : 0;
    };
    auto moves = [&](std::size_t i) {
      return !mesh_.is_deleted(Vertex(static_cast<Index>(i))) && kind_[i] != Kind::fixed;
    };
    for (std::size_t i = 0; i < nv; ++i)
      if (moves(i)) ++starts[run_of(i)];
    Index total = 0;
    for (Index& s : starts) total += std::exchange(s, total);
    order.resize(total);
    for (std::size_t i = 0; i < nv; ++i)
      if (moves(i)) order[starts[run_of(i)]++] = Index(i);
  }

  for (int step = 0; step < kSmoothingSteps; ++step) {
    // Jacobi: every vertex reads the old positions, so the two halves run independently.
    parallel_for(order.size(), [&](std::size_t begin, std::size_t end) {
      for (std::size_t j = begin; j < end; ++j) {
        const std::size_t i = order[j];
        const Vertex v(static_cast<Index>(i));
        const Vec3d p = to_double(mesh_.position(v));
        Vec3d centroid{}, normal{};
        double weight = 0;
        if (kind_[i] == Kind::free) {
          // Toward the area-weighted centroid of the triangles around v (it evens out
          // triangle areas, which puts more edges near the target than the uniform
          // Laplacian); adaptive: the neighbours weighted by the inverse target length, so
          // that edges settle in proportion to their targets. Moved in the tangent plane.
          for (Halfedge g : mesh_.outgoing(v)) {
            Vertex w = mesh_.to_vertex(g);
            Vec3d pw = to_double(mesh_.position(w));
            Vec3d n{};
            if (!mesh_.is_boundary(g)) n = cross(pw - p, to_double(mesh_.position(mesh_.to_vertex(mesh_.next(g)))) - p);
            normal += n;
            if (adaptive) {
              double wt = 1.0 / size(v, w);
              centroid += pw * wt;
              weight += wt;
            } else if (!mesh_.is_boundary(g)) {
              Vec3d pu = to_double(mesh_.position(mesh_.to_vertex(mesh_.next(g))));
              double a = norm(n);
              centroid += (p + pw + pu) * (a / 3.0);
              weight += a;
            }
          }
          if (!(weight > 0)) {
            scratch_[i] = mesh_.position(v);
            continue;
          }
          Vec3d u = centroid / weight - p;
          double nn = sqrnorm(normal);
          if (nn > 0) u -= normal * (dot(normal, u) / nn);
          scratch_[i] = to_float(p + u);
        } else {
          // Along the curve: toward the middle of the two curve neighbours.
          Vec3d ends[2];
          int n = 0;
          for (Halfedge g : mesh_.outgoing(v))
            if ((edge_flags_[Mesh::edge(g).idx()] & kCurve) && n < 2)
              ends[n++] = to_double(mesh_.position(mesh_.to_vertex(g)));
          if (n != 2) {
            scratch_[i] = mesh_.position(v);
            continue;
          }
          Vec3d tangent = ends[1] - ends[0];
          double tt = sqrnorm(tangent);
          Vec3d u = (ends[0] + ends[1]) * 0.5 - p;
          if (tt > 0) u = tangent * (dot(tangent, u) / tt);
          scratch_[i] = to_float(p + u);
        }
      }
    });
    for (Index i : order) mesh_.position(Vertex(i)) = scratch_[i];
  }

  // Back onto the input: free vertices onto the surface, sliding ones onto their curves.
  parallel_for(order.size(), [&](std::size_t begin, std::size_t end) {
    for (std::size_t j = begin; j < end; ++j) {
      const std::size_t i = order[j];
      const Vertex v(static_cast<Index>(i));
      const Vec3d p = to_double(mesh_.position(v));
      if (kind_[i] == Kind::free) {
        ClosestPoint c = surface_.closest_point_with_hint(p, surface_hint_[i]);
        if (!c.found()) continue;
        mesh_.position(v) = to_float(c.point);
        surface_hint_[i] = c.triangle;
        if (adaptive) {
          auto corners = input_corners(c.triangle);
          double s = 0;
          for (int k = 0; k < 3; ++k) s += c.barycentric[k] * input_sizing_[input_.to_vertex(corners[k]).idx()];
          if (std::isfinite(s) && s > 0) sizing_[i] = s;  // no NaN from a zero-area triangle
        }
      } else if (!curves_.empty()) {
        ClosestPoint c = curves_.closest_point_with_hint(p, curve_hint_[i]);
        if (!c.found()) continue;
        mesh_.position(v) = to_float(c.point);
        curve_hint_[i] = c.triangle;
      }
    }
  });
}

// Moved vertices take their attributes from the input surface where they landed: vertex
// channels, and corner channels (all corners of such a vertex share one value, since
// seams are pinned). Channels named "normal" are renormalized after blending.
void Remesher::resample_attributes() {
  struct Pair {
    const ChannelArray* from;
    ChannelArray* to;
  };
  std::vector<Pair> vertex_pairs, corner_pairs;
  auto collect = [](const PropertyContainer& in, PropertyContainer& out, std::vector<Pair>& pairs) {
    for (std::size_t i = 0; i < out.count(); ++i) {
      PropertyArray& a = out.at(i);
      if (a.type() != typeid(ChannelArray) || a.is_internal()) continue;
      const ChannelArray* src = in.get_channel(a.name());
      auto* dst = static_cast<ChannelArray*>(&a);
      if (src && src->scalar() == dst->scalar() && src->components() == dst->components()) pairs.push_back({src, dst});
    }
  };
  collect(input_.vertex_properties(), mesh_.vertex_properties(), vertex_pairs);
  collect(input_.halfedge_properties(), mesh_.halfedge_properties(), corner_pairs);
  if (vertex_pairs.empty() && corner_pairs.empty()) return;

  auto renormalize = [](ChannelArray* c, Index i) {
    if (c->name() != "normal" || c->scalar() != ScalarType::f32 || c->components() != 3) return;
    auto* n = reinterpret_cast<float*>(c->element(i));
    double len = std::sqrt(double(n[0]) * n[0] + double(n[1]) * n[1] + double(n[2]) * n[2]);
    if (len > 0)
      for (int k = 0; k < 3; ++k) n[k] = static_cast<float>(n[k] / len);
  };

  parallel_for(mesh_.vertices_size(), [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
      const Vertex v(static_cast<Index>(i));
      if (mesh_.is_deleted(v) || kind_[i] == Kind::fixed) continue;
      ClosestPoint c = surface_.closest_point_with_hint(to_double(mesh_.position(v)), surface_hint_[i]);
      if (!c.found()) continue;
      auto corners = input_corners(c.triangle);
      const double w[3] = {c.barycentric[0], c.barycentric[1], c.barycentric[2]};
      Index from_vertices[3], from_corners[3];
      for (int k = 0; k < 3; ++k) {
        from_vertices[k] = input_.to_vertex(corners[k]).idx();
        from_corners[k] = corners[k].idx();
      }
      for (const Pair& p : vertex_pairs) {
        detail::blend_element(*p.from, std::span<const Index>(from_vertices), std::span<const double>(w),
                              p.to->element(v.idx()));
        renormalize(p.to, v.idx());
      }
      if (corner_pairs.empty()) continue;
      Halfedge first = Halfedge();
      for (Halfedge g : mesh_.outgoing(v)) {
        Halfedge in = Mesh::opposite(g);  // points to v; its corner belongs to face(in)
        if (mesh_.is_boundary(in)) continue;
        if (!first.is_valid()) {
          first = in;
          for (const Pair& p : corner_pairs) {
            detail::blend_element(*p.from, std::span<const Index>(from_corners), std::span<const double>(w),
                                  p.to->element(in.idx()));
            renormalize(p.to, in.idx());
          }
        } else {
          for (const Pair& p : corner_pairs)
            std::memcpy(p.to->element(in.idx()), p.to->element(first.idx()), p.to->stride());
        }
      }
    }
  });
}

RemeshReport Remesher::run() {
  report_.input_faces = mesh_.n_faces();
  // The target: the mean edge length of the input, unless given.
  length_ = options_.target_edge_length;
  if (length_ <= 0) {
    double sum = 0;
    for (Edge e : mesh_.edges()) sum += std::sqrt(length_sq(mesh_.vertex(e, 0), mesh_.vertex(e, 1)));
    length_ = mesh_.n_edges() ? sum / double(mesh_.n_edges()) : 0;
    if (!(length_ > 0))
      throw Error(
          "remesh: the mesh's edges all have zero length, so there is no edge length to aim for; give "
          "target_edge_length");
  }
  report_.target_edge_length = length_;
  // A target far below the input's edges (the mean edge of a 100,000-gon on its own disc, a
  // length typed in the wrong units) would run for hours and exhaust memory: refuse it now.
  const double area = surface_area(mesh_);
  const double forecast = area / (std::sqrt(3.0) / 4.0 * length_ * length_);
  if (forecast > double(options_.max_faces)) {
    char text[320];
    std::snprintf(text, sizeof text,
                  "remesh: a target edge length of %.4g%s on a surface of area %.4g would make about %.3g "
                  "triangles, more than the limit of %zu; give a larger target_edge_length",
                  length_, options_.target_edge_length > 0 ? "" : " (the mean edge length of the input)", area,
                  forecast, options_.max_faces);
    throw Error(text);
  }

  progress_.update(0.0, "triangulating");
  if (options_.selection_only) {
    // Polygons outside the selection stay: their edges are frozen (classify()).
    const std::vector<std::uint8_t> selected = detail::selected_faces(mesh_);
    std::vector<Face> polygons;
    for (Face f : mesh_.faces())
      if (mesh_.valence(f) > 3 && selected[f.idx()]) polygons.push_back(f);
    for (Face f : polygons) mesh_.triangulate(f);
    report_.triangulated_faces = polygons.size();
  } else {
    for (Face f : mesh_.faces())
      if (mesh_.valence(f) > 3) ++report_.triangulated_faces;
    if (report_.triangulated_faces) mesh_.triangulate();
  }

  progress_.update(0.01, "building the distance tree");
  surface_ = TriangleTree(input_);
  first_triangle_.assign(input_.faces_size(), 0);
  for (Index t = static_cast<Index>(surface_.n_triangles()); t-- > 0;) first_triangle_[surface_.face(t).idx()] = t;
  for (std::size_t i = 0; i < mesh_.vertex_properties().count(); ++i)
    // build()'s provenance ("hedge:*") is not blended: a vertex made in the middle of an edge
    // has no source vertex, so it keeps the arrays' defaults.
    if (!mesh_.vertex_properties().at(i).is_internal()) vertex_arrays_.push_back(&mesh_.vertex_properties().at(i));
  for (std::size_t i = 0; i < mesh_.halfedge_properties().count(); ++i)
    if (!mesh_.halfedge_properties().at(i).is_internal()) corner_arrays_.push_back(&mesh_.halfedge_properties().at(i));

  progress_.update(0.03, "finding features");
  classify();
  grow_vertex_arrays();
  // Start every vertex's projection from a triangle of its own input face.
  for (Vertex v : mesh_.vertices()) {
    if (mesh_.is_isolated(v) || v.idx() >= input_.vertices_size()) continue;
    for (Halfedge h : input_.outgoing(v))
      if (Face f = input_.face(h); f.is_valid()) {
        surface_hint_[v.idx()] = first_triangle_[f.idx()];
        break;
      }
  }
  if (options_.adaptive) compute_sizing();

  const int n = options_.iterations;
  for (int it = 0; it < n; ++it) {
    auto at = [&](double stage) { return 0.05 + 0.93 * (it + stage / 4.0) / n; };
    const std::string round = " (iteration " + std::to_string(it + 1) + " of " + std::to_string(n) + ")";
    progress_.update(at(0), "splitting long edges" + round);
    split_long_edges();
    progress_.update(at(1), "collapsing short edges" + round);
    collapse_short_edges();
    progress_.update(at(2), "flipping edges" + round);
    equalize_valences();
    progress_.update(at(3), "smoothing" + round);
    smooth_and_project();
  }
  open_caps();
  progress_.update(0.98, "carrying attributes");
  resample_attributes();
  mesh_.compact();
  report_.output_faces = mesh_.n_faces();
  report_.output_vertices = mesh_.n_vertices();
  return report_;
}

}  // namespace

RemeshReport remesh(Mesh& mesh, const RemeshOptions& options, Progress& progress) {
  if (!(options.target_edge_length >= 0) || !std::isfinite(options.target_edge_length))
    throw Error("remesh: target_edge_length must be a finite number of at least 0 (0 = mean input edge length)");
  if (options.iterations < 1 || options.iterations > 100) throw Error("remesh: iterations must be from 1 to 100");
  if (!(options.feature_angle >= 0 && options.feature_angle <= 180))
    throw Error("remesh: feature_angle must be from 0 to 180 degrees");
  if (mesh.n_faces() == 0) throw Error("remesh: the mesh has no faces");

  // Work in place, keeping the input: it is the surface to project onto, and what the
  // caller gets back when something fails or the user cancels.
  Mesh backup = mesh;
  try {
    // Every pass walks the mesh in index order: numbered along a space-filling curve, it
    // stays in cache far better (and deleted elements go). The surface to project onto is
    // this copy, numbered as the working mesh is at the start.
    detail::sort_spatially(mesh);
    const Mesh input = mesh;
    Remesher remesher(mesh, input, options, progress);
    return remesher.run();
  } catch (...) {
    mesh = std::move(backup);
    throw;
  }
}

Operation remesh_operation() {
  const char* help =
      "Rebuilds the surface with nearly equilateral triangles of one edge length: repeatedly splits long edges, "
      "collapses short ones, flips edges toward six neighbours per vertex, smooths tangentially and projects back "
      "onto the original surface (Botsch & Kobbelt 2004, \"A remeshing approach to multiresolution modeling\"). "
      "Use it before simulation, subdivision or sculpting, or to clean up scans and CAD tessellations with slivers. "
      "Polygons are triangulated first. Sharp edges (above the feature angle) and boundaries are kept; edges where "
      "texture coordinates, corner normals or face attributes change (seams) are kept as well. Vertex and corner "
      "attributes (colours, UVs, normals) are interpolated on splits and resampled from the original surface where "
      "vertices move; face attributes are copied to the faces that continue them.";
  using O = RemeshOptions;
  using R = RemeshReport;
  return Binding<O, R>("remesh", "Isotropic Remesh", Category::remeshing, help, remesh)
      .option(&O::target_edge_length, "target_edge_length", "Target edge length", at_least(0),
              "Edge length to reach, in model units; 0 uses the mean edge length of the input.")
      .option(&O::iterations, "iterations", "Iterations", between(1, 100),
              "Rounds of split, collapse, flip, smooth and project; 3 to 10 is typical.")
      .option(&O::feature_angle, "feature_angle", "Feature angle", between(0, 180),
              "Edges whose faces meet at a dihedral angle above this many degrees are sharp features: "
              "they are kept (only split), and their vertices slide only along them. 180 turns this off.")
      .option(&O::preserve_boundary, "preserve_boundary", "Preserve boundary",
              "Keep boundary edges (only split) and boundary vertices fixed; otherwise boundary edges may "
              "also collapse and boundary vertices slide along the boundary.")
      .option(&O::adaptive, "adaptive", "Adaptive",
              "Let the edge length follow curvature: shorter where the surface bends (down to a quarter of "
              "the target), longer where it is flat (up to twice the target).")
      .selection(&O::selection_only,
                 "Only the selected faces are remeshed; faces outside the selection and the border stay as they "
                 "are.")
      .result(&R::target_edge_length, "target_edge_length")
      .result(&R::input_faces, "input_faces")
      .result(&R::output_faces, "faces")
      .result(&R::output_vertices, "vertices")
      .result(&R::splits, "splits")
      .result(&R::collapses, "collapses")
      .result(&R::flips, "flips")
      .result(&R::feature_edges, "feature_edges")
      .result(&R::fixed_vertices, "fixed_vertices")
      .result("triangulated_faces", [](const O&, const R& r) -> std::optional<Value> {
        if (!r.triangulated_faces) return std::nullopt;
        return field_value(r.triangulated_faces);
      });
}

}  // namespace hedge
