// Quadric error metric decimation (Garland & Heckbert 1997) with per-wedge interpolation of
// corner attributes (Hoppe 1999): the algorithm of decimate.h and its catalogue entry.
#include "hedge/decimate.h"

#include <algorithm>
#include <atomic>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <numbers>
#include <numeric>
#include <optional>
#include <vector>

#include "binding.h"
#include "hedge/distance.h"
#include "hedge/error.h"
#include "hedge/geometry.h"
#include "hedge/limits.h"
#include "parallel.h"
#include "selection.h"
#include "spatial_order.h"
#include "welded_copies.h"
#ifdef HEDGE_DECIMATE_DEBUG
#include <cstdio>

#include "hedge/validate.h"
#endif

namespace hedge {
namespace {

// The squared distance to a set of weighted planes, sum of w (n.u + s)^2, as u^T A u +
// 2 g.u + k in coordinates u relative to an origin (the vertex it belongs to). Relative to
// the vertex, g and k stay as small as the errors they measure, so a vertex can store its
// quadric in floats (PackedQuadric) without losing them to cancellation; all arithmetic
// is in doubles.
struct Quadric {
  double a00 = 0, a01 = 0, a02 = 0, a11 = 0, a12 = 0, a22 = 0;  // A
  double g0 = 0, g1 = 0, g2 = 0, k = 0;
  double weight = 0;  // sum of the plane weights: value / weight is a mean squared distance

  //! Plane n.u + s = 0 (n unit), weight w.
  void add_plane(const Vec3d& n, double s, double w) {
    a00 += w * n[0] * n[0], a01 += w * n[0] * n[1], a02 += w * n[0] * n[2];
    a11 += w * n[1] * n[1], a12 += w * n[1] * n[2], a22 += w * n[2] * n[2];
    g0 += w * n[0] * s, g1 += w * n[1] * s, g2 += w * n[2] * s;
    k += w * s * s;
    weight += w;
  }
  //! Plane m.u = 0 through the origin, given by a multiple m of its unit normal: adds
  //! f m m^T, with f = w / |m|^2 for the plane's weight w.
  void add_plane_through_origin(const Vec3d& m, double f, double w) {
    a00 += f * m[0] * m[0], a01 += f * m[0] * m[1], a02 += f * m[0] * m[2];
    a11 += f * m[1] * m[1], a12 += f * m[1] * m[2], a22 += f * m[2] * m[2];
    weight += w;
  }
  Quadric& operator+=(const Quadric& q) {
    a00 += q.a00, a01 += q.a01, a02 += q.a02, a11 += q.a11, a12 += q.a12, a22 += q.a22;
    g0 += q.g0, g1 += q.g1, g2 += q.g2, k += q.k, weight += q.weight;
    return *this;
  }
  //! Every plane's weight times f.
  Quadric& operator*=(double f) {
    a00 *= f, a01 *= f, a02 *= f, a11 *= f, a12 *= f, a22 *= f;
    g0 *= f, g1 *= f, g2 *= f, k *= f, weight *= f;
    return *this;
  }

  Vec3d times(const Vec3d& u) const {
    return {{a00 * u[0] + a01 * u[1] + a02 * u[2], a01 * u[0] + a11 * u[1] + a12 * u[2],
             a02 * u[0] + a12 * u[1] + a22 * u[2]}};
  }
  Vec3d linear() const { return {{g0, g1, g2}}; }
  double value(const Vec3d& u) const { return dot(u, times(u)) + 2 * dot(u, linear()) + k; }
  double operator()(const Vec3d& u) const { return std::max(0.0, value(u)); }
  //! The same quadric about the origin moved by delta.
  Quadric shifted(const Vec3d& delta) const {
    Quadric q = *this;
    const Vec3d ad = times(delta);
    q.g0 += ad[0], q.g1 += ad[1], q.g2 += ad[2];
    q.k = dot(delta, ad) + 2 * dot(delta, linear()) + k;
    return q;
  }
};

// A quadric about its vertex, in 44 bytes.
struct PackedQuadric {
  float a00 = 0, a01 = 0, a02 = 0, a11 = 0, a12 = 0, a22 = 0, g0 = 0, g1 = 0, g2 = 0, k = 0, weight = 0;
  Quadric unpack() const { return {a00, a01, a02, a11, a12, a22, g0, g1, g2, k, weight}; }
  void store(const Quadric& q) {
    a00 = float(q.a00), a01 = float(q.a01), a02 = float(q.a02), a11 = float(q.a11), a12 = float(q.a12);
    a22 = float(q.a22), g0 = float(q.g0), g1 = float(q.g1), g2 = float(q.g2), k = float(q.k);
    weight = float(q.weight);
  }
};

// Two doubles side by side: two edges measured at once, each lane doing exactly the
// operations one edge does alone, so each gets the same bits (x86-64's baseline has no
// fused multiply-add for the compiler to contract into).
using DoublePair = double __attribute__((vector_size(16)));
// What comparing lanes gives: bool for double, a mask of lanes for DoublePair.
template <class T>
using LaneMask = decltype(T{} > T{});

// A quadric without its weight, in lanes of type T (double: one edge; DoublePair: two).
template <class T>
struct QuadricLanes {
  T a00, a01, a02, a11, a12, a22, g0, g1, g2, k;
};

// The quadric of an edge's two ends about a's place, a and b stored about their own places
// and b at ab from a: what unpack() + unpack().shifted(-ab) gives, the same operations in
// the same order, written out so that no intermediate quadric goes through memory. `a(f)`
// and `b(f)` give the lanes of field f of the ends' packed quadrics. Always inline: it is
// evaluate()'s core, and GCC stops inlining it once it has several callers.
template <class T, class Lanes>
[[gnu::always_inline]] inline QuadricLanes<T> merge_lanes(Lanes a, Lanes b, T ab0, T ab1, T ab2) {
  const T d0 = -ab0, d1 = -ab1, d2 = -ab2;
  const T b00 = b(&PackedQuadric::a00), b01 = b(&PackedQuadric::a01), b02 = b(&PackedQuadric::a02);
  const T b11 = b(&PackedQuadric::a11), b12 = b(&PackedQuadric::a12), b22 = b(&PackedQuadric::a22);
  const T bg0 = b(&PackedQuadric::g0), bg1 = b(&PackedQuadric::g1), bg2 = b(&PackedQuadric::g2);
  const T ad0 = b00 * d0 + b01 * d1 + b02 * d2, ad1 = b01 * d0 + b11 * d1 + b12 * d2,
          ad2 = b02 * d0 + b12 * d1 + b22 * d2;
  const T bk =
      (0.0 + d0 * ad0 + d1 * ad1 + d2 * ad2) + 2.0 * (0.0 + d0 * bg0 + d1 * bg1 + d2 * bg2) + b(&PackedQuadric::k);
  return {a(&PackedQuadric::a00) + b00,        a(&PackedQuadric::a01) + b01,
          a(&PackedQuadric::a02) + b02,        a(&PackedQuadric::a11) + b11,
          a(&PackedQuadric::a12) + b12,        a(&PackedQuadric::a22) + b22,
          a(&PackedQuadric::g0) + (bg0 + ad0), a(&PackedQuadric::g1) + (bg1 + ad1),
          a(&PackedQuadric::g2) + (bg2 + ad2), a(&PackedQuadric::k) + bk};
}

// The lanes of one packed quadric's fields, as doubles.
inline auto lanes_of(const PackedQuadric& q) {
  return [&q](float PackedQuadric::*f) { return double(q.*f); };
}

[[gnu::always_inline]] inline Quadric merged_about_first(const PackedQuadric& a, const PackedQuadric& b,
                                                         const Vec3d& ab) {
  const QuadricLanes<double> m = merge_lanes<double>(lanes_of(a), lanes_of(b), ab[0], ab[1], ab[2]);
  return {m.a00, m.a01, m.a02, m.a11, m.a12, m.a22, m.g0, m.g1, m.g2, m.k, double(a.weight) + double(b.weight)};
}

// Pull of the optimal placement towards the edge's midpoint, relative to the quadric's mean
// eigenvalue. 1% keeps new vertices inside their neighbourhood in flat and cylindrical
// regions (better triangles, attributes interpolated inside the old triangles) for about
// 10% more mean error and no change in the Hausdorff distance on the dragon.
constexpr double kPull = 0.01;

// Where an edge's merged quadric q (about a, b at ab) is least once pulled towards the
// edge's middle c: the solution of (A + lambda I) u = lambda c - g, lambda kPull times A's
// mean eigenvalue. The pull settles the directions the planes leave free (flat or
// cylindrical regions), where the bare minimum drifts along the surface, without moving
// the well-determined ones by more than that fraction. Found when the system is well
// conditioned (det > eps tr^3, invariant under rotation and scale, keeps the smallest
// eigenvalue above eps tr) and u lies within the edge's length of c (a nearly flat
// neighbourhood can put it far along a valley of the quadric: a numerical accident, not a
// better surface). The cost there is q(u) = g.u + lambda u.(c - u) + k, from the solved
// system without a product by A, and at least 0.
template <class T>
struct PulledMinimum {
  T u0, u1, u2, cost;
  LaneMask<T> found;
};

template <class T>
[[gnu::always_inline]] inline PulledMinimum<T> pulled_minimum(const QuadricLanes<T>& q, T ab0, T ab1, T ab2) {
  const T c0 = ab0 * 0.5, c1 = ab1 * 0.5, c2 = ab2 * 0.5;
  const T lambda = kPull / 3 * (q.a00 + q.a11 + q.a22);
  const T a00 = q.a00 + lambda, a11 = q.a11 + lambda, a22 = q.a22 + lambda;
  const T a01 = q.a01, a02 = q.a02, a12 = q.a12;
  const T g0 = q.g0 - lambda * c0, g1 = q.g1 - lambda * c1, g2 = q.g2 - lambda * c2;
  const T m00 = a11 * a22 - a12 * a12, m01 = a02 * a12 - a01 * a22, m02 = a01 * a12 - a02 * a11;
  const T m11 = a00 * a22 - a02 * a02, m12 = a01 * a02 - a00 * a12, m22 = a00 * a11 - a01 * a01;
  const T det = a00 * m00 + a01 * m01 + a02 * m02;
  const T tr = a00 + a11 + a22;
  const T inv = -1.0 / det;
  const T u0 = (m00 * g0 + m01 * g1 + m02 * g2) * inv, u1 = (m01 * g0 + m11 * g1 + m12 * g2) * inv,
          u2 = (m02 * g0 + m12 * g1 + m22 * g2) * inv;
  const T o0 = u0 - c0, o1 = u1 - c1, o2 = u2 - c2;
  const T reach = 4.0 * (0.0 + ab0 * ab0 + ab1 * ab1 + ab2 * ab2);
  const T value = (0.0 + q.g0 * u0 + q.g1 * u1 + q.g2 * u2) +
                  lambda * (0.0 + u0 * (c0 - u0) + u1 * (c1 - u1) + u2 * (c2 - u2)) + q.k;
  return {u0, u1, u2, 0.0 < value ? value : T{},
          LaneMask<T>((det > 1e-9 * tr * tr * tr) & ((0.0 + o0 * o0 + o1 * o1 + o2 * o2) <= reach))};
}

// The queue of edges by cost: a radix heap (Ahuja, Mehlhorn, Orlin & Tarjan 1990) over the
// bit patterns of the float costs (non-negative floats order like their bits). It needs
// keys that never drop below the last one taken, which quadrics nearly guarantee: merging
// only adds planes, so costs grow; a key below (an edge refused earlier, legal again) is
// taken next, as a binary heap would take it. Pushing appends to a bucket and taking
// redistributes one bucket, both sequential sweeps, instead of sifting through a tree of
// random cache lines, which dominated a binary heap's cost here.
//
// Entries are never updated in place: a changed edge gets a new entry, and the old one is
// recognised as stale by its version stamp when it surfaces (the lowest 8 bits of the key,
// which costs 2^-15 of relative precision in the ordering).
class EdgeQueue {
 public:
  static std::uint32_t key(float cost, std::uint8_t version) {
    std::uint32_t bits;
    std::memcpy(&bits, &cost, sizeof bits);
    return (bits & ~0xffu) | version;
  }
  static std::uint8_t version(std::uint32_t key) { return std::uint8_t(key & 0xffu); }
  //! The current version of each edge, to drop stale entries early.
  explicit EdgeQueue(const std::vector<std::uint8_t>* versions) : versions_(versions) {}
  struct Entry {
    std::uint32_t key;
    Index edge;
  };

  bool empty() const { return size_ == 0; }
  std::size_t size() const { return size_; }
  void clear() {
    for (auto& b : buckets_) b.clear();
    occupied_ = 0;
    size_ = 0;
    last_ = 0;
  }
  void push(std::uint32_t k, Index edge) {
    if (k < last_) {
      // Below the last key taken: it goes next, keeping its version.
      k = (last_ & ~0xffu) | (k & 0xffu);
      if (k < last_) k += 0x100;
    }
    put({k, edge});
    ++size_;
  }
  //! The edge pop() will return next unless a lower key is pushed first, or kInvalidIndex
  //! when that is not cheap to tell: a guess, for fetching its data ahead.
  Index peek() const {
    if (occupied_ & 1) return buckets_[0].back().edge;
    if (occupied_ == 0) return kInvalidIndex;
    const std::vector<Entry>& first = buckets_[std::countr_zero(occupied_)];
    if (first.size() > 8) return kInvalidIndex;
    const Entry* best = nullptr;
    for (const Entry& e : first)
      if ((*versions_)[e.edge] == version(e.key) && (!best || e.key < best->key)) best = &e;
    return best ? best->edge : kInvalidIndex;
  }
  //! Takes the entry of least key, or an entry with a stale version; precondition: !empty().
  Entry pop() {
    if (!(occupied_ & 1)) refill();
    if (!(occupied_ & 1)) return {0, kInvalidIndex};  // only stale entries were left
    const Entry e = buckets_[0].back();
    buckets_[0].pop_back();
    if (buckets_[0].empty()) occupied_ &= ~std::uint64_t(1);
    --size_;
    return e;
  }

