// Laplacian smoothing (smooth.h). The one-rings are flattened into arrays once; every step is
// then a gather from one position buffer into the other (Jacobi), split across two threads.
#include "hedge/smooth.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <exception>
#include <numbers>
#include <thread>
#include <vector>

#include "binding.h"
#include "hedge/error.h"
#include "hedge/normals.h"
#include "parallel.h"
#include "selection.h"

namespace hedge {
namespace {

// Smoothing steps are short per element: threads pay off from smaller ranges than elsewhere.
constexpr std::size_t kSmoothGrain = 16384;

//! The neighbours each vertex is smoothed toward, with the edge that joins them (for the
//! cotangent weights). Fixed vertices have none.
struct Rings {
  std::vector<Index> offset;  // vertices_size() + 1
  std::vector<Index> neighbour;
  std::vector<Index> edge;
  std::vector<char> curve;  // boundary vertex smoothed along its boundary curve (uniform 1D rule)
};

// `selected`: per vertex, empty for all; unselected vertices get no ring and stay.
Rings make_rings(const Mesh& m, bool preserve_boundary, const std::vector<std::uint8_t>& selected) {
  const std::size_t V = m.vertices_size();
  Rings r;
  r.offset.assign(V + 1, 0);
  r.curve.assign(V, 0);
  r.neighbour.reserve(m.n_halfedges());
  r.edge.reserve(m.n_halfedges());
  for (Index i = 0; i < V; ++i) {
    const Vertex v(i);
    r.offset[i] = Index(r.neighbour.size());
    if (m.is_deleted(v) || m.is_isolated(v) || (!selected.empty() && !selected[i])) continue;
    const Halfedge out = m.halfedge(v);
    if (m.is_boundary(out)) {
      if (preserve_boundary) continue;
      // Along the boundary curve only: moving toward interior neighbours would pull the
      // boundary inward across the hole.
      const Halfedge in = m.prev(out);
      r.neighbour.push_back(m.to_vertex(out).idx());
      r.edge.push_back(Mesh::edge(out).idx());
      r.neighbour.push_back(m.from_vertex(in).idx());
      r.edge.push_back(Mesh::edge(in).idx());
      r.curve[i] = 1;
      continue;
    }
    for (Halfedge h : m.outgoing(v)) {
      r.neighbour.push_back(m.to_vertex(h).idx());
      r.edge.push_back(Mesh::edge(h).idx());
    }
  }
  r.offset[V] = Index(r.neighbour.size());
  return r;
}

constexpr double kMaxCot = 19.081136687728211;  // cot(3°): bounds the weight of needle triangles

double clamped_cot(const Vec3d& u, const Vec3d& v) {
  const double c = dot(u, v), s = norm(cross(u, v));
  if (s <= 0) return c > 0 ? kMaxCot : (c < 0 ? -kMaxCot : 0.0);
  return std::clamp(c / s, -kMaxCot, kMaxCot);
}

//! Per-edge cotangent weights (cot α + cot β) / 2 of the current shape, clamped at 0 from
//! below. Polygons see the edge from their centroid.
void cotangent_weights(const Mesh& m, const std::vector<Vec3d>& p, const std::vector<Vec3d>& centroid,
                       std::vector<double>& weight, unsigned threads) {
  parallel_for(
      m.edges_size(), threads,
      [&](std::size_t lo, std::size_t hi) {
        for (Index e = Index(lo); e < hi; ++e) {
          if (m.is_deleted(Edge(e))) continue;
          double w = 0;
          for (unsigned side = 0; side < 2; ++side) {
            const Halfedge h = Mesh::halfedge(Edge(e), side);
            const Face f = m.face(h);
            if (!f.is_valid()) continue;
            const Halfedge n = m.next(h);
            const bool triangle = m.next(m.next(n)) == h;
            const Vec3d& apex = triangle ? p[m.to_vertex(n).idx()] : centroid[f.idx()];
            w += 0.5 * clamped_cot(p[m.from_vertex(h).idx()] - apex, p[m.to_vertex(h).idx()] - apex);
          }
          weight[e] = std::max(0.0, w);
        }
      },
      kSmoothGrain);
}

}  // namespace

const char* smoothing_method_name(SmoothingMethod method) {
  switch (method) {
    case SmoothingMethod::uniform:
      return "uniform";
    case SmoothingMethod::cotangent:
      return "cotangent";
    case SmoothingMethod::taubin:
      return "taubin";
  }
  return "unknown";
}

SmoothReport smooth(Mesh& mesh, const SmoothOptions& options, Progress& progress) {
  if (options.iterations < 1) throw Error("smooth: iterations must be 1 or more");
  if (!(options.strength > 0 && options.strength <= 1))
    throw Error("smooth: strength must be greater than 0 and at most 1, got " + std::to_string(options.strength));
  if (!(options.pass_band > 0 && options.pass_band < 1))
    throw Error("smooth: the pass band must lie between 0 and 1, got " + std::to_string(options.pass_band));

  SmoothReport report;
  report.iterations = options.iterations;
  double lambda = options.strength, mu = 0;
  if (options.method == SmoothingMethod::taubin) {
    // The filter (1 - λk)(1 - μk) must stay within [-1, 1] up to k = 2, the largest
    // eigenvalue a normalized Laplacian can have: that holds for λ up to about 0.69.
    constexpr double kTaubinMaxLambda = 0.68;
    if (lambda > kTaubinMaxLambda) {
      report.message = "taubin: strength " + std::to_string(lambda) + " limited to " +
                       std::to_string(kTaubinMaxLambda) + " to keep the μ step stable";
      lambda = kTaubinMaxLambda;
    }
    mu = -lambda / (1.0 - options.pass_band * lambda);
  }
  report.lambda = lambda;
  report.mu = mu;

  const Rings rings =
      make_rings(mesh, options.preserve_boundary,
                 options.selection_only ? detail::selected_vertices(mesh) : std::vector<std::uint8_t>());
  const std::size_t V = mesh.vertices_size();
  for (Index v = 0; v < V; ++v) report.moved_vertices += rings.offset[v + 1] > rings.offset[v];

  // Double buffer in double precision; the mesh is written once at the end, so an error or
  // a cancellation leaves it untouched.
  std::vector<Vec3d> current(V), next(V);
  for (Index v = 0; v < V; ++v) current[v] = to_double(mesh.positions()[v]);
  const std::vector<Vec3d> original = current;
  std::vector<double> weight;
  std::vector<Vec3d> centroid;
  bool has_polygons = false;
  if (options.method == SmoothingMethod::cotangent) {
    weight.assign(mesh.edges_size(), 0.0);
    for (Face f : mesh.faces())
      if (mesh.valence(f) != 3) has_polygons = true;
    if (has_polygons) centroid.assign(mesh.faces_size(), Vec3d{});
  }

  auto step = [&](double amount, bool weighted) {
    parallel_for(
        V, options.threads,
        [&](std::size_t lo, std::size_t hi) {
          for (std::size_t v = lo; v < hi; ++v) {
            const Index b = rings.offset[v], e = rings.offset[v + 1];
            if (b == e) {
              next[v] = current[v];
              continue;
            }
            Vec3d sum{};
            double total = 0;
            if (weighted && !rings.curve[v]) {
              for (Index k = b; k < e; ++k) {
                const double w = weight[rings.edge[k]];
                sum += current[rings.neighbour[k]] * w;
                total += w;
              }
            }
            if (total <= 0) {  // uniform, or all cotangent weights vanished
              sum = Vec3d{};
              for (Index k = b; k < e; ++k) sum += current[rings.neighbour[k]];
              total = double(e - b);
            }
            next[v] = current[v] + (sum / total - current[v]) * amount;
          }
        },
        kSmoothGrain);
    current.swap(next);
  };

  for (int it = 0; it < options.iterations; ++it) {
    progress.update(double(it) / options.iterations, "smoothing");
    switch (options.method) {
      case SmoothingMethod::uniform:
        step(lambda, false);
        break;
      case SmoothingMethod::cotangent:
        if (has_polygons)
          for (Face f : mesh.faces()) {
            Vec3d c{};
            double n = 0;
            for (Vertex x : mesh.vertices(f)) {
              c += current[x.idx()];
              n += 1;
            }
            centroid[f.idx()] = c / n;
          }
        cotangent_weights(mesh, current, centroid, weight, options.threads);
        step(lambda, true);
        break;
      case SmoothingMethod::taubin:
        step(lambda, false);
        step(mu, false);
        break;
    }
  }

  double sum = 0, count = 0;
  for (Index v = 0; v < V; ++v) {
    if (mesh.is_deleted(Vertex(v))) continue;
    const double d = distance(current[v], original[v]);
    sum += d;
    count += 1;
    report.max_displacement = std::max(report.max_displacement, d);
  }
  report.mean_displacement = count ? sum / count : 0;
  for (Index v = 0; v < V; ++v) mesh.positions()[v] = to_float(current[v]);
  refresh_normal_channels(mesh, true, true);
  return report;
}

Operation smooth_operation() {
  const char* help =
      "Removes noise by moving every vertex toward a weighted mean of its neighbours, all vertices at once, "
      "repeated. Methods: uniform (the umbrella operator: simple and fast, but the shape shrinks and triangles "
      "slide along the surface), cotangent (Desbrun et al. 1999: cotangent weights, clamped and normalized, so "
      "vertices move across the surface rather than along it), taubin (Taubin 1995: a shrinking λ step followed "
      "by an inflating μ step, μ = -λ / (1 - k_PB λ) with k_PB the pass band (0.1 by default); smooths noise while "
      "keeping the volume; strengths above "
      "0.68 are limited to keep it stable). Strength is λ, the fraction of the way to the mean per step. With "
      "preserve_boundary, boundary vertices stay fixed; otherwise they are smoothed along their boundary curve. "
      "Only positions change: the connectivity and every attribute are kept, except vertex and face normals, which "
      "are recomputed from the new shape.";
  using O = SmoothOptions;
  using R = SmoothReport;
  auto run = [](Mesh& mesh, const O& options, Progress& progress) {
    if (options.strength > 0) return smooth(mesh, options, progress);
    R nothing;
    nothing.message = "strength 0: nothing to do";
    return nothing;
  };
  return Binding<O, R>("smooth", "Smooth", Category::smoothing, help, run)
      .choice(&O::method, "method", "Method",
              {SmoothingMethod::uniform, SmoothingMethod::cotangent, SmoothingMethod::taubin}, smoothing_method_name,
              "uniform is fastest but shrinks; cotangent follows the surface; taubin keeps the volume")
      .option(&O::iterations, "iterations", "Iterations", between(1, 1000), "number of smoothing steps")
      .option(&O::strength, "strength", "Strength", between(0, 1),
              "λ: how far each step moves a vertex toward the mean (0 to 1)")
      .option(&O::preserve_boundary, "preserve_boundary", "Preserve boundary",
              "keep boundary vertices fixed (otherwise smooth them along the boundary)")
      .selection(&O::selection_only,
                 "only the selected vertices move (those inside the selected faces when the host "
                 "selects faces only)")
      .option(&O::pass_band, "pass_band", "Pass band", between(0.01, 0.5),
              "taubin only: k_PB, the frequency below which shapes pass unchanged (μ = -λ / (1 - k_PB λ))")
      .result("method",
              [](const O& o, const R&) -> std::optional<Value> { return std::string(smoothing_method_name(o.method)); })
      .result(&R::iterations, "iterations")
      .result(&R::moved_vertices, "moved_vertices")
      .result(&R::lambda, "lambda")
      .result("mu",
              [](const O& o, const R& r) -> std::optional<Value> {
                if (o.method != SmoothingMethod::taubin) return std::nullopt;
                return r.mu;
              })
      .result(&R::mean_displacement, "mean_displacement")
      .result(&R::max_displacement, "max_displacement")
      .messages([](const O&, const R& r) {
        return r.message.empty() ? std::vector<std::string>{} : std::vector<std::string>{r.message};
      });
}

}  // namespace hedge
