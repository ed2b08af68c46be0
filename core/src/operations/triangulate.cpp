// Triangulating polygons (triangulate.h). Each polygon is projected to the plane of its Newell
// normal and cut one ear at a time with Mesh::insert_edge, which walks only the ear: O(1) per
// triangle, so a face of 100,000 corners takes milliseconds.
#include "hedge/triangulate.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <optional>
#include <string>
#include <unordered_map>
#include <unordered_set>
#include <utility>
#include <vector>

#include "binding.h"
#include "hedge/error.h"
#include "selection.h"

namespace hedge {
namespace {

using Vec2d = Vec<double, 2>;

//! Twice the signed area of triangle a, b, c: positive when counter-clockwise.
double orient(const Vec2d& a, const Vec2d& b, const Vec2d& c) {
  return (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
}

//! Reflex corners in a 2D tree of boxes (median splits), queried with a triangle: subtrees
//! whose box lies outside one of the triangle's edges are skipped. Unlike a grid, a long thin
//! ear (fans toward a far corner are common) only visits the corners near its border.
//! Entries are never removed: callers skip corners that became convex or were cut off.
class ReflexTree {
 public:
  ReflexTree(const std::vector<Vec2d>& q, std::vector<std::size_t> corners) : q_(q), items_(std::move(corners)) {
    if (!items_.empty()) build(0, items_.size());
  }

  //! Calls visit(corner) for corners in boxes that touch triangle a, b, c (counter-clockwise);
  //! returns true as soon as visit does.
  template <class Visit>
  bool any_near(const Vec2d& a, const Vec2d& b, const Vec2d& c, Visit visit) const {
    if (nodes_.empty()) return false;
    const Vec2d lo{{std::min({a[0], b[0], c[0]}), std::min({a[1], b[1], c[1]})}};
    const Vec2d hi{{std::max({a[0], b[0], c[0]}), std::max({a[1], b[1], c[1]})}};
    std::size_t stack[64];
    std::size_t top = 0;
    stack[top++] = 0;
    while (top) {
      const Node& n = nodes_[stack[--top]];
      if (n.hi[0] < lo[0] || n.hi[1] < lo[1] || n.lo[0] > hi[0] || n.lo[1] > hi[1]) continue;
      if (outside(n, a, b) || outside(n, b, c) || outside(n, c, a)) continue;
      if (n.left == 0) {
        for (std::size_t k = n.begin; k < n.end; ++k)
          if (visit(items_[k])) return true;
      } else {
        stack[top++] = n.left;
        stack[top++] = n.left + 1;
      }
    }
    return false;
  }

 private:
  struct Node {
    Vec2d lo, hi;
    std::size_t begin = 0, end = 0, left = 0;  // children at left and left + 1; 0 for a leaf
  };

  // All four corners of the box strictly to the right of p -> q (outside a CCW triangle).
  static bool outside(const Node& n, const Vec2d& p, const Vec2d& q) {
    return orient(p, q, n.lo) < 0 && orient(p, q, n.hi) < 0 && orient(p, q, Vec2d{{n.lo[0], n.hi[1]}}) < 0 &&
           orient(p, q, Vec2d{{n.hi[0], n.lo[1]}}) < 0;
  }

  void build(std::size_t begin, std::size_t end) {
    // Breadth-first, children stored in pairs; a median split keeps the depth at log2(n / 8).
    nodes_.push_back(Node{});
    std::vector<std::size_t> todo = {0};
    nodes_[0].begin = begin;
    nodes_[0].end = end;
    while (!todo.empty()) {
      const std::size_t id = todo.back();
      todo.pop_back();
      Node n = nodes_[id];
      n.lo = n.hi = q_[items_[n.begin]];
      for (std::size_t k = n.begin; k < n.end; ++k)
        for (int d = 0; d < 2; ++d) {
          n.lo[d] = std::min(n.lo[d], q_[items_[k]][d]);
          n.hi[d] = std::max(n.hi[d], q_[items_[k]][d]);
        }
      if (n.end - n.begin > 8) {
        const int axis = n.hi[0] - n.lo[0] >= n.hi[1] - n.lo[1] ? 0 : 1;
        const std::size_t mid = n.begin + (n.end - n.begin) / 2;
        std::nth_element(items_.begin() + std::ptrdiff_t(n.begin), items_.begin() + std::ptrdiff_t(mid),
                         items_.begin() + std::ptrdiff_t(n.end),
                         [&](std::size_t x, std::size_t y) { return q_[x][axis] < q_[y][axis]; });
        n.left = nodes_.size();
        Node l, r;
        l.begin = n.begin;
        l.end = mid;
        r.begin = mid;
        r.end = n.end;
        nodes_.push_back(l);
        nodes_.push_back(r);
        todo.push_back(n.left);
        todo.push_back(n.left + 1);
      }
      nodes_[id] = n;
    }
  }

  const std::vector<Vec2d>& q_;
  std::vector<std::size_t> items_;
  std::vector<Node> nodes_;
};

//! One polygon being cut into triangles: its corners as a ring, the half-edge that points to
//! each corner inside the face that remains (the polygon keeps its face; each ear becomes a
//! new one), and the corners projected to the polygon's plane.
class Cutter {
 public:
  Cutter(Mesh& mesh, Face f) : m_(mesh), face_(f) {
    for (Halfedge h : m_.halfedges(f)) {
      in_.push_back(h);
      v_.push_back(m_.to_vertex(h));
      p_.push_back(to_double(m_.position(v_.back())));
    }
    n_ = in_.size();
    remaining_ = n_;
    next_.resize(n_);
    prev_.resize(n_);
    removed_.assign(n_, 0);
    for (std::size_t i = 0; i < n_; ++i) {
      next_[i] = i + 1 == n_ ? 0 : i + 1;
      prev_[i] = i == 0 ? n_ - 1 : i - 1;
    }
    project();
  }

  std::size_t size() const { return n_; }
  std::size_t added() const { return added_; }

  //! The least-area triangulation by dynamic programming over the diagonals; `strict` asks
  //! for counter-clockwise triangles in the plane. False when none exists.
  bool min_area(bool strict, std::vector<std::array<std::size_t, 3>>& triangles) {
    const std::size_t n = n_;
    constexpr double inf = std::numeric_limits<double>::infinity();
    std::vector<double> area(n * n, inf), worst(n * n, inf);
    std::vector<std::size_t> choice(n * n, 0);
    std::vector<char> joined(n * n, 0);  // the diagonal exists as an edge already
    mark_existing_diagonals(joined);
    auto at = [n](std::size_t i, std::size_t j) { return i * n + j; };
    for (std::size_t i = 0; i + 1 < n; ++i) {
      area[at(i, i + 1)] = 0;
      worst[at(i, i + 1)] = -inf;
    }
    const double area_tolerance = 1e-9 * newell_area_ + 1e-300;
    for (std::size_t len = 2; len < n; ++len)
      for (std::size_t i = 0; i + len < n; ++i) {
        const std::size_t j = i + len;
        if (!(i == 0 && j == n - 1) && joined[at(i, j)]) continue;
        double best_area = inf, best_worst = inf;
        std::size_t best_k = 0;
        for (std::size_t k = i + 1; k < j; ++k) {
          const double a_ik = area[at(i, k)], a_kj = area[at(k, j)];
          if (a_ik == inf || a_kj == inf) continue;
          if (strict && orient(q_[i], q_[k], q_[j]) <= tolerance_) continue;
          const double a = a_ik + a_kj + triangle_area(i, k, j);
          const double w = std::max({worst[at(i, k)], worst[at(k, j)], -triangle_quality(i, k, j)});
          if (a < best_area - area_tolerance || (a <= best_area + area_tolerance && w < best_worst)) {
            best_area = a;
            best_worst = w;
            best_k = k;
          }
        }
        area[at(i, j)] = best_area;
        worst[at(i, j)] = best_worst;
        choice[at(i, j)] = best_k;
      }
    if (area[at(0, n - 1)] == inf) return false;
    triangles.clear();
    std::vector<std::pair<std::size_t, std::size_t>> todo = {{0, n - 1}};
    while (!todo.empty()) {
      auto [i, j] = todo.back();
      todo.pop_back();
      if (j < i + 2) continue;
      const std::size_t k = choice[at(i, j)];
      triangles.push_back({i, k, j});
      todo.push_back({i, k});
      todo.push_back({k, j});
    }
    return true;
  }

  //! Cuts the polygon along a given triangulation, one ear at a time.
  void apply(const std::vector<std::array<std::size_t, 3>>& triangles) {
    std::vector<char> used(triangles.size(), 0);
    while (remaining_ > 3) {
      bool cut = false;
      for (std::size_t t = 0; t < triangles.size() && !cut; ++t) {
        if (used[t]) continue;
        const auto& c = triangles[t];
        for (int x = 0; x < 3 && !cut; ++x) {
          const std::size_t tip = c[x], a = c[(x + 1) % 3], b = c[(x + 2) % 3];
          if (removed_[tip]) continue;
          if ((prev_[tip] == a && next_[tip] == b) || (prev_[tip] == b && next_[tip] == a)) {
            clip(tip);
            used[t] = 1;
            cut = true;
          }
        }
      }
      if (!cut) throw Error("triangulate: internal error: the triangulation of a polygon has no ear");
    }
  }

  //! Ear clipping; `relaxed` is set when no proper ear was left and the least bad corner was
  //! cut instead. False when no corner can be cut without doubling an existing edge.
  bool ear_clip(bool& relaxed) {
    reflex_.assign(n_, 0);
    std::vector<std::size_t> reflex;
    for (std::size_t i = 0; i < n_; ++i)
      if (orient(q_[prev_[i]], q_[i], q_[next_[i]]) <= tolerance_) {
        reflex_[i] = 1;
        reflex.push_back(i);
      }
    const ReflexTree tree(q_, std::move(reflex));
    std::size_t i = 0, stop = 0;
    while (remaining_ > 3) {
      if (is_ear(i, tree)) {
        const std::size_t a = prev_[i], b = next_[i];
        clip(i);
        refresh(a);
        refresh(b);
        i = stop = b;
        continue;
      }
      i = next_[i];
      if (i != stop) continue;
      // A full turn without an ear (a projection that crosses itself, or ears whose diagonal
      // exists elsewhere): cut the corner that is most convex among those with a free diagonal.
      std::size_t best = n_;
      double best_turn = -std::numeric_limits<double>::infinity();
      std::size_t x = i;
      do {
        const double turn = orient(q_[prev_[x]], q_[x], q_[next_[x]]);
        if (turn > best_turn && !joined(prev_[x], next_[x])) {
          best_turn = turn;
          best = x;
        }
        x = next_[x];
      } while (x != i);
      if (best == n_) return false;
      relaxed = true;
      const std::size_t a = prev_[best], b = next_[best];
      clip(best);
      refresh(a);
      refresh(b);
      i = stop = b;
    }
    return true;
  }

  //! Fans what remains of the polygon around a new vertex at its centroid; the vertex blends
  //! the corners' vertex attributes (split_face blends the corner attributes).
  void split_at_centroid() {
    std::vector<Index> from;
    Vec3d centroid{};
    for (std::size_t x = first_remaining(), k = 0; k < remaining_; ++k, x = next_[x]) {
      from.push_back(v_[x].idx());
      centroid += p_[x];
    }
    centroid /= double(remaining_);
    const Vertex v = m_.add_vertex(to_float(centroid));
    const std::vector<float> weights(from.size(), 1.0f / float(from.size()));
    PropertyContainer& props = m_.vertex_properties();
    for (std::size_t a = 0; a < props.count(); ++a)
      if (!props.at(a).is_internal()) props.at(a).interpolate(v.idx(), from, weights);
    m_.split_face(face_, v);
    added_ += remaining_ - 1;
    remaining_ = 0;
  }

 private:
  void project() {
    // Newell's normal, as a fan from corner 0 (precision far from the origin).
    Vec3d normal{};
    for (std::size_t i = 1; i + 1 < n_; ++i) normal += cross(p_[i] - p_[0], p_[i + 1] - p_[0]);
    newell_area_ = 0.5 * norm(normal);
    Vec3d z = normalize(normal);
    if (newell_area_ == 0) z = Vec3d{{0, 0, 1}};
    // u, w, z right-handed, so the polygon runs counter-clockwise in (u, w).
    int axis = 0;
    for (int k = 1; k < 3; ++k)
      if (std::abs(z[k]) < std::abs(z[axis])) axis = k;
    Vec3d e{};
    e[axis] = 1;
    const Vec3d u = normalize(cross(z, e)), w = cross(z, u);
    q_.resize(n_);
    double extent = 0;
    for (std::size_t i = 0; i < n_; ++i) {
      const Vec3d d = p_[i] - p_[0];
      q_[i] = Vec2d{{dot(d, u), dot(d, w)}};
      extent = std::max({extent, std::abs(q_[i][0]), std::abs(q_[i][1])});
    }
    tolerance_ = 1e-12 * extent * extent;
  }

  double triangle_area(std::size_t a, std::size_t b, std::size_t c) const {
    return 0.5 * norm(cross(p_[b] - p_[a], p_[c] - p_[a]));
  }

  //! 4 sqrt(3) area / (sum of squared edge lengths): 1 for equilateral, 0 for degenerate.
  double triangle_quality(std::size_t a, std::size_t b, std::size_t c) const {
    const double s = sqrnorm(p_[b] - p_[a]) + sqrnorm(p_[c] - p_[b]) + sqrnorm(p_[a] - p_[c]);
    return s > 0 ? 4.0 * std::numbers::sqrt3 * triangle_area(a, b, c) / s : 0.0;
  }

  //! joined[i * n + j]: corners i and j are joined by an edge of the mesh (outside the face).
  void mark_existing_diagonals(std::vector<char>& joined) const {
    std::vector<std::pair<Index, std::size_t>> corner_of;  // (vertex, corner), sorted
    for (std::size_t i = 0; i < n_; ++i) corner_of.emplace_back(v_[i].idx(), i);
    std::sort(corner_of.begin(), corner_of.end());
    for (std::size_t i = 0; i < n_; ++i)
      for (Vertex w : m_.vertices(v_[i])) {
        auto it = std::lower_bound(corner_of.begin(), corner_of.end(), std::make_pair(w.idx(), std::size_t(0)));
        if (it != corner_of.end() && it->first == w.idx())
          joined[i * n_ + it->second] = joined[it->second * n_ + i] = 1;
      }
  }

  //! Corners a and b are joined by an edge: one that existed around the polygon when cutting
  //! began, or a diagonal cut since. Big polygons use a hash set: ear clipping makes fans whose
  //! apex has a huge valence, and walking rings on every ear test would add up.
  bool joined(std::size_t a, std::size_t b) const {
    if (n_ <= 32) return m_.find_halfedge(v_[a], v_[b]).is_valid();  // small polygons: no set to build
    if (!joined_ready_) collect_joined();
    return joined_.contains(pair_key(a, b));
  }

  static std::uint64_t pair_key(std::size_t a, std::size_t b) {
    return std::uint64_t(std::min(a, b)) << 32 | std::uint64_t(std::max(a, b));
  }

  void collect_joined() const {
    std::unordered_map<Index, std::size_t> corner_of;
    corner_of.reserve(n_);
    for (std::size_t i = 0; i < n_; ++i) corner_of.emplace(v_[i].idx(), i);
    for (std::size_t i = 0; i < n_; ++i)
      for (Vertex w : m_.vertices(v_[i]))
        if (auto it = corner_of.find(w.idx()); it != corner_of.end()) joined_.insert(pair_key(i, it->second));
    joined_ready_ = true;
  }

  //! Cuts off the triangle prev(i), i, next(i).
  void clip(std::size_t i) {
    const std::size_t a = prev_[i], b = next_[i];
    in_[b] = m_.insert_edge(in_[a], in_[b]);  // a -> b, in the remaining face
    if (joined_ready_) joined_.insert(pair_key(a, b));
    next_[a] = b;
    prev_[b] = a;
    removed_[i] = 1;
    --remaining_;
    ++added_;
  }

  void refresh(std::size_t x) {
    if (reflex_[x] && orient(q_[prev_[x]], q_[x], q_[next_[x]]) > tolerance_) reflex_[x] = 0;
  }

  bool is_ear(std::size_t i, const ReflexTree& tree) const {
    if (reflex_[i]) return false;
    const std::size_t a = prev_[i], b = next_[i];
    const Vec2d &pa = q_[a], &pi = q_[i], &pb = q_[b];
    if (orient(pa, pi, pb) <= tolerance_) return false;
    // Only a reflex corner can lie inside an ear of a simple polygon; on its border counts.
    const bool blocked = tree.any_near(pa, pi, pb, [&](std::size_t r) {
      if (removed_[r] || !reflex_[r] || r == a || r == i || r == b) return false;
      const Vec2d& pr = q_[r];
      return orient(pa, pi, pr) >= 0 && orient(pi, pb, pr) >= 0 && orient(pb, pa, pr) >= 0;
    });
    return !blocked && !joined(a, b);
  }

  std::size_t first_remaining() const {
    std::size_t x = 0;
    while (removed_[x]) ++x;
    return x;
  }

  Mesh& m_;
  Face face_;
  std::vector<Halfedge> in_;
  std::vector<Vertex> v_;
  std::vector<Vec3d> p_;
  std::vector<Vec2d> q_;
  std::vector<std::size_t> next_, prev_;
  std::vector<char> removed_, reflex_;
  std::size_t n_ = 0, remaining_ = 0, added_ = 0;
  double newell_area_ = 0, tolerance_ = 0;
  mutable std::unordered_set<std::uint64_t> joined_;
  mutable bool joined_ready_ = false;
};

}  // namespace

const char* triangulation_method_name(TriangulationMethod method) {
  switch (method) {
    case TriangulationMethod::min_area:
      return "min_area";
    case TriangulationMethod::ear_clipping:
      return "ear_clipping";
  }
  return "unknown";
}

TriangulateReport triangulate(Mesh& mesh, const TriangulateOptions& options, Progress& progress) {
  TriangulateReport report;
  std::vector<Face> polygons;
  const std::vector<std::uint8_t> selected =
      options.selection_only ? detail::selected_faces(mesh) : std::vector<std::uint8_t>();
  for (Face f : mesh.faces()) {
    const Halfedge h = mesh.halfedge(f);
    if (mesh.next(mesh.next(mesh.next(h))) != h && (selected.empty() || selected[f.idx()])) polygons.push_back(f);
  }
  report.polygons = polygons.size();
  if (polygons.empty()) return report;

  // Cut on a copy: an error or a cancellation leaves the input as it was.
  std::optional<Mesh> copy;
  Mesh& work = options.keep_input_on_failure ? copy.emplace(mesh) : mesh;
  std::vector<std::array<std::size_t, 3>> triangles;
  for (std::size_t k = 0; k < polygons.size(); ++k) {
    if ((k & 1023) == 0) progress.update(double(k) / double(polygons.size()), "triangulating");
    Cutter cutter(work, polygons[k]);
    bool done = false;
    if (options.method == TriangulationMethod::min_area && cutter.size() <= options.max_dp_corners) {
      if (cutter.min_area(true, triangles)) {
        cutter.apply(triangles);
        done = true;
      } else if (cutter.min_area(false, triangles)) {
        cutter.apply(triangles);
        ++report.relaxed;
        done = true;
      }
    } else {
      ++report.ear_clipped;
      bool relaxed = false;
      done = cutter.ear_clip(relaxed);
      report.relaxed += relaxed;
    }
    if (!done) {
      cutter.split_at_centroid();
      ++report.centroid_vertices;
    }
    report.triangles += cutter.added() + 1;  // the polygon's own face is the last triangle
  }
  if (copy) mesh = std::move(*copy);
  return report;
}

Operation triangulate_operation() {
  const char* help =
      "Splits every polygon into triangles, convex or not: each triangle lies inside the polygon and faces the "
      "same way, seen in the polygon's best-fit plane (Newell's normal). Methods: min_area chooses, by dynamic "
      "programming over the diagonals, the triangulation of least total area (for non-planar polygons the "
      "flattest; for planar ones, whose triangulations all have the same area, the one whose worst triangle is "
      "best shaped); polygons above 100 corners are ear-clipped instead, as O(n^3) would be slow. ear_clipping "
      "cuts ears in the polygon's plane, fast even for faces of 100,000 corners. A diagonal that already exists as "
      "an edge elsewhere is never used (the mesh stays manifold); in the rare polygon that cannot be split "
      "otherwise, a vertex is added at its centroid. Attributes: new corners copy the polygon's corner value at "
      "the same vertex (UVs stay per face), new faces copy the polygon's face attributes (materials), vertices "
      "are untouched.";
  using O = TriangulateOptions;
  using R = TriangulateReport;
  return Binding<O, R>("triangulate", "Triangulate", Category::cleaning, help, triangulate)
      .fixed(&O::keep_input_on_failure, false)
      .choice(&O::method, "method", "Method", {TriangulationMethod::min_area, TriangulationMethod::ear_clipping},
              triangulation_method_name,
              "min_area for the best triangles (dynamic programming), ear_clipping for speed")
      .selection(&O::selection_only, "only the selected polygons are split; the others stay as they are")
      .result(
          "method",
          [](const O& o, const R&) -> std::optional<Value> { return std::string(triangulation_method_name(o.method)); })
      .result(&R::polygons, "polygons")
      .result(&R::triangles, "triangles")
      .result(&R::ear_clipped, "ear_clipped")
      .result(&R::relaxed, "relaxed")
      .result(&R::centroid_vertices, "centroid_vertices")
      .messages([](const O&, const R& r) {
        std::vector<std::string> out;
        if (r.relaxed)
          out.push_back(std::to_string(r.relaxed) +
                        " polygons have no triangulation that stays flat in their plane (self-crossing "
                        "or blocked by existing edges); they were split as well as possible");
        if (r.centroid_vertices)
          out.push_back(std::to_string(r.centroid_vertices) +
                        " polygons could not be split without doubling an edge; a vertex was added at "
                        "their centroid");
        return out;
      });
}

}  // namespace hedge