 private:
  int bucket(std::uint32_t k) const { return k == last_ ? 0 : 32 - std::countl_zero(k ^ last_); }
  void put(const Entry& e) {
    const int b = bucket(e.key);
    buckets_[b].push_back(e);
    occupied_ |= std::uint64_t(1) << b;
  }
  // Stale entries are dropped on the way (most entries are: every collapse re-queues the
  // edges around the kept vertex), so they are not moved down bucket after bucket.
  void refill() {
    for (;;) {
      if (occupied_ == 0) return;
      const int i = std::countr_zero(occupied_);  // bucket 0 is empty
      occupied_ &= ~(std::uint64_t(1) << i);      // its entries all move to lower buckets
      std::vector<Entry>& from = buckets_[i];
      std::size_t live = 0;
      // The versions of a bucket's edges are scattered over the array: fetch them ahead.
      constexpr std::size_t kAhead = 64;
      for (std::size_t j = 0; j < std::min(kAhead, from.size()); ++j) detail::prefetch(&(*versions_)[from[j].edge]);
      for (std::size_t j = 0; j < from.size(); ++j) {
        if (j + kAhead < from.size()) detail::prefetch(&(*versions_)[from[j + kAhead].edge]);
        if ((*versions_)[from[j].edge] == version(from[j].key)) from[live++] = from[j];
      }
      size_ -= from.size() - live;
      from.resize(live);
      if (live == 0) continue;
      std::uint32_t least = from.front().key;
      for (const Entry& e : from) least = std::min(least, e.key);
      last_ = least;
      for (const Entry& e : from) put(e);
      from.clear();
      return;
    }
  }
  const std::vector<std::uint8_t>* versions_;
  std::vector<Entry> buckets_[33];
  std::uint64_t occupied_ = 0;  // bit i: buckets_[i] holds entries
  std::uint32_t last_ = 0;
  std::size_t size_ = 0;
};

// The best collapse of one edge.
struct Candidate {
  Point position;     // where the kept vertex goes
  float cost;         // quadric error there (area x squared distance, in units of the diagonal)
  float kept_weight;  // interpolation weight of the kept vertex's attributes
  std::uint8_t side;  // collapse halfedge(e, side): its from_vertex goes
};

// Per-vertex flags, kept with the quadric (VertexData). The seam bits say what a
// vertex may do with respect to seams of per-corner attributes: kOnSeam when a seam edge
// touches it, kSeamLine when it lies inside one seam (it may slide along it), kLockedSeam
// for seam ends, junctions and seams meeting the boundary (it stays).
// kLocked: with selection_only, a vertex with a face outside the selection (so those faces
// stay as they were), or a vertex the lock attribute marks; it neither moves nor goes.
enum VertexFlag : std::uint8_t { kBoundary = 1, kOnSeam = 2, kSeamLine = 4, kLockedSeam = 8, kLocked = 16 };
constexpr std::uint8_t kSeamBits = kOnSeam | kSeamLine | kLockedSeam;

// Boundary edges add a plane through the edge, perpendicular to its face, so moving a
// boundary vertex off the boundary's line costs (Garland & Heckbert's boundary constraint).
constexpr double kBoundaryWeight = 10;

// Quadrics are stored in floats: a weight far beyond this would only blur their precision.
constexpr double kMaxWeightStrength = 1000;

// Collapsing in regions (Decimator::collapse_in_regions): from this many faces on, while
// more than kTailShare of the faces to remove, and of the target, are left (and at least
// kMinPhase collapses' worth). A phase's passes cost in proportion to the mesh left, the
// serial tail in proportion to its own collapses: past a small share of the target, another
// phase is cheaper than leaving its collapses to the tail.
constexpr std::size_t kRegionsMinFaces = 50000;
constexpr std::size_t kRegionVertices = 16384;  // about this many vertices per region, in at least
constexpr std::size_t kMinRegions = 32;         // this many regions
constexpr double kTailShare = 0.02;
constexpr std::size_t kMinPhase = 2048;
constexpr std::size_t kThresholdShare = 4;  // the threshold: (faces to remove) / this cost less
constexpr float kNoCost = std::numeric_limits<float>::infinity();
constexpr std::uint16_t kNoRegion = detail::RegionPartitions::kNone;

class Decimator {
 public:
  Decimator(Mesh& mesh, const DecimateOptions& options, Progress& progress)
      : m_(mesh), opt_(options), progress_(progress), copies_(mesh) {}

  DecimateReport run();

 private:
  // ---- setup -------------------------------------------------------------------------
  void triangulate_polygons();
  void compute_frame();
  void read_weights_and_locks();
  void find_shapes();
  void compute_quadrics();
  // What face_planes() met going round a vertex.
  struct RingSeen {
    std::size_t valence = 0;
    bool hole = false;  // a gap between two of its faces: the vertex is on the boundary
  };
  template <class Where>
  Quadric face_planes(Vertex v, Where where, RingSeen* seen = nullptr) const;
  bool add_boundary_planes(Vertex v, Quadric& q) const;
  void find_corner_channels();
  void classify_vertices();
  //! Lets collapses meet extract()'s weld of build()'s copies from now on; false when they
  //! could already (or there are no copies).
  bool relax_weld() {
    if (!copies_.any() || weld_relaxed_) return false;
    weld_relaxed_ = true;
    return true;
  }
  std::uint8_t classify(Vertex v) const;
  void fill_heap();
  // The error of collapsing h, placed as c says: a mean squared distance.
  double error_sq_of(Halfedge h, const Candidate& c) const {
    const PackedQuadric& q0 = vd_[m_.from_vertex(h).idx()].quadric;
    const PackedQuadric& q1 = vd_[m_.to_vertex(h).idx()].quadric;
    double weight = double(q0.weight) + double(q1.weight);
    if (!shapes_.empty()) weight += shapes_weight(m_.from_vertex(h), m_.to_vertex(h));
    return weight > 0 ? double(c.cost) / weight : 0;
  }

  // ---- evaluation ----------------------------------------------------------------------
  Vec3d local(const Point& p) const { return (to_double(p) - center_) * inv_scale_; }
  Vec3d local(Vertex v) const { return local(m_.position(v)); }
  Vec3d at(Vertex v) const { return to_double(vd_[v.idx()].position); }
  Point world(const Vec3d& p) const { return to_float(center_ + p * scale_); }
  // Shapes: the offset of v in shape k, and v's place there, in the normalized frame.
  Vec3d shape_offset(std::size_t k, Vertex v) const {
    float o[3];
    std::memcpy(o, shapes_[k]->element(v.idx()), sizeof o);
    return Vec3d{{o[0], o[1], o[2]}} * inv_scale_;
  }
  Vec3d shape_at(std::size_t k, Vertex v) const { return at(v) + shape_offset(k, v); }
  PackedQuadric& shape_quadric(std::size_t k, Vertex v) { return shape_quadrics_[v.idx() * shapes_.size() + k]; }
  const PackedQuadric& shape_quadric(std::size_t k, Vertex v) const {
    return shape_quadrics_[v.idx() * shapes_.size() + k];
  }
  double shapes_cost(Vertex a, Vertex b, const Vec3d& p, double s) const;
  double shapes_weight(Vertex a, Vertex b) const;
  bool corners_equal(Halfedge a, Halfedge b) const {
    for (const ChannelArray* c : corner_channels_)
      if (!c->same(a.idx(), b.idx())) return false;
    return true;
  }
  // kPlace: also where the new vertex goes and how its attributes blend (c.position,
  // c.kept_weight, c.side); without it only c.cost is set, which is all the queue needs.
  template <bool kPlace = true>
  bool evaluate(Edge e, Candidate& c) const;
  // The cost of e's best collapse; kNoCost when it has none (or is deleted).
  float measure(Edge e) const {
    Candidate c;
    return !m_.is_deleted(e) && evaluate<false>(e, c) ? c.cost : kNoCost;
  }
  double boundary_shift(Halfedge h0, const Vec3d& p) const;
  struct Scratch;
  struct Worker;
  // Evaluates e and queues it in w's queue under a new version (any older entry becomes
  // stale) when it costs at most w.max_cost; an edge without any legal placement just loses
  // its entries. During the phases its cost is kept too.
  void requeue(Edge e, Worker& w);
  void requeue(Edge e, float cost, Worker& w);
  // An edge with neither end flagged (boundary, seam, lock) and no shape keys: the common
  // case, whose cost measure_pair() finds two at a time.
  bool plain(Edge e) const {
    return shapes_.empty() && (vd_[m_.vertex(e, 0).idx()].flags | vd_[m_.vertex(e, 1).idx()].flags) == 0;
  }
  // measure() of two plain edges, side by side in the lanes of DoublePair: the same bits.
  void measure_pair(Edge e0, Edge e1, float& cost0, float& cost1) const;
  // cost(i) = measure(edge(i)) for i < n, the plain edges two at a time.
  template <class EdgeAt, class CostAt>
  void measure_all(std::size_t n, EdgeAt edge, CostAt cost) const;

  // ---- fetching ahead ------------------------------------------------------------------
  // Each collapse starts with cache misses: the popped edge lies anywhere in the mesh, and its
  // rings are chains of dependent loads. The edge expected next (EdgeQueue::peek(), right
  // about four times in five) has its neighbourhood fetched while the current collapse runs,
  // one dependent step per call to fetch_ahead(), so that each step's loads have arrived
  // when the next one reads them. Only hints: a wrong guess costs some memory traffic.
  void start_fetch_ahead(Scratch& s, Index edge) const;
  void fetch_ahead(Scratch& s) const;

  // ---- collapsing ----------------------------------------------------------------------
  // Why a collapse is refused, in the order tested.
  enum Refusal {
    kLegal = 0,
    kEarLeft,      // the triangle on the left has its two other edges on the boundary
    kValenceLeft,  // vl would be left with two edges
    kEarRight,
    kValenceRight,
    kTriangleHole,  // a hole of three edges would become a 2-gon
    kSharedCorner,  // both triangles have the same third corner
    kPinch,         // an interior edge between two boundary vertices
    kLowValence,    // the merged vertex would have fewer than three edges
    kDoubleEdge,    // v0 and v1 are joined twice
    kLink,          // the rings share a vertex besides vl and vr
    kWeld,          // extract()'s weld of build()'s copies would give an edge of v1 a third face
    kFold,          // a triangle would turn too far or become degenerate
    kQuality,       // the worst triangle would fall below min_quality
    kRegion,        // during a phase: a ring leaves the region
    kRefusals
  };
  Refusal check(Halfedge h, const Point& target, Scratch& s, std::uint16_t region = kNoRegion) const;
  // Inline in check(), whatever GCC's budget for the file says: out of line it costs 2 % more.
  [[gnu::always_inline]] bool triangle_ok(const Vec3d& old_apex, const Vec3d& new_apex, const Vec3d& a, const Vec3d& b,
                                          Scratch& s) const;
  // What a collapse changed, for the queue to follow up.
  struct Collapsed {
    Vertex kept;
    Vertex reclassified[2];  // vl, vr when their seam flags changed (their edges need measuring)
    Edge doomed[5];          // the collapsed edge and one of each merged pair
    int removed_faces;
  };
  // The collapse itself: the mesh, the quadrics, attributes and flags. It writes only the
  // vertices of the closed one-rings of h's ends and the faces around them, and reads only
  // faces holding one of those vertices, so collapses in regions that hold their rings (a
  // phase's) may run on several threads at once, each with its own scratch and tally.
  Collapsed apply_collapse(Halfedge h, const Candidate& c, Scratch& s, Mesh::Deletions& tally);
  // apply_collapse() and what follows in w's queue; returns the number of faces removed.
  int collapse(Halfedge h, const Candidate& c, Worker& w);
  struct RingEntry;
  // A face around one end of the collapse, as check() walked it: the end (apex) and entries i
  // and i + 1 of its ring, with barycentric weights in that order.
  struct RingHit {
    const std::vector<RingEntry>* ring = nullptr;  // null: nothing found
    Vertex apex;
    std::size_t i = 0;
    float weight[3] = {0, 0, 0};  // non-negative, normalized in blend_element
  };
  template <class Take>
  RingHit nearest_in_rings(const Vec3d& p, Vertex v0, Vertex v1, const Scratch& s, Take take) const;
  void locate_vertex(Vertex v0, Vertex v1, const Candidate& c, Scratch& s) const;
  void gather_wedges(Halfedge h, const Point& target, Scratch& s) const;
  void blend_wedges(Vertex kept, const Scratch& s);
  void interpolate_vertex(Vertex removed, Vertex kept, const Candidate& c, Scratch& s);

  Mesh& m_;
  const DecimateOptions& opt_;
  Progress& progress_;
  const detail::WeldedCopies copies_;
  bool weld_relaxed_ = false;  // the last resort: collapses may meet the weld

