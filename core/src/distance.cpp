// Closest points on triangles through an AABB tree (binned SAH), and the sampled
// Hausdorff distance between two meshes built on it.
#include "hedge/distance.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <exception>
#include <string>
#include <thread>

#include "hedge/error.h"
#include "hedge/threads.h"
#include "parallel.h"

namespace hedge {

ClosestPoint closest_point_on_triangle(const Vec3d& p, const Vec3d& a, const Vec3d& b, const Vec3d& c) {
  // Voronoi regions of the triangle's features (Ericson, Real-Time Collision Detection 5.1.5),
  // with guards so that degenerate triangles give an edge or corner instead of NaN.
  ClosestPoint r;
  r.triangle = 0;
  auto finish = [&](const Vec3d& bary) {
    r.barycentric = bary;
    r.point = a * bary[0] + b * bary[1] + c * bary[2];
    r.distance = distance(p, r.point);
    return r;
  };
  Vec3d ab = b - a, ac = c - a, ap = p - a;
  double ab2 = sqrnorm(ab), ac2 = sqrnorm(ac);
  if (!(sqrnorm(cross(ab, ac)) > 1e-24 * ab2 * ac2)) {
    // Degenerate (collinear or repeated corners): the region tests below lose their
    // meaning, the nearest of the three segments is the answer.
    ClosestPoint best;
    const Vec3d* corners[3] = {&a, &b, &c};
    for (int i = 0; i < 3; ++i) {
      const Vec3d& s = *corners[i];
      const Vec3d& t = *corners[(i + 1) % 3];
      Vec3d st = t - s;
      double len2 = sqrnorm(st);
      double u = len2 > 0 ? std::clamp(dot(p - s, st) / len2, 0.0, 1.0) : 0.0;
      Vec3d bary{};
      bary[i] = 1 - u;
      bary[(i + 1) % 3] = u;
      ClosestPoint cand = finish(bary);
      if (cand.distance < best.distance) best = cand;
    }
    return best;
  }
  double d1 = dot(ab, ap), d2 = dot(ac, ap);
  if (d1 <= 0 && d2 <= 0) return finish({{1, 0, 0}});
  Vec3d bp = p - b;
  double d3 = dot(ab, bp), d4 = dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) return finish({{0, 1, 0}});
  double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) {
    double den = d1 - d3;
    double v = den > 0 ? d1 / den : 0;
    return finish({{1 - v, v, 0}});
  }
  Vec3d cp = p - c;
  double d5 = dot(ab, cp), d6 = dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) return finish({{0, 0, 1}});
  double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) {
    double den = d2 - d6;
    double w = den > 0 ? d2 / den : 0;
    return finish({{1 - w, 0, w}});
  }
  double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
    double den = (d4 - d3) + (d5 - d6);
    double w = den > 0 ? (d4 - d3) / den : 0;
    return finish({{0, 1 - w, w}});
  }
  double sum = va + vb + vc;
  double v = vb / sum, w = vc / sum;
  return finish({{1 - v - w, v, w}});
}

namespace {

constexpr Index kLeafSize = 4;
constexpr int kBins = 12;

struct Box {
  float lo[3] = {std::numeric_limits<float>::max(), std::numeric_limits<float>::max(),
                 std::numeric_limits<float>::max()};
  float hi[3] = {-std::numeric_limits<float>::max(), -std::numeric_limits<float>::max(),
                 -std::numeric_limits<float>::max()};
  void add(const Box& b) {
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], b.lo[k]);
      hi[k] = std::max(hi[k], b.hi[k]);
    }
  }
  void add(float x, float y, float z) {
    lo[0] = std::min(lo[0], x), hi[0] = std::max(hi[0], x);
    lo[1] = std::min(lo[1], y), hi[1] = std::max(hi[1], y);
    lo[2] = std::min(lo[2], z), hi[2] = std::max(hi[2], z);
  }
  double half_area() const {
    if (hi[0] < lo[0]) return 0;
    double dx = double(hi[0]) - lo[0], dy = double(hi[1]) - lo[1], dz = double(hi[2]) - lo[2];
    return dx * dy + dy * dz + dz * dx;
  }
};

// One triangle while building: its box, centroid and index, kept contiguous so that each
// node's pass over its range streams through memory.
struct Ref {
  Box box;
  float c[3];
  Index id;
};

struct Bin {
  Box box, cbox;  // triangles' boxes and centroids
  Index count = 0;
};

// Node layout the builder writes (same as TriangleTree::Node).
struct BuildNode {
  float lo[3], hi[3];
  Index index, count;
};

// The triangles while building, each written before it is read.
using Refs = std::vector<Ref, detail::UnsetAllocator<Ref>>;
// Every node's fields are written as it is made, so the array needs no fill.
using BuildNodes = std::vector<BuildNode, detail::UnsetAllocator<BuildNode>>;

// Builds the hierarchy over refs[begin, end) depth first (a node's first child directly
// follows it); box and cbox bound the range's triangles and centroids, computed by the
// parent's bins so every level costs one pass.
struct Builder {
  Refs& refs;

  // Chooses the split: fills the bounds of both sides and returns the middle, or begin
  // when the range should stay a leaf.
  Index split(Index begin, Index end, const Box& cbox, Box child_box[2], Box child_cbox[2]) {
    // Binning along the longest axis of the centroids only: a third of the work of trying
    // all three, for trees that answer queries about as fast.
    int axis = 0;
    for (int k = 1; k < 3; ++k)
      if (double(cbox.hi[k]) - cbox.lo[k] > double(cbox.hi[axis]) - cbox.lo[axis]) axis = k;
    Bin bins[kBins];
    const double lo = cbox.lo[axis], extent = double(cbox.hi[axis]) - lo;
    if (!(extent > 0)) return begin;  // all centroids coincide
    const float scale = static_cast<float>(kBins / extent), lo_f = static_cast<float>(lo);
    auto bin_of = [&](const Ref& r) { return std::min(kBins - 1, static_cast<int>((r.c[axis] - lo_f) * scale)); };
    // Neighbouring triangles mostly fall in one bin, where each bound would wait for the
    // last one's: two sets of bins, taking the triangles in turn, halve those chains.
    Bin other_bins[kBins];
    auto put = [&](Bin* set, const Ref& r) {
      Bin& bin = set[bin_of(r)];
      ++bin.count;
      bin.box.add(r.box);
      bin.cbox.add(r.c[0], r.c[1], r.c[2]);
    };
    Index i = begin;
    for (; i + 1 < end; i += 2) {
      put(bins, refs[i]);
      put(other_bins, refs[i + 1]);
    }
    if (i < end) put(bins, refs[i]);
    for (int b = 0; b < kBins; ++b) {
      bins[b].count += other_bins[b].count;
      bins[b].box.add(other_bins[b].box);
      bins[b].cbox.add(other_bins[b].cbox);
    }
    const Index count = end - begin;
    int best_split = 0;
    double best_cost = std::numeric_limits<double>::infinity();
    double right_cost[kBins];
    Box acc;
    Index n = 0;
    for (int b = kBins - 1; b > 0; --b) {
      acc.add(bins[b].box);
      n += bins[b].count;
      right_cost[b] = acc.half_area() * n;
    }
    acc = Box();
    n = 0;
    for (int b = 0; b < kBins - 1; ++b) {
      acc.add(bins[b].box);
      n += bins[b].count;
      double cost = acc.half_area() * n + right_cost[b + 1];
      if (n > 0 && n < count && cost < best_cost) best_cost = cost, best_split = b + 1;
    }
    if (best_split == 0) return begin;
    for (int side = 0; side < 2; ++side) child_box[side] = child_cbox[side] = Box();
    for (int b = 0; b < kBins; ++b) {
      int side = b < best_split ? 0 : 1;
      child_box[side].add(bins[b].box);
      child_cbox[side].add(bins[b].cbox);
    }
    auto it =
        std::partition(refs.begin() + begin, refs.begin() + end, [&](const Ref& r) { return bin_of(r) < best_split; });
    return static_cast<Index>(it - refs.begin());
  }

  static void set_box(BuildNode& n, const Box& box) {
    for (int k = 0; k < 3; ++k) n.lo[k] = box.lo[k], n.hi[k] = box.hi[k];
  }