  Vec3d center_{};
  double scale_ = 1, inv_scale_ = 1;
  double cos_max_normal_change_ = 0;
  bool seam_mode_ = false;
  std::vector<std::uint8_t> inside_selection_;  // per vertex, with selection_only (selection.h)
  std::vector<double> weight_factor_;           // per vertex, 1 + strength * weight (weight_attribute)
  std::vector<double> lock_;                    // per vertex, non-zero when locked (lock_attribute)
  // The mesh's other shapes (soup.h: "shape:" channels, e.g. Blender's shape keys), and a
  // quadric per vertex and shape about the vertex's place in that shape, vertex-major.
  std::vector<const ChannelArray*> shapes_;
  std::vector<PackedQuadric> shape_quadrics_;
  bool has_boundary_ = false;

  // Everything evaluate() reads about a vertex, in one cache line: its quadric (about its
  // position), its position in the normalized frame, valence and flags. The loop is bound
  // by cache misses, not arithmetic.
  struct alignas(64) VertexData {
    PackedQuadric quadric;
    Vec3f position;
    std::uint16_t valence = 0;
    std::uint8_t flags = 0;
  };
  // Left unset by resize(): compute_quadrics() writes every element on its threads, which
  // then take the page faults of first touching the array instead of one zero-filling thread.
  std::vector<VertexData, detail::UnsetAllocator<VertexData>> vd_;
  std::vector<std::uint8_t> version_;  // of each edge's current queue entry: one byte, stays in cache
  struct RingEntry {
    Vertex vertex;  // a neighbour, in counter-clockwise order
    Face face;      // the face between it and the next neighbour (invalid: a hole)
    Halfedge out;   // to the neighbour from the ring's end: the face's corner at the neighbour
    Vec3d position;
  };

  std::vector<ChannelArray*> corner_channels_;  // host per-corner channels (seams are judged on these)
  // Vertex properties. Real-valued host channels blend in the old triangle holding the new
  // vertex, which takes a search of the faces around the collapse; the rest (build()'s
  // internal arrays, and host ids, flags and 8-bit colours, which do not blend) take the
  // nearer end's value, so an id always names one of the two vertices merged.
  struct VertexArray {
    PropertyArray* array;
    ChannelArray* located;  // a real-valued host channel, blended where the vertex lands
  };
  std::vector<VertexArray> vertex_arrays_;
  bool locate_vertices_ = false;  // some vertex channel is located

  // What testing and making one collapse needs besides the mesh, reused from one collapse to
  // the next (no allocation per collapse), and the fetching ahead of the next one.
  struct Scratch {
    std::vector<RingEntry> ring0, ring1;  // check(): both ends' rings
    double worst_new = 1, worst_old = 1;  // triangle quality around the collapse being tested
    Index vertex_blend_index[3];
    float vertex_blend_weight[3];
    int vertex_blend_size = 0;
    struct WedgeFace {
      Face face;
      Halfedge corner;  // its corner at the collapsing end, before the collapse
    };
    std::vector<WedgeFace> wedge_faces[2];  // faces whose corner at the kept vertex joins wedge l / r
    std::vector<std::byte> wedge_values;    // new corner values: [wedge l, wedge r] per channel
    bool wedge_present[2] = {false, false};
    Index interp_index[2];
    float interp_weight[2];
    std::vector<Vec3d> shape_before;  // both ends' places in each shape
    Edge ahead_edge;
    int ahead_stage = 0;  // 0: nothing to fetch
    Halfedge ahead_ring[2], ahead_ring_start[2];
  };
  // One collapsing loop: the queue over the whole mesh, or a region's during a phase.
  struct Worker {
    explicit Worker(const std::vector<std::uint8_t>* versions) : queue(versions) {}
    EdgeQueue queue;
    Scratch scratch;
    Mesh::Deletions tally;
    std::uint16_t region = kNoRegion;  // collapses only inside it; kNoRegion: anywhere
    float max_cost = kNoCost;          // edges above this wait for a later phase
    std::size_t face_budget = 0;       // a region's share of the faces to remove
    std::size_t collapses = 0, removed_faces = 0;
    double max_error_sq = 0;
    bool refused_for_error = false;
    std::vector<Index> remeasure;  // edges across the region's border whose ends changed
  };
  Worker serial_{&version_};

  // ---- collapsing in regions -----------------------------------------------------------
  // While much is left to remove, collapses run in phases, each region of the mesh on its
  // own thread: a region collapses, greedily from its own queue, its edges below the phase's
  // cost threshold whose ends' one-rings lie wholly inside it, so regions never meet and the
  // result does not depend on which thread ran which region. Regions are runs of a Morton
  // order of the vertices, as many as the mesh's size asks (never one per thread); two grids
  // alternate, each shifted by half a region every other time, so that edges near one
  // phase's borders are inside the next one's.
  // Every region works on a small part of the mesh, which stays in cache better than the
  // one queue over everything. The queue over the whole mesh takes over for the last
  // collapses, which hit the exact target and relax the limits when needed.
  void measure_edges();
  void collapse_in_regions();
  std::size_t collapse_phase();
  void collapse_region(Worker& w);
  // Per edge during the phases; kNoCost: no candidate. Like live_edges_, left unset by
  // resize() and written whole on all threads, which share the first touch of its pages.
  std::vector<float, detail::UnsetAllocator<float>> cost_;
  // The partitions into regions, and the phase's map from a vertex to its region.
  detail::RegionPartitions partitions_;
  const std::uint16_t* region_ = nullptr;
  // Per vertex during a phase: 1 when a neighbour lies in another region. Only edges with
  // neither end on a border are queued: any other would be refused (its rings leave the
  // region). Within a phase no vertex leaves or joins a border: a collapse gives the kept
  // vertex only neighbours of the removed one, and regions never collapse a border vertex.
  std::vector<std::uint8_t> border_;
  std::vector<Index, detail::UnsetAllocator<Index>> live_edges_;  // in order; those deleted are dropped at each phase
  std::vector<Worker> workers_;                                   // one per region
  std::size_t regions_ = 0;
  struct Queued {
    std::uint32_t key;
    Index edge;
  };
  std::vector<std::vector<Queued>> phase_lists_;  // per part and region: the edges to queue
  std::vector<std::uint32_t> phase_histograms_;   // per part: the costs' top bits
  std::vector<std::uint16_t> phase_order_;        // the regions, largest queue first

  std::size_t faces_ = 0;
  std::size_t target_ = 0;
  DecimateReport report_;
  double max_error_sq_seen_ = 0;
  bool refused_for_error_ = false;
  bool skipped_for_parity_ = false;
};

void Decimator::triangulate_polygons() {
  // With selection_only, polygons outside the selection stay: their vertices are all locked,
  // so no collapse reaches them.
  const std::vector<std::uint8_t> selected =
      opt_.selection_only ? detail::selected_faces(m_) : std::vector<std::uint8_t>();
  auto is_polygon = [&](Face f) {
    return !m_.is_deleted(f) && m_.next(m_.next(m_.next(m_.halfedge(f)))) != m_.halfedge(f) &&
           (selected.empty() || selected[f.idx()]);
  };
  // Meshes are mostly triangles already: the scan that finds none runs on all threads, and
  // only a mesh with polygons lists them (in order) and splits them.
  std::atomic<std::size_t> found{0};
  parallel_for(m_.faces_size(), opt_.threads, [&](std::size_t begin, std::size_t end) {
    std::size_t count = 0;
    for (std::size_t i = begin; i < end; ++i) count += is_polygon(Face(Index(i)));
    found += count;
  });
  if (found == 0) return;
  std::vector<Face> polygons;
  polygons.reserve(found);
  for (std::size_t i = 0, n = m_.faces_size(); i < n; ++i)
    if (is_polygon(Face(Index(i)))) polygons.push_back(Face(Index(i)));
  for (Face f : polygons) m_.triangulate(f);
  report_.triangulated_faces = polygons.size();
}

// Quadrics are built in coordinates centred on the bounding box and scaled by its diagonal:
// errors come out as fractions of the diagonal and keep their precision far from the origin.
void Decimator::compute_frame() {
  const detail::Frame frame = detail::normalized_frame(m_, opt_.threads);
  center_ = frame.center;
  scale_ = frame.scale;
  inv_scale_ = 1 / scale_;
}

void Decimator::read_weights_and_locks() {
  if (!opt_.lock_attribute.empty()) {
    lock_ = detail::vertex_values(m_, opt_.lock_attribute, "decimate: lock_attribute");
    for (Vertex v : m_.vertices()) report_.locked_vertices += lock_[v.idx()] != 0;
  }
  if (opt_.weight_attribute.empty()) return;
  std::vector<double> w = detail::vertex_values(m_, opt_.weight_attribute, "decimate: weight_attribute");
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (Vertex v : m_.vertices())
    if (std::isfinite(w[v.idx()])) lo = std::min(lo, w[v.idx()]), hi = std::max(hi, w[v.idx()]);
  // Vertex groups hold 0 to 1; other attributes (MeshLab's quality, a curvature) any range,
  // which only their spread can turn into weights.
  const bool rescale = lo < 0 || hi > 1;
  if (rescale)
    report_.messages.push_back("weight_attribute '" + opt_.weight_attribute + "' runs from " + std::to_string(lo) +
                               " to " + std::to_string(hi) + ": rescaled to 0 to 1 as weights");
  weight_factor_.assign(w.size(), 1);
  for (Vertex v : m_.vertices()) {
    double x = std::isfinite(w[v.idx()]) ? w[v.idx()] : 0;
    if (rescale) x = hi > lo ? (x - lo) / (hi - lo) : 0;
    weight_factor_[v.idx()] = 1 + opt_.weight_strength * std::clamp(x, 0.0, 1.0);
  }
}

void Decimator::compute_quadrics() {
  const std::size_t n = m_.vertices_size();
  vd_.clear();
  vd_.resize(n);
  parallel_for(n, opt_.threads, [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
      vd_[i] = VertexData();
      const Vertex v(static_cast<Index>(i));
      if (m_.is_deleted(v)) continue;
      vd_[i].position = to_float(local(v));
      if (m_.is_isolated(v)) vd_[i].flags = kBoundary;  // as Mesh::is_boundary() says
    }
  });
  // Each vertex sums the planes of its own faces and boundary edges, around its ring: the
  // same order, so the same bits, on any number of threads. The vertices are visited in the
  // order of the faces, each from the face its outgoing half-edge (or, on the boundary, that
  // half-edge's opposite) lies in: neighbouring faces lie near one another in the arrays
  // more often than neighbouring vertices do (subdivision numbers every new vertex after
  // the old ones), so the rings walked one after the other share what is in cache.
  std::atomic<bool> has_boundary{false};
  parallel_for(m_.faces_size(), opt_.threads, [&](std::size_t begin, std::size_t end) {
    bool boundary = false;
    auto sum_planes = [&](Vertex v) {
      const std::size_t i = v.idx();
      RingSeen seen;
      Quadric q = face_planes(
          v, [&](Vertex w) { return at(w); }, &seen);
      vd_[i].valence =
          static_cast<std::uint16_t>(std::min<std::size_t>(seen.valence, std::numeric_limits<std::uint16_t>::max()));
      // A gap between its faces: the vertex is on the boundary (its outgoing half-edge lies
      // on it), found here rather than by another pass through every vertex's half-edge.
      if (seen.hole) {
        vd_[i].flags = kBoundary;
        boundary |= add_boundary_planes(v, q);
      }
      // A weight scales every plane of the vertex, and so its share of a merged quadric: the
      // cost rises where detail matters while cost / weight stays a mean squared distance.
      if (!weight_factor_.empty()) q *= weight_factor_[i];
      vd_[i].quadric.store(q);
      // Each shape's faces, as the mesh's own (its boundary is held by the mesh's quadrics).
      for (std::size_t k = 0; k < shapes_.size(); ++k) {
        Quadric qk = face_planes(v, [&](Vertex w) { return shape_at(k, w); });
        if (!weight_factor_.empty()) qk *= weight_factor_[i];
        shape_quadric(k, v).store(qk);
      }
    };
    for (std::size_t j = begin; j < end; ++j) {
      const Face f(static_cast<Index>(j));
      if (m_.is_deleted(f)) continue;
      for (Halfedge h : m_.halfedges(f)) {
        if (const Vertex v = m_.from_vertex(h); m_.halfedge(v) == h) sum_planes(v);
        const Halfedge o = Mesh::opposite(h);
        if (const Vertex w = m_.to_vertex(h); m_.is_boundary(o) && m_.halfedge(w) == o) sum_planes(w);
      }
    }
    if (boundary) has_boundary.store(true, std::memory_order_relaxed);
  });
  has_boundary_ = has_boundary.load();
}

// The planes of v's faces weighted by area, so that a region's error does not depend on how
// finely it happens to be tessellated, about v's own place (where(v)), which lies on all of
// them. Each face's plane comes from its corners in its own order, the same bits for each
// of its vertices.
template <class Where>
Quadric Decimator::face_planes(Vertex v, Where where, RingSeen* seen) const {
  Quadric q;
  for (Halfedge x : m_.outgoing(v)) {
    if (seen) ++seen->valence;
    const Face f = m_.face(x);
    if (!f.is_valid()) {
      if (seen) seen->hole = true;
      continue;
    }
    const Halfedge h = m_.halfedge(f);
    const Vec3d pa = where(m_.to_vertex(h)), pb = where(m_.to_vertex(m_.next(h))), pc = where(m_.to_vertex(m_.prev(h)));
    const Vec3d doubled_area = cross(pb - pa, pc - pa);  // along the normal
    const double len = norm(doubled_area);
    if (!(len > 0)) continue;
    // v is a corner, so its own faces' planes pass through it: no offset. Weighted by the
    // area (len / 2), the unit normal's n n^T is doubled_area doubled_area^T / len^2.
    q.add_plane_through_origin(doubled_area, 0.5 / len, 0.5 * len);
  }
  return q;
}

// The plane through each boundary edge at v, perpendicular to its face; true when there is one.
bool Decimator::add_boundary_planes(Vertex v, Quadric& q) const {
  bool any = false;
  for (Halfedge x : m_.outgoing(v)) {
    Halfedge h = x;
    if (!m_.is_boundary(h)) h = Mesh::opposite(h);
    if (!m_.is_boundary(h)) continue;
    any = true;
    const Halfedge inner = Mesh::opposite(h);
    const Vertex a = m_.from_vertex(inner), b = m_.to_vertex(inner), c = m_.to_vertex(m_.next(inner));
    const Vec3d pa = at(a), pb = at(b), pc = at(c);
    const Vec3d along = pb - pa;
    const Vec3d face_normal = cross(along, pc - pa);
    Vec3d normal = cross(along, face_normal);
    const double len = norm(normal);
    if (!(len > 0)) continue;
    normal /= len;
    q.add_plane(normal, dot(normal, at(v) - pa), kBoundaryWeight * sqrnorm(along));
  }
  return any;
}

void Decimator::find_shapes() {
  const PropertyContainer& vp = m_.vertex_properties();
  for (std::size_t i = 0; i < vp.count(); ++i) {
    const PropertyArray& a = vp.at(i);
    if (a.type() != typeid(ChannelArray) || !a.name().starts_with(kShapePrefix)) continue;
    const auto& c = static_cast<const ChannelArray&>(a);
    // A shape the same as the mesh (all offsets zero) would only repeat its quadrics.
    const bool moves = std::any_of(c.bytes().begin(), c.bytes().end(), [](std::byte b) { return b != std::byte{0}; });
    if (c.scalar() == ScalarType::f32 && c.components() == 3 && moves) shapes_.push_back(&c);
  }
  shape_quadrics_.resize(shapes_.size() * m_.vertices_size());
}

// The error of a collapse in the other shapes: the merged vertex at p (relative to a) takes
// the offsets (1 - s) of a's and s of b's, as its attributes are blended along the edge.
double Decimator::shapes_cost(Vertex a, Vertex b, const Vec3d& p, double s) const {
  double cost = 0;
  for (std::size_t k = 0; k < shapes_.size(); ++k) {
    const Vec3d oa = shape_offset(k, a), ob = shape_offset(k, b);
    const Vec3d ab = at(b) + ob - at(a) - oa;  // b relative to a, in shape k
    const Quadric q = merged_about_first(shape_quadric(k, a), shape_quadric(k, b), ab);
    cost += q(p + (ob - oa) * s);
  }
  return cost;
}

double Decimator::shapes_weight(Vertex a, Vertex b) const {
  double w = 0;
  for (std::size_t k = 0; k < shapes_.size(); ++k) {
    w += double(shape_quadric(k, a).weight);
    w += double(shape_quadric(k, b).weight);
  }
  return w;
}

void Decimator::find_corner_channels() {
  PropertyContainer& hp = m_.halfedge_properties();
  for (std::size_t i = 0; i < hp.count(); ++i) {
    PropertyArray& a = hp.at(i);
    if (a.type() == typeid(ChannelArray) && !a.is_internal())
      corner_channels_.push_back(static_cast<ChannelArray*>(&a));
  }
  seam_mode_ = opt_.preserve_uv_seams && !corner_channels_.empty();

  PropertyContainer& vp = m_.vertex_properties();
  for (std::size_t i = 0; i < vp.count(); ++i) {
    PropertyArray& a = vp.at(i);
    ChannelArray* located = nullptr;
    if (a.type() == typeid(ChannelArray) && !a.is_internal()) {
      auto* channel = static_cast<ChannelArray*>(&a);
      if (channel->scalar() == ScalarType::f32 || channel->scalar() == ScalarType::f64) located = channel;
    }
    vertex_arrays_.push_back({&a, located});
    locate_vertices_ = locate_vertices_ || located;
  }
}

// A vertex is plain when no seam edge touches it; a seam vertex when it lies inside one seam
// (two seam edges, its corners in two wedges); locked otherwise: seam ends and junctions,
// and seams meeting the boundary, keep their place so the charts keep their shape.
std::uint8_t Decimator::classify(Vertex v) const {
  int seams = 0, splits = 0;
  bool boundary = false;
  for (Halfedge x : m_.outgoing(v)) {
    const Halfedge ox = Mesh::opposite(x);
    if (m_.is_boundary(x) || m_.is_boundary(ox)) {
      boundary = true;
      continue;
    }
    const bool differ_here = !corners_equal(m_.prev(x), ox);
    const bool differ_there = !corners_equal(x, m_.prev(ox));
    splits += differ_here;
    seams += differ_here || differ_there;
  }
  if (seams == 0) return 0;
  if (seams == 2 && splits == 2 && !boundary) return kOnSeam | kSeamLine;
  return kOnSeam | kLockedSeam;
}

// The boundary flags come from compute_quadrics(); the seam and lock flags are added here.
void Decimator::classify_vertices() {
  if (!seam_mode_ && inside_selection_.empty() && lock_.empty()) return;
  parallel_for(m_.vertices_size(), opt_.threads, [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
      const Vertex v(static_cast<Index>(i));
      if (m_.is_deleted(v)) continue;
      std::uint8_t f = vd_[i].flags & kBoundary;
      if (seam_mode_) f |= classify(v);
      if (!inside_selection_.empty() && !inside_selection_[i]) f |= kLocked;
      if (!lock_.empty() && lock_[i] != 0) f |= kLocked;
      vd_[i].flags = f;
    }
  });
}