  // Bounds of a range whose centroids coincide, halved to bound the depth.
  void bounds(Index begin, Index end, Box& box, Box& cbox) {
    box = cbox = Box();
    for (Index i = begin; i < end; ++i) {
      box.add(refs[i].box);
      cbox.add(refs[i].c[0], refs[i].c[1], refs[i].c[2]);
    }
  }

  Index build(Index begin, Index end, const Box& box, const Box& cbox, BuildNodes& nodes, int depth) {
    Index id = static_cast<Index>(nodes.size());
    nodes.emplace_back();
    set_box(nodes[id], box);
    Index count = end - begin;
    Box child_box[2], child_cbox[2];
    Index mid = begin;
    if (count > kLeafSize && depth < 64) {
      mid = split(begin, end, cbox, child_box, child_cbox);
      if (mid == begin && count > 2 * kLeafSize) {
        mid = begin + count / 2;
        bounds(begin, mid, child_box[0], child_cbox[0]);
        bounds(mid, end, child_box[1], child_cbox[1]);
      }
    }
    if (mid == begin) {
      nodes[id].index = begin;
      nodes[id].count = count;
      return id;
    }
    build(begin, mid, child_box[0], child_cbox[0], nodes, depth + 1);
    Index right = build(mid, end, child_box[1], child_cbox[1], nodes, depth + 1);
    nodes[id].index = right;
    nodes[id].count = 0;
    return id;
  }

  // The root's two subtrees on two threads (when there are two), then the second appended
  // to the first.
  void build_parallel(Index n, const Box& box, const Box& cbox, BuildNodes& nodes) {
    Box child_box[2], child_cbox[2];
    Index mid = n > 65536 ? split(0, n, cbox, child_box, child_cbox) : 0;
    if (mid == 0) {
      build(0, n, box, cbox, nodes, 0);
      return;
    }
    nodes.emplace_back();
    set_box(nodes[0], box);
    BuildNodes right;
    auto build_right = [&] {
      right.reserve(2 * (n - mid) / kLeafSize + 1);
      build(mid, n, child_box[1], child_cbox[1], right, 1);
    };
    if (thread_count() < 2) {  // the same tree, one subtree after the other
      build(0, mid, child_box[0], child_cbox[0], nodes, 1);
      build_right();
    } else {
      std::exception_ptr failure;
      std::thread other([&] {
        try {
          build_right();
        } catch (...) {
          failure = std::current_exception();
        }
      });
      try {
        build(0, mid, child_box[0], child_cbox[0], nodes, 1);
      } catch (...) {
        other.join();
        throw;
      }
      other.join();
      if (failure) std::rethrow_exception(failure);
    }
    Index offset = static_cast<Index>(nodes.size());
    nodes[0].index = offset;
    nodes[0].count = 0;
    for (BuildNode& node : right) {
      if (node.count == 0) node.index += offset;
      nodes.push_back(node);
    }
  }
};

inline double box_distance_sq(const float lo[3], const float hi[3], const Vec3d& p) {
  double d = 0;
  for (int k = 0; k < 3; ++k) {
    double e = std::max({double(lo[k]) - p[k], p[k] - double(hi[k]), 0.0});
    d += e * e;
  }
  return d;
}

}  // namespace

TriangleTree::TriangleTree(const Mesh& mesh) {
  Array<Triangle> tris;
  tris.reserve(mesh.n_faces() + mesh.n_faces() / 4);
  faces_.reserve(tris.capacity());
  for (Face f : mesh.faces()) {
    Halfedge h0 = mesh.halfedge(f);
    const Point& a = mesh.position(mesh.to_vertex(h0));
    for (Halfedge h = mesh.next(h0); mesh.next(h) != h0; h = mesh.next(h)) {
      tris.push_back({a, mesh.position(mesh.to_vertex(h)), mesh.position(mesh.to_vertex(mesh.next(h)))});
      faces_.push_back(f);
    }
  }
  Array<Index> original(tris.size());
  for (std::size_t i = 0; i < original.size(); ++i) original[i] = static_cast<Index>(i);
  build(std::move(tris), std::move(original));
}

TriangleTree::TriangleTree(std::span<const Point> positions, std::span<const std::array<Index, 3>> triangles) {
  Array<Triangle> tris;
  tris.reserve(triangles.size());
  for (std::size_t i = 0; i < triangles.size(); ++i) {
    const auto& t = triangles[i];
    for (Index v : t)
      if (v >= positions.size())
        throw Error("triangle " + std::to_string(i) + " uses vertex " + std::to_string(v) + " but there are only " +
                    std::to_string(positions.size()) + " positions");
    tris.push_back({positions[t[0]], positions[t[1]], positions[t[2]]});
  }
  Array<Index> original(tris.size());
  for (std::size_t i = 0; i < original.size(); ++i) original[i] = static_cast<Index>(i);
  build(std::move(tris), std::move(original));
}

void TriangleTree::build(Array<Triangle> tris, Array<Index> original) {
  static_assert(sizeof(Node) == sizeof(BuildNode));
  const std::size_t n = tris.size();
  if (n >= kInvalidIndex / 2) throw Error("too many triangles for the distance tree");
  Refs refs(n);
  parallel_for(n, 0, [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
      const Triangle& t = tris[i];
      Ref& r = refs[i];
      r.box = Box();
      for (const Point* p : {&t.a, &t.b, &t.c}) r.box.add((*p)[0], (*p)[1], (*p)[2]);
      for (int k = 0; k < 3; ++k) r.c[k] = (t.a[k] + t.b[k] + t.c[k]) / 3.0f;
      r.id = static_cast<Index>(i);
    }
  });
  Box box, cbox;
  for (const Ref& r : refs) {
    box.add(r.box);
    cbox.add(r.c[0], r.c[1], r.c[2]);
  }

  BuildNodes nodes;
  if (n > 0) {
    nodes.reserve(2 * n / kLeafSize + 1);
    Builder{refs}.build_parallel(static_cast<Index>(n), box, cbox, nodes);
  }
  nodes_.resize(nodes.size());
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    const BuildNode& b = nodes[i];
    Node& node = nodes_[i];
    for (int k = 0; k < 3; ++k) node.lo[k] = b.lo[k], node.hi[k] = b.hi[k];
    node.index = b.index;
    node.count = b.count;
  }

  // Store the triangles in leaf order so a leaf reads one contiguous block.
  triangles_.resize(n);
  original_.resize(n);
  position_.resize(n);
  parallel_for(n, 0, [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
      const Index from = refs[i].id;
      triangles_[i] = tris[from];
      original_[i] = original[from];
      position_[original_[i]] = static_cast<Index>(i);  // `original` is a permutation: no two write one place
    }
  });
}

std::array<Vec3d, 3> TriangleTree::corners(Index triangle) const {
  const Triangle& t = triangles_[position_[triangle]];
  return {to_double(t.a), to_double(t.b), to_double(t.c)};
}

Vec3d TriangleTree::box_min() const {
  if (nodes_.empty()) return {};
  return {{nodes_[0].lo[0], nodes_[0].lo[1], nodes_[0].lo[2]}};
}

Vec3d TriangleTree::box_max() const {
  if (nodes_.empty()) return {};
  return {{nodes_[0].hi[0], nodes_[0].hi[1], nodes_[0].hi[2]}};
}

void TriangleTree::search(const Vec3d& p, ClosestPoint& best, double& best_sq, const Vec3d* facing) const {
  if (nodes_.empty()) return;
  struct Entry {
    Index node;
    double dist_sq;
  };
  Entry stack[128];
  int top = 0;
  stack[top++] = {0, box_distance_sq(nodes_[0].lo, nodes_[0].hi, p)};
  while (top > 0) {
    Entry e = stack[--top];
    if (e.dist_sq >= best_sq) continue;
    Index id = e.node;
    for (;;) {
      const Node& node = nodes_[id];
      if (node.count) {
        for (Index i = node.index, end = node.index + node.count; i < end; ++i) {
          const Triangle& t = triangles_[i];
          if (facing && !(dot(cross(to_double(t.b) - to_double(t.a), to_double(t.c) - to_double(t.a)), *facing) > 0))
            continue;
          ClosestPoint c = closest_point_on_triangle(p, to_double(t.a), to_double(t.b), to_double(t.c));
          double d_sq = c.distance * c.distance;
          if (d_sq < best_sq) {
            best_sq = d_sq;
            best = c;
            best.triangle = original_[i];
          }
        }
        break;
      }
      // Descend into the nearer child first; keep the other for later if it may still win.
      Index first = id + 1, second = node.index;
      double d_first = box_distance_sq(nodes_[first].lo, nodes_[first].hi, p);
      double d_second = box_distance_sq(nodes_[second].lo, nodes_[second].hi, p);
      if (d_second < d_first) {
        std::swap(first, second);
        std::swap(d_first, d_second);
      }
      if (d_second < best_sq && top < 128) stack[top++] = {second, d_second};
      if (d_first >= best_sq) break;
      id = first;
    }
  }
}