namespace {
double segment_sq(const Vec3d& q, const Vec3d& a, const Vec3d& b) {
  const Vec3d d = b - a;
  const double dd = sqrnorm(d);
  const double t = dd > 0 ? std::clamp(dot(q - a, d) / dd, 0.0, 1.0) : 0.0;
  return sqrnorm(q - (a + d * t));
}
// Squared distance from q to the polyline x - p - y.
double polyline_sq(const Vec3d& q, const Vec3d& x, const Vec3d& p, const Vec3d& y) {
  return std::min(segment_sq(q, x, p), segment_sq(q, p, y));
}
}  // namespace

// How far the boundary line moves when the boundary vertices among the ends of e go to p:
// the squared distance of each old vertex to the new polyline. Boundary quadrics only see
// distances across the boundary's edges; a thin tongue retracting along itself costs them
// nothing, this does.
double Decimator::boundary_shift(Halfedge h0, const Vec3d& p) const {
  const Halfedge o0 = Mesh::opposite(h0);
  const Vertex a = m_.to_vertex(o0), b = m_.to_vertex(h0);
  if (m_.is_boundary(h0) || m_.is_boundary(o0)) {
    const Halfedge hb = m_.is_boundary(h0) ? h0 : o0;
    const Vec3d x = at(m_.from_vertex(m_.prev(hb))), y = at(m_.to_vertex(m_.next(hb)));
    return std::max(polyline_sq(at(a), x, p, y), polyline_sq(at(b), x, p, y));
  }
  double shift = 0;
  for (Vertex v : {a, b}) {
    if (!(vd_[v.idx()].flags & kBoundary)) continue;
    const Halfedge hb = m_.halfedge(v);  // its outgoing boundary half-edge
    shift = std::max(shift, polyline_sq(at(v), at(m_.from_vertex(m_.prev(hb))), p, at(m_.to_vertex(hb))));
  }
  return shift;
}

// The cheapest legal placement for collapsing e. Which end may go and which may move
// follows from the boundary and seam rules; the position is the quadric's minimum when
// both ends are free, else the best point of the edge, else the fixed end.
template <bool kPlace>
bool Decimator::evaluate(Edge e, Candidate& c) const {
  const Halfedge h0 = Mesh::halfedge(e, 0);
  const Halfedge o0 = Mesh::opposite(h0);
  const Vertex b = m_.to_vertex(h0), a = m_.to_vertex(o0);  // h0 runs a -> b
  const VertexData &da = vd_[a.idx()], &db = vd_[b.idx()];
  const std::uint8_t fa = da.flags, fb = db.flags;
  // Both ends of a boundary edge are on the boundary: only then are its faces read.
  const bool boundary_edge = (fa & fb & kBoundary) && (m_.is_boundary(h0) || m_.is_boundary(o0));

  bool seam = false, seam_both = false;
  if (seam_mode_ && !boundary_edge && ((fa | fb) & kOnSeam)) {
    const bool differ_a = !corners_equal(m_.prev(h0), o0), differ_b = !corners_equal(h0, m_.prev(o0));
    seam = differ_a || differ_b;
    seam_both = differ_a && differ_b;
  }
  auto removable = [&](std::uint8_t f) {
    if (opt_.preserve_boundary && (f & kBoundary) && !boundary_edge) return false;
    if (f & (kLockedSeam | kLocked)) return false;
    if (f & kSeamLine) return seam_both;
    return true;
  };
  auto movable = [&](std::uint8_t f) {
    if (opt_.preserve_boundary && (f & kBoundary)) return false;
    if (f & (kLockedSeam | kLocked)) return false;
    if (f & kSeamLine) return seam_both;
    return true;
  };
  // Most edges have neither end on a boundary, a seam or a lock: both ends free.
  const bool plain = (fa | fb) == 0;
  const bool ra = plain || removable(fa), rb = plain || removable(fb);
  if (!ra && !rb) return false;
  const bool ma = plain || movable(fa), mb = plain || movable(fb);
  const bool touches_boundary = boundary_edge || ((fa | fb) & kBoundary);

  // Everything relative to a: both quadrics about a, a at the origin, b at ab.
  const Vec3d pa = to_double(da.position), pb = to_double(db.position);
  const Vec3d ab = pb - pa;
  const Quadric q = merged_about_first(da.quadric, db.quadric, ab);
  const double boundary_weight = kBoundaryWeight * sqrnorm(ab);
  if ((ra && mb) || (rb && ma)) {
    // Both ends free: the removed vertex is whichever may go (a when both may).
    const bool remove_a = ra && mb;
    const Vec3d from = remove_a ? Vec3d{} : ab, to = remove_a ? ab : Vec3d{};
    const Vec3d d = to - from;
    const double dd = sqrnorm(d);
    Vec3d p;
    bool found = false;
    double cost = 0;
    // Seams move only along themselves: the minimum over the edge keeps the new vertex on
    // the seam line, where both charts' coordinates can be interpolated.
    if (!seam) {
      const QuadricLanes<double> lanes{q.a00, q.a01, q.a02, q.a11, q.a12, q.a22, q.g0, q.g1, q.g2, q.k};
      const PulledMinimum<double> m = pulled_minimum(lanes, ab[0], ab[1], ab[2]);
      found = m.found;
      p = {{m.u0, m.u1, m.u2}};
      cost = m.cost;
    }
    double t = 0.5;  // along the edge from the removed vertex, for attribute interpolation
    if (!found) {
      const double curvature = dot(d, q.times(d));
      const double slope = dot(q.times(from) + q.linear(), d);
      t = curvature > 0 ? std::clamp(-slope / curvature, 0.0, 1.0) : (slope > 0 ? 0.0 : slope < 0 ? 1.0 : 0.5);
      p = from + d * t;
      cost = q(p);
    } else if (kPlace || !shapes_.empty()) {
      t = dd > 0 ? std::clamp(dot(p - from, d) / dd, 0.0, 1.0) : 0.5;
    }
    if (touches_boundary) cost += boundary_weight * boundary_shift(h0, pa + p);
    if (!shapes_.empty()) cost += shapes_cost(a, b, p, remove_a ? t : 1 - t);
    c.cost = static_cast<float>(cost);
    if constexpr (kPlace) {
      c.position = world(pa + p);
      c.kept_weight = static_cast<float>(t);
      c.side = remove_a ? 0 : 1;
    }
    return true;
  }
  // One end stays where it is.
  constexpr double inf = std::numeric_limits<double>::infinity();
  double cost_keep_b = ra ? q(ab) : inf, cost_keep_a = rb ? q(Vec3d{}) : inf;
  if (touches_boundary) {
    if (ra) cost_keep_b += boundary_weight * boundary_shift(h0, pb);
    if (rb) cost_keep_a += boundary_weight * boundary_shift(h0, pa);
  }
  if (!shapes_.empty()) {
    if (ra) cost_keep_b += shapes_cost(a, b, ab, 1);
    if (rb) cost_keep_a += shapes_cost(a, b, Vec3d{}, 0);
  }
  const bool keep_b = cost_keep_b <= cost_keep_a;
  c.cost = static_cast<float>(keep_b ? cost_keep_b : cost_keep_a);
  if constexpr (kPlace) {
    c.position = m_.position(keep_b ? b : a);
    c.kept_weight = 1;
    c.side = keep_b ? 0 : 1;
  }
  return true;
}