ClosestPoint TriangleTree::closest_point(const Vec3d& p, double max_distance) const {
  ClosestPoint best;
  double best_sq = max_distance * max_distance;
  if (std::isinf(max_distance)) best_sq = std::numeric_limits<double>::infinity();
  search(p, best, best_sq);
  return best;
}

ClosestPoint TriangleTree::closest_point_facing(const Vec3d& p, const Vec3d& direction, double max_distance) const {
  ClosestPoint best;
  double best_sq = max_distance * max_distance;
  if (std::isinf(max_distance)) best_sq = std::numeric_limits<double>::infinity();
  search(p, best, best_sq, &direction);
  return best;
}

ClosestPoint TriangleTree::closest_point_with_hint(const Vec3d& p, Index hint) const {
  if (hint >= triangles_.size()) return closest_point(p);
  const Triangle& t = triangles_[position_[hint]];
  ClosestPoint best = closest_point_on_triangle(p, to_double(t.a), to_double(t.b), to_double(t.c));
  best.triangle = hint;
  // Search strictly closer than the hint; the hint stands when nothing beats it.
  double best_sq = best.distance * best.distance;
  search(p, best, best_sq);
  return best;
}

std::size_t TriangleTree::heap_bytes() const {
  return nodes_.capacity() * sizeof(Node) + triangles_.capacity() * sizeof(Triangle) +
         (original_.capacity() + position_.capacity()) * sizeof(Index) + faces_.capacity() * sizeof(Face);
}

// ---- Hausdorff sampling -------------------------------------------------------------------

namespace {

std::uint64_t splitmix64(std::uint64_t x) {
  x += 0x9e3779b97f4a7c15ull;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}

// A small generator seeded per face, so samples do not depend on which thread runs which
// block.
struct Random {
  std::uint64_t state;
  double uniform() {
    state = splitmix64(state);
    return double(state >> 11) * 0x1.0p-53;
  }
};

// Partial result of one block of samples; blocks are reduced in order (deterministic sums).
struct Partial {
  double max = -1;
  Vec3d worst{};
  double sum_all = 0, sum_sq_all = 0;
  std::size_t count_all = 0;
  double sum_area = 0, sum_sq_area = 0;
  std::size_t count_area = 0;
};

enum class Kind { vertices, edges, faces };

struct Sampler {
  const Mesh& from;
  const TriangleTree& to;
  const HausdorffOptions& options;
  double density = 0;  // face samples per unit area

  void measure(const Vec3d& p, bool area_sample, Index& hint, Partial& r) const {
    ClosestPoint c = to.closest_point_with_hint(p, hint);
    hint = c.triangle;
    double d = c.distance;
    if (d > r.max) {
      r.max = d;
      r.worst = p;
    }
    r.sum_all += d;
    r.sum_sq_all += d * d;
    ++r.count_all;
    if (area_sample) {
      r.sum_area += d;
      r.sum_sq_area += d * d;
      ++r.count_area;
    }
  }

  void sample_triangle(const Vec3d& a, const Vec3d& b, const Vec3d& c, Random& rng, Index& hint, Partial& r) const {
    double area = 0.5 * norm(cross(b - a, c - a));
    double expected = area * density;
    auto n = static_cast<std::size_t>(std::floor(expected + rng.uniform()));
    if (n == 0) return;
    auto point_in = [&](const Vec3d& p0, const Vec3d& p1, const Vec3d& p2) {
      double s = std::sqrt(rng.uniform()), t = rng.uniform();
      return p0 * (1 - s) + p1 * (s * (1 - t)) + p2 * (s * t);
    };
    // Stratified: one point in each of the k*k triangles of the regular k-subdivision,
    // the rest anywhere.
    auto k = static_cast<std::size_t>(std::sqrt(double(n)));
    if (k >= 2) {
      auto grid = [&](double i, double j) {
        double u = i / double(k), v = j / double(k);
        return a * (1 - u - v) + b * u + c * v;
      };
      for (std::size_t i = 0; i < k; ++i)
        for (std::size_t j = 0; i + j < k; ++j) {
          measure(point_in(grid(double(i), double(j)), grid(double(i + 1), double(j)), grid(double(i), double(j + 1))),
                  true, hint, r);
          if (i + j + 1 < k)
            measure(point_in(grid(double(i + 1), double(j)), grid(double(i + 1), double(j + 1)),
                             grid(double(i), double(j + 1))),
                    true, hint, r);
        }
      n -= k * k;
    }
    for (std::size_t s = 0; s < n; ++s) measure(point_in(a, b, c), true, hint, r);
  }