// evaluate<false>()'s path for two plain edges: both ends free, a removed; where a lane's
// minimum is not found, that edge goes through evaluate() alone.
void Decimator::measure_pair(Edge e0, Edge e1, float& cost0, float& cost1) const {
  const VertexData *a[2], *b[2];
  for (int i = 0; i < 2; ++i) {
    const Halfedge h0 = Mesh::halfedge(i == 0 ? e0 : e1, 0);
    b[i] = &vd_[m_.to_vertex(h0).idx()];
    a[i] = &vd_[m_.to_vertex(Mesh::opposite(h0)).idx()];
  }
  auto lanes = [](const VertexData* const* d) {
    return [d](float PackedQuadric::*f) { return DoublePair{double(d[0]->quadric.*f), double(d[1]->quadric.*f)}; };
  };
  auto position = [](const VertexData* const* d, int i) {
    return DoublePair{double(d[0]->position[i]), double(d[1]->position[i])};
  };
  const DoublePair ab0 = position(b, 0) - position(a, 0), ab1 = position(b, 1) - position(a, 1),
                   ab2 = position(b, 2) - position(a, 2);
  const PulledMinimum<DoublePair> m =
      pulled_minimum(merge_lanes<DoublePair>(lanes(a), lanes(b), ab0, ab1, ab2), ab0, ab1, ab2);
  cost0 = m.found[0] ? static_cast<float>(m.cost[0]) : measure(e0);
  cost1 = m.found[1] ? static_cast<float>(m.cost[1]) : measure(e1);
}

template <class EdgeAt, class CostAt>
void Decimator::measure_all(std::size_t n, EdgeAt edge, CostAt cost) const {
  constexpr std::size_t kAhead = 8;  // edges: their half-edges may stream in, their ends do not
  std::size_t waiting = n;           // a plain edge without its pair yet
  for (std::size_t i = 0; i < n; ++i) {
    if (i + kAhead < n)
      for (unsigned side = 0; side < 2; ++side) detail::prefetch(&vd_[m_.vertex(edge(i + kAhead), side).idx()]);
    const Edge e = edge(i);
    if (m_.is_deleted(e) || !plain(e)) {
      cost(i) = measure(e);
    } else if (waiting == n) {
      waiting = i;
    } else {
      measure_pair(edge(waiting), e, cost(waiting), cost(i));
      waiting = n;
    }
  }
  if (waiting != n) cost(waiting) = measure(edge(waiting));
}

// The current collapse may change the neighbourhood being fetched between two steps; the
// records of deleted elements keep in-range indices, so such a walk only reads stale values
// (and fetches the wrong lines), and it stops after 20 steps whatever it finds.
void Decimator::start_fetch_ahead(Scratch& s, Index edge) const {
  s.ahead_stage = 0;
  if (edge == kInvalidIndex) return;
  s.ahead_edge = Edge(edge);
  s.ahead_stage = 1;
  m_.prefetch(s.ahead_edge);
  detail::prefetch(&version_[edge]);
}

void Decimator::fetch_ahead(Scratch& s) const {
  if (s.ahead_stage == 0) return;
  const Halfedge h0 = Mesh::halfedge(s.ahead_edge, 0), o0 = Mesh::opposite(h0);
  if (s.ahead_stage == 1) {
    // The ends and the triangles' other half-edges and faces. The rings start from the
    // edge's own half-edges (each is outgoing from one end), not from halfedge(v), which
    // would be one more load to wait for.
    for (int i = 0; i < 2; ++i) {
      const Halfedge x = i == 0 ? h0 : o0;
      const Vertex v = m_.to_vertex(x);
      detail::prefetch(&vd_[v.idx()]);
      m_.prefetch(v);
      if (const Face f = m_.face(x); f.is_valid()) m_.prefetch(f), m_.prefetch(m_.next(x)), m_.prefetch(m_.prev(x));
      s.ahead_ring[i] = s.ahead_ring_start[i] = x;
    }
  } else if (s.ahead_stage == 2) {
    // The opposite corners, from the half-edges stage 1 fetched.
    for (Halfedge x : {h0, o0})
      if (m_.face(x).is_valid()) detail::prefetch(&vd_[m_.to_vertex(m_.next(x)).idx()]);
  }
  // One step around both rings: the neighbour's data, and the next half-edge's record.
  bool more = false;
  for (int i = 0; i < 2; ++i) {
    Halfedge& x = s.ahead_ring[i];
    if (!x.is_valid()) continue;
    const Vertex w = m_.to_vertex(x);
    detail::prefetch(&vd_[w.idx()]);
    detail::prefetch(&version_[Mesh::edge(x).idx()]);
    x = m_.ccw_rotated(x);
    if (x == s.ahead_ring_start[i]) {
      x = Halfedge();
      continue;
    }
    m_.prefetch(x);
    more = true;
  }
  s.ahead_stage = more && s.ahead_stage < 20 ? s.ahead_stage + 1 : 0;
}

// Every edge is measured on all threads (evaluate() only reads).
void Decimator::measure_edges() {
  const std::size_t n = m_.edges_size();
  cost_.resize(n);
  parallel_for(n, opt_.threads, [&](std::size_t begin, std::size_t end) {
    measure_all(
        end - begin, [&](std::size_t i) { return Edge(static_cast<Index>(begin + i)); },
        [&](std::size_t i) -> float& { return cost_[begin + i]; });
  });
}

// The queue, from the costs as the phases left them, in edge order, so that it does not
// depend on the thread count.
void Decimator::fill_heap() {
  version_.assign(m_.edges_size(), 0);
  serial_.queue.clear();
  for (std::size_t i = 0; i < cost_.size(); ++i)
    if (cost_[i] != kNoCost && !m_.is_deleted(Edge(static_cast<Index>(i))))
      serial_.queue.push(EdgeQueue::key(cost_[i], 0), static_cast<Index>(i));
  cost_ = {};
}

void Decimator::requeue(Edge e, Worker& w) { requeue(e, measure(e), w); }

void Decimator::requeue(Edge e, float cost, Worker& w) {
  const std::uint8_t v = ++version_[e.idx()];
  if (!cost_.empty()) cost_[e.idx()] = cost;
  if (cost == kNoCost || cost > w.max_cost) return;
  if (w.region != kNoRegion && (border_[m_.vertex(e, 0).idx()] || border_[m_.vertex(e, 1).idx()])) return;
  w.queue.push(EdgeQueue::key(cost, v), e.idx());
}

namespace {
// The bits of a non-negative float order like the float; a cost that rounding made negative
// counts as zero.
std::uint32_t cost_bits(float cost) { return std::bit_cast<std::uint32_t>(std::max(cost, 0.0f)); }

}  // namespace

void Decimator::collapse_in_regions() {
  m_.prepare_deletion_marks();
  version_.assign(m_.edges_size(), 0);
  const std::size_t vertices = m_.vertices_size();
  // Regions small enough to stay in cache. The cells are of the vertices' places at the
  // start: any partition serves, this one keeps regions compact.
  partitions_ = detail::RegionPartitions(m_, center_, inv_scale_, std::max(vertices / kRegionVertices, kMinRegions),
                                         opt_.threads);
  regions_ = partitions_.regions();
  live_edges_.resize(m_.edges_size());
  parallel_for(live_edges_.size(), opt_.threads, [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) live_edges_[i] = Index(i);
  });
  workers_.clear();
  for (std::size_t r = 0; r < regions_; ++r) workers_.emplace_back(&version_).region = std::uint16_t(r);

  // The grids alternate, and each grid's runs shift every other time, so that edges near
  // one phase's borders lie inside the next phase's regions.
  const std::size_t start_faces = faces_, to_remove = faces_ - target_;
  const std::size_t tail = std::max(kMinPhase, std::size_t(kTailShare * double(std::min(to_remove, target_))));
  for (int phase = 0; faces_ - target_ > tail; ++phase) {
    region_ = partitions_.phase(phase);
    const std::size_t made = collapse_phase();
    progress_.update(0.1 + 0.85 * double(start_faces - faces_) / double(to_remove), "collapsing edges");
    if (made < kMinPhase) break;
  }
  workers_.clear();
  partitions_ = {};
  region_ = nullptr;
  border_ = {};
  live_edges_ = {};
  phase_lists_ = {};
  phase_histograms_ = {};
  phase_order_ = {};
}

std::size_t Decimator::collapse_phase() {
  // 1. The threshold: a share of the faces still to remove, in collapses, cost less (each
  // collapse removes two faces, and makes more cheap edges). Edges across borders count
  // too: with the grids alternating few stay there, and the count reads only the costs.
  // Both passes over the edges run on all threads, each part a run of edges.
  // The edges deleted since the last phase leave the list of live edges on the way.
  const std::size_t n_parts = resolve_thread_count(opt_.threads);
  auto for_each_part = [&](auto&& fn) {
    const std::size_t n_edges = live_edges_.size();
    parallel_for(
        n_parts, opt_.threads,
        [&](std::size_t begin, std::size_t end) {
          for (std::size_t k = begin; k < end; ++k) fn(k, n_edges * k / n_parts, n_edges * (k + 1) / n_parts);
        },
        1);
  };
  // The region of an edge with neither end on a border; kNoRegion for the others.
  auto region_of = [&](std::size_t i) -> std::uint16_t {
    const Edge e(static_cast<Index>(i));
    const Index a = m_.vertex(e, 0).idx(), b = m_.vertex(e, 1).idx();
    return border_[a] || border_[b] ? kNoRegion : region_[a];
  };
  constexpr int kShift = 16;
  constexpr std::size_t kBuckets = std::size_t(1) << (32 - kShift);
  std::vector<std::uint32_t>& histograms = phase_histograms_;
  histograms.assign(n_parts * kBuckets, 0);
  std::vector<std::size_t> part_live(n_parts);
  // On one thread: a byte per vertex is filled in less time than a second thread takes to start.
  border_.assign(m_.vertices_size(), 0);
  for_each_part([&](std::size_t k, std::size_t begin, std::size_t end) {
    std::uint32_t* histogram = histograms.data() + k * kBuckets;
    std::size_t live = begin;
    // Deleted edges leave gaps in the list, so its half-edges are not a stream the hardware
    // follows on its own: they are fetched some edges ahead (a third less time for the pass).
    constexpr std::size_t kAhead = 48;
    for (std::size_t j = begin; j < end; ++j) {
      if (j + kAhead < end) m_.prefetch(Edge(live_edges_[j + kAhead]));
      const Index i = live_edges_[j];
      if (m_.is_deleted(Edge(i))) continue;
      live_edges_[live++] = i;
      if (cost_[i] != kNoCost) ++histogram[cost_bits(cost_[i]) >> kShift];
      const Index a = m_.vertex(Edge(i), 0).idx(), b = m_.vertex(Edge(i), 1).idx();
      if (region_[a] != region_[b]) {
        // Both parts may mark one vertex: the same byte, stored atomically.
        std::atomic_ref<std::uint8_t>(border_[a]).store(1, std::memory_order_relaxed);
        std::atomic_ref<std::uint8_t>(border_[b]).store(1, std::memory_order_relaxed);
      }
    }
    part_live[k] = live - begin;
  });
  {
    std::size_t live = 0;
    for (std::size_t k = 0; k < n_parts; ++k) {
      const std::size_t begin = live_edges_.size() * k / n_parts;
      std::copy_n(live_edges_.begin() + std::ptrdiff_t(begin), part_live[k],
                  live_edges_.begin() + std::ptrdiff_t(live));
      live += part_live[k];
    }
    live_edges_.resize(live);
  }
  const std::size_t wanted = (faces_ - target_) / kThresholdShare;
  std::size_t below = 0, last_bucket = 0;
  for (std::size_t b = 0; b < kBuckets && below < wanted; ++b) {
    std::size_t count = 0;
    for (std::size_t k = 0; k < n_parts; ++k) count += histograms[k * kBuckets + b];
    below += count;
    if (count) last_bucket = b;
  }
  const float max_cost = std::bit_cast<float>(std::uint32_t(((last_bucket + 1) << kShift) - 1));

  // 2. Each region's queue: its edges below the threshold with both ends inside it, queued
  // in edge order whatever the number of parts.
  std::vector<std::vector<Queued>>& lists = phase_lists_;  // kept: their memory serves every phase
  lists.resize(n_parts * regions_);
  for (std::vector<Queued>& list : lists) list.clear();
  for_each_part([&](std::size_t k, std::size_t begin, std::size_t end) {
    // Only the edges below the threshold are read past their cost, too sparsely for the
    // hardware to see a stream: their half-edges are fetched a few edges ahead.
    constexpr std::size_t kAhead = 64;
    for (std::size_t j = begin; j < end; ++j) {
      if (j + kAhead < end) {
        const Index ahead = live_edges_[j + kAhead];
        if (cost_[ahead] <= max_cost) m_.prefetch(Edge(ahead));
      }
      const Index i = live_edges_[j];
      if (cost_[i] == kNoCost || cost_[i] > max_cost) continue;
      const std::uint16_t r = region_of(i);
      if (r != kNoRegion) lists[k * regions_ + r].push_back({EdgeQueue::key(cost_[i], version_[i]), Index(i)});
    }
  });
  parallel_for(
      regions_, opt_.threads,
      [&](std::size_t begin, std::size_t end) {
        for (std::size_t r = begin; r < end; ++r) {
          Worker& w = workers_[r];
          w.queue.clear();
          w.max_cost = max_cost;
          w.tally = {};
          w.collapses = w.removed_faces = 0;
          w.max_error_sq = 0;
          w.refused_for_error = false;
          w.remeasure.clear();
          for (std::size_t k = 0; k < n_parts; ++k)
            for (const Queued& q : lists[k * regions_ + r]) w.queue.push(q.key, q.edge);
        }
      },
      1);
  // Each region may remove its share of the faces still to remove, by its candidates, so
  // that the regions together never pass the target.
  std::size_t total = 0;
  for (const Worker& w : workers_) total += w.queue.size();
  if (total == 0) return 0;
  for (Worker& w : workers_)
    w.face_budget = std::size_t(double(faces_ - target_) * double(w.queue.size()) / double(total));

  // 3. The regions, on all threads; each thread takes the next region left, the largest
  // queues first, so that no thread is left with a long one while the others wait.
  std::vector<std::uint16_t>& order = phase_order_;
  order.resize(regions_);
  std::iota(order.begin(), order.end(), std::uint16_t(0));
  std::stable_sort(order.begin(), order.end(), [&](std::uint16_t x, std::uint16_t y) {
    return workers_[x].queue.size() > workers_[y].queue.size();
  });
  std::atomic<std::size_t> next{0};
  parallel_for(
      n_parts, opt_.threads,
      [&](std::size_t begin, std::size_t end) {
        for (std::size_t t = begin; t < end; ++t)
          for (std::size_t r; (r = next.fetch_add(1)) < regions_;) collapse_region(workers_[order[r]]);
      },
      1);

  // 4. Together again.
  std::size_t made = 0;
  for (Worker& w : workers_) {
    m_.add_deletions(w.tally);
    faces_ -= w.removed_faces;
    made += w.collapses;
    report_.collapses += w.collapses;
    max_error_sq_seen_ = std::max(max_error_sq_seen_, w.max_error_sq);
    refused_for_error_ = refused_for_error_ || w.refused_for_error;
    for (Index i : w.remeasure) cost_[i] = measure(Edge(i));
  }
  return made;
}