  void run_block(Kind kind, std::size_t begin, std::size_t end, Partial& r) const {
    Index hint = kInvalidIndex;
    switch (kind) {
      case Kind::vertices:
        for (std::size_t i = begin; i < end; ++i) {
          Vertex v(static_cast<Index>(i));
          if (from.is_deleted(v) || from.is_isolated(v)) continue;
          measure(to_double(from.position(v)), false, hint, r);
        }
        break;
      case Kind::edges:
        for (std::size_t i = begin; i < end; ++i) {
          Edge e(static_cast<Index>(i));
          if (from.is_deleted(e)) continue;
          Vec3d p = (to_double(from.position(from.vertex(e, 0))) + to_double(from.position(from.vertex(e, 1)))) * 0.5;
          measure(p, false, hint, r);
        }
        break;
      case Kind::faces:
        for (std::size_t i = begin; i < end; ++i) {
          Face f(static_cast<Index>(i));
          if (from.is_deleted(f)) continue;
          Random rng{splitmix64(options.seed * 0x2545f4914f6cdd1dull + i)};
          Halfedge h0 = from.halfedge(f);
          Vec3d a = to_double(from.position(from.to_vertex(h0)));
          for (Halfedge h = from.next(h0); from.next(h) != h0; h = from.next(h))
            sample_triangle(a, to_double(from.position(from.to_vertex(h))),
                            to_double(from.position(from.to_vertex(from.next(h)))), rng, hint, r);
        }
        break;
    }
  }
};

double surface_area(const Mesh& mesh) {
  double area = 0;
  for (Face f : mesh.faces()) {
    Halfedge h0 = mesh.halfedge(f);
    Vec3d a = to_double(mesh.position(mesh.to_vertex(h0)));
    for (Halfedge h = mesh.next(h0); mesh.next(h) != h0; h = mesh.next(h))
      area += 0.5 * norm(cross(to_double(mesh.position(mesh.to_vertex(h))) - a,
                               to_double(mesh.position(mesh.to_vertex(mesh.next(h)))) - a));
  }
  return area;
}

}  // namespace

OneSidedDistance one_sided_distance(const Mesh& from, const TriangleTree& to, const HausdorffOptions& options) {
  if (to.empty()) throw Error("distance: the surface to measure against has no faces");
  Sampler sampler{from, to, options};
  double area = surface_area(from);
  if (area > 0 && options.sample_density > 0) sampler.density = options.sample_density * double(from.n_faces()) / area;

  struct Block {
    Kind kind;
    std::size_t begin, end;
  };
  std::vector<Block> blocks;
  constexpr std::size_t kBlock = 2048;
  auto add_blocks = [&](Kind kind, std::size_t n) {
    for (std::size_t b = 0; b < n; b += kBlock) blocks.push_back({kind, b, std::min(n, b + kBlock)});
  };
  if (options.sample_vertices) add_blocks(Kind::vertices, from.vertices_size());
  if (options.sample_edge_midpoints) add_blocks(Kind::edges, from.edges_size());
  if (sampler.density > 0) add_blocks(Kind::faces, from.faces_size());

  std::vector<Partial> partials(blocks.size());
  std::atomic<std::size_t> next{0};
  auto work = [&] {
    for (std::size_t b; (b = next.fetch_add(1)) < blocks.size();)
      sampler.run_block(blocks[b].kind, blocks[b].begin, blocks[b].end, partials[b]);
  };
  unsigned threads =
      std::max(1u, std::min(resolve_thread_count(options.threads), static_cast<unsigned>(blocks.size())));
  std::vector<std::thread> pool;
  for (unsigned t = 1; t < threads; ++t) pool.emplace_back(work);
  work();
  for (auto& t : pool) t.join();

  Partial total;
  for (const Partial& p : partials) {
    if (p.max > total.max) {
      total.max = p.max;
      total.worst = p.worst;
    }
    total.sum_all += p.sum_all;
    total.sum_sq_all += p.sum_sq_all;
    total.count_all += p.count_all;
    total.sum_area += p.sum_area;
    total.sum_sq_area += p.sum_sq_area;
    total.count_area += p.count_area;
  }
  OneSidedDistance r;
  r.samples = total.count_all;
  if (total.count_all == 0) return r;
  r.max = total.max;
  r.worst_sample = total.worst;
  double n = double(total.count_area ? total.count_area : total.count_all);
  double sum = total.count_area ? total.sum_area : total.sum_all;
  double sum_sq = total.count_area ? total.sum_sq_area : total.sum_sq_all;
  r.mean = sum / n;
  r.rms = std::sqrt(sum_sq / n);
  return r;
}