// A region's greedy loop: its cheapest edge first, while it costs at most the threshold and
// the region's share of faces lasts.
void Decimator::collapse_region(Worker& w) {
  const double max_error_sq = opt_.max_error * opt_.max_error;
  while (!w.queue.empty() && w.removed_faces + 2 <= w.face_budget) {
    const EdgeQueue::Entry entry = w.queue.pop();
    if (entry.edge == kInvalidIndex) continue;
    const Edge e(entry.edge);
    if (EdgeQueue::version(entry.key) != version_[e.idx()] || m_.is_deleted(e)) continue;
    ++version_[e.idx()];
    start_fetch_ahead(w.scratch, w.queue.peek());
    Candidate c;
    if (!evaluate(e, c)) {
      cost_[e.idx()] = kNoCost;
      continue;
    }
    cost_[e.idx()] = c.cost;
    if (c.cost > w.max_cost) continue;
    const Halfedge h = Mesh::halfedge(e, c.side);
    const double error_sq = error_sq_of(h, c);
    if (max_error_sq > 0 && error_sq > max_error_sq) {
      w.refused_for_error = true;
      cost_[e.idx()] = kNoCost;
      continue;
    }
    fetch_ahead(w.scratch);
    const Refusal why = check(h, c.position, w.scratch, w.region);
    if (why == kRegion) continue;  // its cost stays: a later phase's regions lie elsewhere
    if (why != kLegal) {
      cost_[e.idx()] = kNoCost;
      continue;
    }
    fetch_ahead(w.scratch);
    w.removed_faces += std::size_t(collapse(h, c, w));
    ++w.collapses;
    w.max_error_sq = std::max(w.max_error_sq, error_sq);
  }
}

// Rotation limit and degeneracy of one triangle (apex, a, b) when its apex moves.
inline bool Decimator::triangle_ok(const Vec3d& old_apex, const Vec3d& new_apex, const Vec3d& a, const Vec3d& b,
                                   Scratch& s) const {
  if (opt_.prevent_flips) {
    const Vec3d n_old = cross(a - old_apex, b - old_apex);
    const Vec3d ea = a - new_apex, eb = b - new_apex;
    const Vec3d n_new = cross(ea, eb);
    const double longest = std::max({sqrnorm(ea), sqrnorm(eb), sqrnorm(b - a)});
    const double new_sq = sqrnorm(n_new);
    // Degenerate: height below a millionth of the longest edge.
    if (!(new_sq > 1e-12 * longest * longest)) return false;
    const double old_sq = sqrnorm(n_old);
    if (old_sq > 0 && dot(n_old, n_new) < cos_max_normal_change_ * std::sqrt(old_sq * new_sq)) return false;
  }
  if (opt_.min_quality > 0) {
    s.worst_new = std::min(s.worst_new, triangle_quality(new_apex, a, b));
    s.worst_old = std::min(s.worst_old, triangle_quality(old_apex, a, b));
  }
  return true;
}

// The link condition (Dey et al.), pmp's and OpenMesh's guards against pinching and
// pillows, and the geometric checks on every triangle that survives around both ends.
// Stricter than Mesh::is_collapse_ok(), in O(valence).
Decimator::Refusal Decimator::check(Halfedge h, const Point& target, Scratch& s, std::uint16_t region) const {
  const Halfedge o = Mesh::opposite(h);
  const Vertex v0 = m_.to_vertex(o), v1 = m_.to_vertex(h);

  // The two rings, in order: each entry is a neighbour and the face between it and the next.
  // Both rings are walked at once: each step waits for the half-edge the previous one
  // named, so two walks side by side overlap their cache misses instead of queueing them.
  // They come first: during a phase nothing outside the region may be read, another thread
  // may be changing it (the faces around v0 and v1 hold only vertices of this region or of
  // its border, which no region changes).
  s.ring0.clear();
  s.ring1.clear();
  const Halfedge start0 = m_.halfedge(v0), start1 = m_.halfedge(v1);
  Halfedge x0 = start0, x1 = start1;
  bool more0 = true, more1 = true;  // neither end is isolated: both have h
  bool outside = false;
  auto step = [&](Halfedge& x, Halfedge start, bool& more, std::vector<RingEntry>& ring) {
    const Vertex w = m_.to_vertex(x);
    if (region != kNoRegion && region_[w.idx()] != region) outside = true;
    // The fold test below reads every neighbour's place from its record (the one measuring
    // the kept vertex's edges reads next, so the mesh's positions stay out of the loop):
    // start those cache misses now, so they overlap the link test instead of following it.
    detail::prefetch(&vd_[w.idx()]);
    ring.push_back({w, m_.face(x), x, Vec3d{}});
    x = m_.ccw_rotated(x);
    more = x != start;
  };
  while ((more0 || more1) && !outside) {
    if (more0) step(x0, start0, more0, s.ring0);
    if (more1) step(x1, start1, more1, s.ring1);
  }
  if (outside) return kRegion;

  const Face fl = m_.face(h), fr = m_.face(o);
  Vertex vl, vr;
  if (fl.is_valid()) {
    const Halfedge hn = m_.next(h), hp = m_.prev(h);
    vl = m_.to_vertex(hn);
    if (m_.is_boundary(Mesh::opposite(hn)) && m_.is_boundary(Mesh::opposite(hp))) return kEarLeft;
    if (vd_[vl.idx()].valence <= 3 && !(vd_[vl.idx()].flags & kBoundary)) return kValenceLeft;
  }
  if (fr.is_valid()) {
    const Halfedge on = m_.next(o), op = m_.prev(o);
    vr = m_.to_vertex(on);
    if (m_.is_boundary(Mesh::opposite(on)) && m_.is_boundary(Mesh::opposite(op))) return kEarRight;
    if (vd_[vr.idx()].valence <= 3 && !(vd_[vr.idx()].flags & kBoundary)) return kValenceRight;
  }
  // A hole of three edges would become a 2-gon (possible where build() left a multi-edge).
  if (!fl.is_valid() && m_.next(m_.next(m_.next(h))) == h) return kTriangleHole;
  if (!fr.is_valid() && m_.next(m_.next(m_.next(o))) == o) return kTriangleHole;
  const bool b0 = vd_[v0.idx()].flags & kBoundary, b1 = vd_[v1.idx()].flags & kBoundary;
  if (fl.is_valid() && fr.is_valid()) {
    if (vl == vr) return kSharedCorner;
    if (b0 && b1) return kPinch;
  }
  const int removed_faces = int(fl.is_valid()) + int(fr.is_valid());
  if (!b0 && !b1 && int(vd_[v0.idx()].valence) + int(vd_[v1.idx()].valence) - 2 - removed_faces < 3) return kLowValence;

  // Link condition: the only common neighbours are vl and vr; and a second edge v0 - v1
  // would become a loop. The rings are short, so plain scans beat marking arrays.
  int edges_to_v1 = 0;
  for (const RingEntry& r : s.ring0) edges_to_v1 += r.vertex == v1;
  if (edges_to_v1 > 1) return kDoubleEdge;
  for (const RingEntry& r1 : s.ring1) {
    if (r1.vertex == vl || r1.vertex == vr || r1.vertex == v0) continue;
    for (const RingEntry& r0 : s.ring0)
      if (r0.vertex == r1.vertex) return kLink;
  }
  // The same through extract()'s weld of build()'s copies.
  if (!weld_relaxed_ && copies_.meets_collapse(m_, h)) return kWeld;
  // Every triangle that stays, around either end, with its apex moved to the target. Quality
  // is judged over the whole neighbourhood (pmp's rule): a collapse may not make its worst
  // triangle worse than both the threshold and the worst triangle it replaces, so slivers of
  // the input do not freeze the regions around them.
  const Vec3d p_new = local(target);
  s.worst_new = s.worst_old = 1;
  if (opt_.min_quality > 0) {
    const Vec3d p0 = at(v0), p1 = at(v1);
    if (vl.is_valid()) s.worst_old = std::min(s.worst_old, triangle_quality(p0, p1, at(vl)));
    if (vr.is_valid()) s.worst_old = std::min(s.worst_old, triangle_quality(p1, p0, at(vr)));
  }
  auto faces_ok = [&](Vertex v, std::vector<RingEntry>& ring) {
    for (RingEntry& r : ring) r.position = at(r.vertex);  // nearest_in_rings() reads them too
    const Vec3d apex = at(v);
    const std::size_t n = ring.size();
    for (std::size_t i = 0; i < n; ++i) {
      const Face f = ring[i].face;
      if (!f.is_valid() || f == fl || f == fr) continue;
      if (!triangle_ok(apex, p_new, ring[i].position, ring[i + 1 == n ? 0 : i + 1].position, s)) return false;
    }
    return true;
  };
  if (!faces_ok(v0, s.ring0)) return kFold;
  if (!faces_ok(v1, s.ring1)) return kFold;
  if (s.worst_new < opt_.min_quality && s.worst_new < s.worst_old) return kQuality;
  return kLegal;
}

// Where the new vertex lies in the old surface: the nearest point of the faces around both
// ends that `take(face)` accepts, as a face and barycentric coordinates. Interpolating there is
// exact for attributes linear over the triangle (UV charts, ramps), unlike a blend along the
// edge when the quadric's optimum leaves it; off the surface, the attributes are those of the
// surface point the vertex stands for. The faces are those check() has just walked and placed
// (RingEntry::position, in the normalized frame): each is an end and two neighbours in turn, so
// no face is walked again.
template <class Take>
Decimator::RingHit Decimator::nearest_in_rings(const Vec3d& p, Vertex v0, Vertex v1, const Scratch& s,
                                               Take take) const {
  RingHit best;
  double best_distance = std::numeric_limits<double>::infinity();
  Vec3d weights{};
  auto search = [&](Vertex apex, const std::vector<RingEntry>& ring) {
    const Vec3d at_apex = at(apex);
    for (std::size_t i = 0, n = ring.size(); i < n; ++i) {
      if (!ring[i].face.is_valid() || !take(ring[i].face)) continue;
      const ClosestPoint cp =
          closest_point_on_triangle(p, at_apex, ring[i].position, ring[i + 1 == n ? 0 : i + 1].position);
      if (cp.distance < best_distance) {
        best_distance = cp.distance;
        best.ring = &ring, best.apex = apex, best.i = i;
        weights = cp.barycentric;
      }
    }
  };
  search(v0, s.ring0);
  search(v1, s.ring1);
  for (int k = 0; k < 3; ++k) best.weight[k] = float(std::clamp(weights[k], 0.0, 1.0));
  if (!(best.weight[0] + best.weight[1] + best.weight[2] > 0)) best.ring = nullptr;
  return best;
}

namespace {
// dst = sum w_i src_i for one element of a channel: f32 and f64 blend, other types take the
// value of the largest weight (ids, flags and 8-bit colours do not blend).
void blend_element(const ChannelArray& c, std::byte* dst, const std::byte* const src[3], const float w[3]) {
  const int n = c.components();
  if (c.scalar() == ScalarType::f32 || c.scalar() == ScalarType::f64) {
    // Weights normalized in double, so a blend never leaves the range of its sources.
    const double total = double(w[0]) + double(w[1]) + double(w[2]);
    for (int k = 0; k < n; ++k) {
      double sum = 0;
      for (int i = 0; i < 3; ++i) {
        if (c.scalar() == ScalarType::f32) {
          float x;
          std::memcpy(&x, src[i] + k * sizeof(float), sizeof x);
          sum += double(w[i]) / total * x;
        } else {
          double x;
          std::memcpy(&x, src[i] + k * sizeof(double), sizeof x);
          sum += double(w[i]) / total * x;
        }
      }
      if (c.scalar() == ScalarType::f32) {
        const float out = float(sum);
        std::memcpy(dst + k * sizeof(float), &out, sizeof out);
      } else {
        std::memcpy(dst + k * sizeof(double), &sum, sizeof sum);
      }
    }
  } else {
    const int heaviest = w[0] >= w[1] && w[0] >= w[2] ? 0 : w[1] >= w[2] ? 1 : 2;
    std::memcpy(dst, src[heaviest], c.stride());
  }
}
}  // namespace

// Before collapsing h (v0 -> v1) to `target`: the wedges that merge, and their new values.
// Across the triangle on the left, v0's corners continuous with its corner there join v1's
// corners continuous with v1's corner there (wedge l); likewise on the right (wedge r).
// Corners in other wedges keep their values. Each merged wedge takes the value at the new
// vertex interpolated inside its own chart's triangles, computed now, while they exist.
void Decimator::gather_wedges(Halfedge h, const Point& target, Scratch& s) const {
  const Halfedge o = Mesh::opposite(h);
  const Face fl = m_.face(h), fr = m_.face(o);
  s.wedge_faces[0].clear();
  s.wedge_faces[1].clear();
  s.wedge_present[0] = fl.is_valid();
  s.wedge_present[1] = fr.is_valid();

  // Walks the fan from `start` (an outgoing half-edge whose face holds corner `corner`),
  // rotating one way, while corners stay equal; stops at a hole or at `stop`.
  auto walk = [&](Halfedge start, Halfedge corner, bool ccw, Face stop, std::vector<Scratch::WedgeFace>& out) {
    Halfedge x = start;
    for (;;) {
      x = ccw ? m_.ccw_rotated(x) : m_.cw_rotated(x);
      const Face f = m_.face(x);
      if (x == start || !f.is_valid() || f == stop) return;
      const Halfedge c = m_.prev(x);
      if (!corners_equal(c, corner)) return;
      out.push_back({f, c});
      corner = c;
    }
  };
  if (fl.is_valid()) {
    walk(h, m_.prev(h), true, fr, s.wedge_faces[0]);   // around v0, from fl towards fr
    walk(m_.next(h), h, false, fr, s.wedge_faces[0]);  // around v1, from fl towards fr
  }
  if (fr.is_valid()) {
    walk(m_.next(o), o, false, fl, s.wedge_faces[1]);  // around v0, from fr towards fl
    walk(o, m_.prev(o), true, fl, s.wedge_faces[1]);   // around v1, from fr towards fl
  }

  std::size_t bytes = 0;
  for (const ChannelArray* c : corner_channels_) bytes += 2 * c->stride();
  s.wedge_values.resize(bytes);
  const Vec3d p = local(target);
  const Vertex v0 = m_.to_vertex(o), v1 = m_.to_vertex(h);
  // Across a non-seam edge both sides are one wedge: one value, bit for bit, or the two
  // sides would drift apart by rounding and read as a new seam.
  const bool one_wedge = fl.is_valid() && fr.is_valid() && corners_equal(m_.prev(h), o) && corners_equal(h, m_.prev(o));
  for (int side = 0; side < 2; ++side) {
    if (!s.wedge_present[side]) continue;
    if (side == 1 && one_wedge) {
      std::size_t offset = 0;
      for (const ChannelArray* c : corner_channels_) {
        std::memcpy(s.wedge_values.data() + offset + c->stride(), s.wedge_values.data() + offset, c->stride());
        offset += 2 * c->stride();
      }
      continue;
    }
    // The chart's triangles: the wedge's faces and the removed one.
    const std::vector<Scratch::WedgeFace>& faces = s.wedge_faces[side];
    const Face removed = side == 0 ? fl : fr;
    const RingHit hit = nearest_in_rings(p, v0, v1, s, [&](Face f) {
      return f == removed || std::any_of(faces.begin(), faces.end(), [f](const auto& w) { return w.face == f; });
    });
    // A face's corner at a vertex is its half-edge pointing there: at the ring's end the one
    // before `out`, at the neighbour `out`, at the next neighbour the one after.
    Halfedge corner[3];
    float weight[3] = {1, 0, 0};
    if (hit.ring) {
      const Halfedge out = (*hit.ring)[hit.i].out;
      corner[0] = m_.prev(out), corner[1] = out, corner[2] = m_.next(out);
      std::copy_n(hit.weight, 3, weight);
    } else {
      // No usable triangle (all degenerate): the kept vertex's corner in the removed face.
      corner[0] = corner[1] = corner[2] = side == 0 ? h : m_.prev(o);
    }
    std::size_t offset = 0;
    for (const ChannelArray* c : corner_channels_) {
      const std::byte* src[3] = {c->element(corner[0].idx()), c->element(corner[1].idx()), c->element(corner[2].idx())};
      blend_element(*c, s.wedge_values.data() + offset + side * c->stride(), src, weight);
      offset += 2 * c->stride();
    }
  }
}

// After the collapse: every corner of a merged wedge takes the wedge's new value.
void Decimator::blend_wedges(Vertex kept, const Scratch& s) {
  for (int side = 0; side < 2; ++side) {
    if (!s.wedge_present[side]) continue;
    for (const Scratch::WedgeFace& w : s.wedge_faces[side]) {
      if (m_.is_deleted(w.face)) continue;
      // The corner gather_wedges() saw, unless the collapse moved it (the half-edges of the
      // edges it merges may be renumbered): then the face is walked to find it.
      Halfedge x = w.corner;
      if (m_.is_deleted(Mesh::edge(x)) || m_.face(x) != w.face || m_.to_vertex(x) != kept) {
        x = m_.halfedge(w.face);
        while (m_.to_vertex(x) != kept) x = m_.next(x);
      }
      std::size_t offset = 0;
      for (ChannelArray* c : corner_channels_) {
        std::memcpy(c->element(x.idx()), s.wedge_values.data() + offset + side * c->stride(), c->stride());
        offset += 2 * c->stride();
      }
    }
  }
}

// Vertex attributes at the new vertex: real-valued host channels by barycentric interpolation
// in the old triangle holding it, located before the collapse while those triangles exist;
// everything else by the generic interpolation along the edge (the nearer end's value).
// The triangles are those around both ends, from the rings check() has just walked and
// placed (RingEntry::position, in the normalized frame): each face around an end is that end
// and two neighbours in turn, so no face is walked again.
void Decimator::locate_vertex(Vertex v0, Vertex v1, const Candidate& c, Scratch& s) const {
  const RingHit hit = nearest_in_rings(local(c.position), v0, v1, s, [](Face) { return true; });
  s.vertex_blend_size = 0;
  if (!hit.ring) return;
  const std::vector<RingEntry>& ring = *hit.ring;
  const Vertex corners[3] = {hit.apex, ring[hit.i].vertex, ring[hit.i + 1 == ring.size() ? 0 : hit.i + 1].vertex};
  for (int i = 0; i < 3; ++i) {
    s.vertex_blend_index[i] = corners[i].idx();
    s.vertex_blend_weight[i] = hit.weight[i];
  }
  s.vertex_blend_size = 3;
}

void Decimator::interpolate_vertex(Vertex removed, Vertex kept, const Candidate& c, Scratch& s) {
  if (vertex_arrays_.empty()) return;
  s.interp_index[0] = removed.idx();
  s.interp_index[1] = kept.idx();
  s.interp_weight[0] = 1 - c.kept_weight;
  s.interp_weight[1] = c.kept_weight;
  const bool copies = copies_.is_copy(removed) || copies_.is_copy(kept);
  for (const VertexArray& a : vertex_arrays_) {
    // Where a copy goes, the kept vertex keeps its own source: taking the copy's would weld
    // it to the copy's other copies.
    if (copies && a.array->is_internal()) continue;
    if (a.located && s.vertex_blend_size == 3 && a.located->stride() <= 256) {
      // Deleted vertices keep their rows until garbage collection: the removed end's too.
      std::byte out[256];
      const std::byte* src[3] = {a.located->element(s.vertex_blend_index[0]),
                                 a.located->element(s.vertex_blend_index[1]),
                                 a.located->element(s.vertex_blend_index[2])};
      blend_element(*a.located, out, src, s.vertex_blend_weight);
      std::memcpy(a.located->element(kept.idx()), out, a.located->stride());
    } else {
      a.array->interpolate(kept.idx(), std::span<const Index>(s.interp_index, 2),
                           std::span<const float>(s.interp_weight, 2));
    }
  }
}

Decimator::Collapsed Decimator::apply_collapse(Halfedge h, const Candidate& c, Scratch& s, Mesh::Deletions& tally) {
  const Halfedge o = Mesh::opposite(h);
  const Vertex v0 = m_.to_vertex(o), v1 = m_.to_vertex(h);
  const Face fl = m_.face(h), fr = m_.face(o);
  const Vertex vl = fl.is_valid() ? m_.to_vertex(m_.next(h)) : Vertex();
  const Vertex vr = fr.is_valid() ? m_.to_vertex(m_.next(o)) : Vertex();
  Collapsed done{
      v1,
      {},
      {Mesh::edge(h), Mesh::edge(m_.next(h)), Mesh::edge(m_.prev(h)), Mesh::edge(m_.next(o)), Mesh::edge(m_.prev(o))},
      int(fl.is_valid()) + int(fr.is_valid())};
  // With no seam at either end or at the opposite corners, every corner at the kept vertex
  // takes the one merged wedge's value and the others keep theirs: no seam can appear, so
  // nothing needs classifying afterwards.
  auto seam_at = [&](Vertex v) { return v.is_valid() && (vd_[v.idx()].flags & kSeamBits); };
  const bool near_seam = seam_mode_ && (seam_at(v0) || seam_at(v1) || seam_at(vl) || seam_at(vr));

  if (!corner_channels_.empty()) gather_wedges(h, c.position, s);
  // Located before the collapse, while the old triangles exist; written after it.
  if (locate_vertices_) locate_vertex(v0, v1, c, s);
  // check() has just passed: it implies Mesh::is_collapse_ok() on a triangle mesh (its link
  // test, ears, pinches and 3-edge holes are the same; a tetrahedron's apex has valence 3,
  // which kValenceLeft/Right refuse), so the mesh's own test, which costs as much as the
  // collapse, is not run again.
  m_.collapse_unchecked(h, tally);
  fetch_ahead(s);
  m_.position(v1) = c.position;
#ifdef HEDGE_DECIMATE_DEBUG
  if (Validation val = validate(m_); !val.ok)
    throw Error("decimate debug: collapse of " + std::to_string(v0.idx()) + " into " + std::to_string(v1.idx()) +
                " broke the mesh: " + val.message);
#endif
  // The merged quadric, moved to be about the new position.
  VertexData &d0 = vd_[v0.idx()], &d1 = vd_[v1.idx()];
  const Vec3d c0 = to_double(d0.position), c1 = to_double(d1.position);
  const Vec3d moved = local(v1);
  d1.quadric.store(merged_about_first(d1.quadric, d0.quadric, c0 - c1).shifted(moved - c1));
  s.shape_before.resize(2 * shapes_.size());
  for (std::size_t k = 0; k < shapes_.size(); ++k) {
    s.shape_before[2 * k] = shape_at(k, v0);
    s.shape_before[2 * k + 1] = shape_at(k, v1);
  }
  d1.position = to_float(moved);
  interpolate_vertex(v0, v1, c, s);
  // Each shape's merged quadric, about the new vertex's place there (its blended offset).
  for (std::size_t k = 0; k < shapes_.size(); ++k) {
    const Vec3d k0 = s.shape_before[2 * k], k1 = s.shape_before[2 * k + 1];
    PackedQuadric& q1 = shape_quadric(k, v1);
    q1.store(merged_about_first(q1, shape_quadric(k, v0), k0 - k1).shifted(shape_at(k, v1) - k1));
  }
  if (!corner_channels_.empty()) blend_wedges(v1, s);

  d1.valence = static_cast<std::uint16_t>(d0.valence + d1.valence - 2 - done.removed_faces);
  if (vl.is_valid()) --vd_[vl.idx()].valence;
  if (vr.is_valid()) --vd_[vr.idx()].valence;

  // The kept vertex is on the boundary when either end was, and stays locked when it was (the
  // removed end never is); vl and vr keep their status.
  d1.flags = (d0.flags | d1.flags) & (kBoundary | kLocked);
  if (near_seam) {
    d1.flags |= classify(v1);
    for (int i = 0; i < 2; ++i) {
      const Vertex v = i == 0 ? vl : vr;
      if (!v.is_valid()) continue;
      const std::uint8_t f = std::uint8_t((vd_[v.idx()].flags & ~kSeamBits) | classify(v));
      if (f == vd_[v.idx()].flags) continue;
      vd_[v.idx()].flags = f;
      done.reclassified[i] = v;
    }
  }
  return done;
}