HausdorffResult hausdorff(const Mesh& a, const Mesh& b, const HausdorffOptions& options) {
  if (a.n_faces() == 0 || b.n_faces() == 0) throw Error("Hausdorff distance: both meshes need faces");
  // The two trees are independent: build them side by side.
  TriangleTree tree_a, tree_b;
  if (resolve_thread_count(options.threads) > 1) {
    std::exception_ptr failure;
    std::thread other([&] {
      try {
        tree_b = TriangleTree(b);
      } catch (...) {
        failure = std::current_exception();
      }
    });
    try {
      tree_a = TriangleTree(a);
    } catch (...) {
      other.join();
      throw;
    }
    other.join();
    if (failure) std::rethrow_exception(failure);
  } else {
    tree_a = TriangleTree(a);
    tree_b = TriangleTree(b);
  }
  HausdorffResult r;
  r.a_to_b = one_sided_distance(a, tree_b, options);
  r.b_to_a = one_sided_distance(b, tree_a, options);
  r.max = std::max(r.a_to_b.max, r.b_to_a.max);
  return r;
}

std::size_t flipped_faces(const Mesh& mesh, const TriangleTree& reference) {
  std::size_t flipped = 0;
  std::vector<Vec3d> corners;
  for (Face f : mesh.faces()) {
    corners.clear();
    for (Vertex v : mesh.vertices(f)) corners.push_back(to_double(mesh.position(v)));
    // Newell's normal of the face (any polygon), and a triangle of its corners for the points.
    Vec3d normal{};
    for (std::size_t i = 0; i < corners.size(); ++i) normal += cross(corners[i], corners[(i + 1) % corners.size()]);
    if (corners.size() < 3 || sqrnorm(normal) == 0) continue;
    const Vec3d &a = corners[0], &b = corners[corners.size() / 2], &c = corners.back();
    double longest = 0;
    for (std::size_t i = 0; i < corners.size(); ++i)
      longest = std::max(longest, distance(corners[i], corners[(i + 1) % corners.size()]));
    int against = 0;
    for (const Vec3d& w : {Vec3d{{1.0 / 3, 1.0 / 3, 1.0 / 3}}, Vec3d{{2.0 / 3, 1.0 / 6, 1.0 / 6}},
                           Vec3d{{1.0 / 6, 2.0 / 3, 1.0 / 6}}, Vec3d{{1.0 / 6, 1.0 / 6, 2.0 / 3}}}) {
      const Vec3d p = a * w[0] + b * w[1] + c * w[2];
      const ClosestPoint cp = reference.closest_point(p);
      if (!cp.found()) continue;
      const auto t = reference.corners(cp.triangle);
      if (!(dot(cross(t[1] - t[0], t[2] - t[0]), normal) < 0)) continue;
      // A layer of the reference facing the same way close by (a thin part, two sides of
      // a sheet) makes the nearest triangle ambiguous: not counted.
      if (!reference.closest_point_facing(p, normal, cp.distance + 0.5 * longest).found()) ++against;
    }
    if (against >= 3) ++flipped;
  }
  return flipped;
}

}  // namespace hedge