int Decimator::collapse(Halfedge h, const Candidate& c, Worker& w) {
  const Collapsed done = apply_collapse(h, c, w.scratch, w.tally);
  // Queue entries of deleted edges go stale.
  for (Edge d : done.doomed)
    if (m_.is_deleted(d)) {
      ++version_[d.idx()];
      if (!cost_.empty()) cost_[d.idx()] = kNoCost;
    }
  // A region measures again only its own edges; the others wait for the phase's end.
  for (Vertex v : done.reclassified)
    if (v.is_valid())
      for (Halfedge x : m_.outgoing(v)) {
        if (w.region == kNoRegion || region_[m_.to_vertex(x).idx()] == w.region)
          requeue(Mesh::edge(x), w);
        else
          w.remeasure.push_back(Mesh::edge(x).idx());
      }
  // Every edge at the kept vertex changed (its neighbours are all in the region): evaluate
  // them now, while their half-edges are in cache (one sweep to fetch the neighbours' data,
  // one to evaluate), rather than when they surface cold.
  // Measured a ring's worth at a time (the plain ones two at a time), then queued in ring order.
  constexpr std::size_t kMaxRing = 32;
  Edge ring[kMaxRing];
  float costs[kMaxRing];
  std::size_t n = 0;
  auto measure_and_queue = [&] {
    measure_all(
        n, [&](std::size_t i) { return ring[i]; }, [&](std::size_t i) -> float& { return costs[i]; });
    for (std::size_t i = 0; i < n; ++i) {
      requeue(ring[i], costs[i], w);
      fetch_ahead(w.scratch);
    }
    n = 0;
  };
  for (Halfedge x : m_.outgoing(done.kept)) {
    detail::prefetch(&vd_[m_.to_vertex(x).idx()]);
    ring[n++] = Mesh::edge(x);
    if (n == kMaxRing) measure_and_queue();
  }
  measure_and_queue();
  return done.removed_faces;
}

DecimateReport Decimator::run() {
  report_.faces_before = m_.n_faces();
  report_.vertices_before = m_.n_vertices();
  cos_max_normal_change_ = std::cos(std::min(opt_.max_normal_change_degrees, 90.0) * std::numbers::pi / 180);

  progress_.update(0, "preparing");
  read_weights_and_locks();  // first: a name the mesh lacks leaves it untouched
  triangulate_polygons();
  faces_ = m_.n_faces();
  // The faces the ratio applies to: all, or the selected ones (the rest stay).
  std::size_t reducible = faces_;
  if (opt_.selection_only) {
    const std::vector<std::uint8_t> selected = detail::selected_faces(m_);
    reducible = 0;
    for (Face f : m_.faces()) reducible += selected[f.idx()];
    inside_selection_ = detail::inside_selection(m_, selected);
  }
  if (opt_.target_faces > 0)
    target_ = opt_.target_faces;
  else
    target_ = faces_ - reducible + static_cast<std::size_t>(std::llround(opt_.target_ratio * double(reducible)));
  report_.target_faces = target_;
  if (faces_ <= target_ || faces_ == 0) {
    report_.faces_after = faces_;
    report_.vertices_after = m_.n_vertices();
    report_.stopped_by = "nothing to do";
    if (report_.triangulated_faces) m_.compact();
    return report_;
  }

  compute_frame();
  find_shapes();
  compute_quadrics();
  find_corner_channels();
  classify_vertices();
  progress_.update(0.05, "measuring edges");
  measure_edges();
  progress_.update(0.1, "measuring edges");
  if (faces_ >= kRegionsMinFaces) collapse_in_regions();
  fill_heap();

  const double max_error_sq = opt_.max_error * opt_.max_error;
  const std::size_t to_remove = faces_ - target_;
  const std::size_t start_faces = faces_;
  std::size_t collapses_since_fill = 0, refills = 0;
  std::size_t steps = 0;
  while (faces_ > target_) {
    if (serial_.queue.empty()) {
      // Edges refused earlier (fold-overs, link condition) may be legal now that their
      // neighbourhood changed: queue every edge again while that still helps. Past the
      // preferred limit on turning triangles, only flips stay forbidden.
      if (faces_ == target_ + 1 && skipped_for_parity_) {
        // Only a boundary collapse fits, and on a non-manifold input the boundary may be
        // all split non-manifold edges, which the weld guards.
        if (!relax_weld()) break;
      } else if (cos_max_normal_change_ > 0) {
        cos_max_normal_change_ = 0;
      } else if (collapses_since_fill == 0 || ++refills > 4) {
        // Short of the target: collapses may meet the weld of build()'s copies too, as the
        // last resort (extract() keeps apart the copies whose weld would then add a defect).
        if (!relax_weld()) break;
        refills = 0;
      }
      collapses_since_fill = 0;
      for (Edge e : m_.edges()) requeue(e, serial_);
      continue;
    }
    if ((++steps & 0x3ff) == 0)
      progress_.update(0.1 + 0.85 * double(start_faces - faces_) / double(to_remove), "collapsing edges");

    const EdgeQueue::Entry entry = serial_.queue.pop();
    if (entry.edge == kInvalidIndex) continue;
    const Edge e(entry.edge);
    if (EdgeQueue::version(entry.key) != version_[e.idx()] || m_.is_deleted(e)) continue;
    ++version_[e.idx()];  // out of the queue now
    start_fetch_ahead(serial_.scratch, serial_.queue.peek());
    // Its placement is computed again rather than stored, which keeps the per-edge state to
    // one byte; the vertex data it reads is needed for the collapse anyway.
    Candidate c;
    if (!evaluate(e, c)) continue;

    const Halfedge h = Mesh::halfedge(e, c.side);
    const double error_sq = error_sq_of(h, c);
    if (max_error_sq > 0 && error_sq > max_error_sq) {
      refused_for_error_ = true;
      continue;
    }
    if (faces_ == target_ + 1 && !m_.is_boundary(e)) {
      // An interior collapse would overshoot by one; only a boundary one fits.
      skipped_for_parity_ = true;
      if (!has_boundary_) break;
      continue;
    }
    fetch_ahead(serial_.scratch);
    if (check(h, c.position, serial_.scratch) != kLegal) continue;
    fetch_ahead(serial_.scratch);
    faces_ -= std::size_t(collapse(h, c, serial_));
    ++report_.collapses;
    ++collapses_since_fill;
    max_error_sq_seen_ = std::max(max_error_sq_seen_, error_sq);
  }

#ifdef HEDGE_DECIMATE_DEBUG
  {
    int hist[kRefusals] = {0}, no_candidate = 0, ok = 0;
    for (Edge e : m_.edges()) {
      Candidate c;
      if (!evaluate(e, c)) {
        ++no_candidate;
        continue;
      }
      const Refusal why = check(Mesh::halfedge(e, c.side), c.position, serial_.scratch);
      if (why == kLegal)
        ++ok;
      else
        ++hist[why];
    }
    std::fprintf(stderr, "end: %d without candidate, %d legal;", no_candidate, ok);
    for (int i = 0; i < kRefusals; ++i)
      if (hist[i]) std::fprintf(stderr, " [%d]=%d", i, hist[i]);
    std::fprintf(stderr, "\n");
  }
#endif
  m_.add_deletions(serial_.tally);
  progress_.update(0.95, "compacting");
  m_.compact();
  report_.faces_after = m_.n_faces();
  report_.vertices_after = m_.n_vertices();
  report_.max_error = std::sqrt(max_error_sq_seen_);
  if (faces_ <= target_)
    report_.stopped_by = "target reached";
  else if (faces_ == target_ + 1 && skipped_for_parity_)
    report_.stopped_by = "stopped one triangle above the target: an interior collapse removes two";
  else if (refused_for_error_)
    report_.stopped_by = "max_error reached";
  else
    report_.stopped_by = "no legal collapse left";
  progress_.update(1, "done");
  return report_;
}

void check_options(const DecimateOptions& o) {
  if (!(o.target_ratio >= 0 && o.target_ratio <= 1))
    throw Error("decimate: target_ratio must be a number from 0 to 1, got " + std::to_string(o.target_ratio));
  if (!(o.max_error >= 0 && o.max_error <= 1))
    throw Error("decimate: max_error must be a number from 0 to 1 (a fraction of the bounding-box diagonal), got " +
                std::to_string(o.max_error));
  if (!(o.min_quality >= 0 && o.min_quality <= 1))
    throw Error("decimate: min_quality must be a number from 0 to 1, got " + std::to_string(o.min_quality));
  if (!(o.max_normal_change_degrees >= 0 && o.max_normal_change_degrees <= 90))
    throw Error("decimate: max_normal_change_degrees must be from 0 to 90, got " +
                std::to_string(o.max_normal_change_degrees));
  if (!(o.weight_strength >= 0 && o.weight_strength <= kMaxWeightStrength))
    throw Error("decimate: weight_strength must be a number from 0 to " + std::to_string(int(kMaxWeightStrength)) +
                ", got " + std::to_string(o.weight_strength));
  if (o.target_faces > std::size_t(std::numeric_limits<Index>::max()))
    throw Error("decimate: target_faces is larger than any mesh can be");
}

}  // namespace

DecimateReport decimate(Mesh& mesh, const DecimateOptions& options, Progress& progress) {
  check_options(options);
  // Only a caller-supplied progress can cancel half-way; keep a copy to restore then.
  std::optional<Mesh> backup;
  if (options.keep_input_on_failure && &progress != &Progress::none()) backup = mesh;
  try {
    return Decimator(mesh, options, progress).run();
  } catch (...) {
    if (backup) mesh = std::move(*backup);
    throw;
  }
}

Operation decimate_operation() {
  const char* help =
      "Reduces the number of triangles while keeping the shape: repeatedly collapses the edge whose removal "
      "changes the surface least, measured by quadric error metrics (Garland and Heckbert, SIGGRAPH 1997), and "
      "puts the merged vertex where that error is smallest. Use it to make scans and dense meshes light enough to "
      "display, edit or send. Polygons are triangulated first. Vertex attributes are interpolated at the new "
      "vertex; per-corner attributes such as UVs are interpolated per wedge and kept continuous across seams "
      "(after Hoppe 1999), and vertices on a seam only slide along it. Boundaries stay in place by default, no "
      "triangle is flipped, and the topology never changes: holes, handles and components stay, so a mesh full "
      "of small pieces and slits may stop above its target. Shape keys weigh in the error: each collapse is "
      "measured in every key too, so a key's shape is kept as well as the mesh's. Other attributes do not (a UV "
      "seam or colour edge is kept by the seam rules, not by the metric), and creases get no special treatment "
      "beyond what the quadrics give them.";
  using O = DecimateOptions;
  using R = DecimateReport;
  return Binding<O, R>("decimate", "Decimate", Category::remeshing, help, decimate)
      .fixed(&O::keep_input_on_failure, false)
      .option(&O::target_faces, "target_faces", "Target faces", between(0, kMaxCorners),  // 32-bit indices
              "Number of triangles to reach; 0 uses the target ratio instead. On a closed surface an "
              "odd count stops one above it, since a collapse there removes two triangles.")
      .option(&O::target_ratio, "target_ratio", "Target ratio", between(0, 1),
              "Fraction of the triangles to keep, when target faces is 0.")
      .option(&O::max_error, "max_error", "Max error", between(0, 1),
              "Never collapse an edge whose error exceeds this fraction of the bounding-box diagonal "
              "(it may then stop above the target); 0 = no limit.")
      .option(&O::preserve_boundary, "preserve_boundary", "Preserve boundary",
              "Boundary vertices stay where they are; boundary edges only collapse along the boundary.")
      .option(&O::preserve_uv_seams, "preserve_uv_seams", "Preserve UV seams",
              "Keep per-corner attributes (UVs, corner normals, colours) continuous: vertices on a seam "
              "only move along it, seam ends and junctions stay.")
      .option(&O::prevent_flips, "prevent_flips", "Prevent flips",
              "Refuse collapses that turn a triangle over (normal change of 90 degrees or more) or make "
              "it degenerate; collapses turning triangles by at most 30 degrees go first.")
      .option(&O::min_quality, "min_quality", "Min triangle quality", between(0, 1),
              "Refuse collapses that create triangles of quality (2 inradius / circumradius, 1 = "
              "equilateral) below this, unless the triangles they replace were already worse.")
      .selection(&O::selection_only,
                 "Only the selected faces are simplified, the target ratio applying to them; faces outside "
                 "the selection stay as they are, and so does the border between the two.")
      .vertex_channel(&O::weight_attribute, "weight_attribute", "Weight attribute",
                      "A vertex attribute saying where detail matters (Blender: a vertex group; MeshLab: "
                      "quality): a vertex of weight w counts its error 1 + strength x w times, so weighted "
                      "regions keep more triangles. Weights run from 0 to 1; other ranges are rescaled. Empty: "
                      "none.")
      .option(&O::weight_strength, "weight_strength", "Weight strength", between(0, kMaxWeightStrength),
              "How much a weight of 1 protects a vertex: its error counts 1 + this many times.")
      .vertex_channel(&O::lock_attribute, "lock_attribute", "Lock attribute",
                      "A vertex attribute (Blender: a vertex group) whose non-zero vertices are locked: they "
                      "neither move nor go. Empty: none.")
      .result(&R::faces_before, "faces_before")
      .result(&R::faces_after, "faces_after")
      .result(&R::vertices_before, "vertices_before")
      .result(&R::vertices_after, "vertices_after")
      .result(&R::target_faces, "target_faces")
      .result(&R::collapses, "collapses")
      .result(&R::triangulated_faces, "triangulated_faces")
      .result(&R::max_error, "max_error")
      .result("locked_vertices",
              [](const O& o, const R& r) -> std::optional<Value> {
                if (o.lock_attribute.empty()) return std::nullopt;
                return field_value(r.locked_vertices);
              })
      .result(&R::stopped_by, "stopped_by")
      .messages(&R::messages);
}

}  // namespace hedge
