// The report operation: counts, topology, edge lengths and triangle quality.
#include "hedge/report.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <vector>

namespace hedge {

double triangle_quality(const Vec3d& a, const Vec3d& b, const Vec3d& c) {
  // 2 r_in / r_out = 8 (s - la)(s - lb)(s - lc) / (la lb lc), with s the half perimeter (Heron).
  double la = distance(b, c), lb = distance(a, c), lc = distance(a, b);
  double s = 0.5 * (la + lb + lc);
  double denom = la * lb * lc;
  if (denom <= 0) return 0;
  double q = 8.0 * (s - la) * (s - lb) * (s - lc) / denom;
  return std::clamp(q, 0.0, 1.0);
}

double triangle_min_angle(const Vec3d& a, const Vec3d& b, const Vec3d& c) {
  double m = std::min({angle_at(a, b, c), angle_at(b, c, a), angle_at(c, a, b)});
  return m * 180.0 / std::numbers::pi;
}

MeshStatistics mesh_statistics(const Mesh& mesh) {
  MeshStatistics s;
  s.topology = topology_stats(mesh);

  constexpr double inf = std::numeric_limits<double>::infinity();
  Vec3d lo{{inf, inf, inf}}, hi{{-inf, -inf, -inf}};
  for (Vertex v : mesh.vertices()) {
    Vec3d p = to_double(mesh.position(v));
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], p[k]);
      hi[k] = std::max(hi[k], p[k]);
    }
  }
  if (mesh.n_vertices()) {
    s.bbox_min = lo;
    s.bbox_max = hi;
    s.bbox_diagonal = distance(lo, hi);
  }

  // Edge lengths, and multi-edges found by sorting the vertex pairs.
  double sum = 0, sum2 = 0;
  s.edge_length_min = mesh.n_edges() ? inf : 0;
  std::vector<std::uint64_t> pairs;
  pairs.reserve(mesh.n_edges());
  for (Edge e : mesh.edges()) {
    Vertex a = mesh.vertex(e, 0), b = mesh.vertex(e, 1);
    double l = distance(to_double(mesh.position(a)), to_double(mesh.position(b)));
    s.edge_length_min = std::min(s.edge_length_min, l);
    s.edge_length_max = std::max(s.edge_length_max, l);
    sum += l;
    sum2 += l * l;
    std::uint64_t lo_idx = std::min(a.idx(), b.idx()), hi_idx = std::max(a.idx(), b.idx());
    pairs.push_back(lo_idx << 32 | hi_idx);
  }
  if (mesh.n_edges()) {
    double n = double(mesh.n_edges());
    s.edge_length_mean = sum / n;
    s.edge_length_stddev = std::sqrt(std::max(0.0, sum2 / n - s.edge_length_mean * s.edge_length_mean));
  }
  std::sort(pairs.begin(), pairs.end());
  for (std::size_t i = 1; i < pairs.size(); ++i)
    if (pairs[i] == pairs[i - 1]) ++s.multi_edges;

  // Faces: kinds, area, volume (divergence theorem over a fan), triangle quality.
  const double degenerate_area = 1e-12 * std::max(s.bbox_diagonal * s.bbox_diagonal, 1e-300);
  double quality_sum = 0, min_angle_sum = 0;
  std::size_t triangles = 0;
  s.min_angle_degrees = 180;
  s.quality_min = 1;
  for (Face f : mesh.faces()) {
    std::size_t n = mesh.valence(f);
    if (n == 3)
      ++s.triangles;
    else if (n == 4)
      ++s.quads;
    else
      ++s.polygons;
    Halfedge h0 = mesh.halfedge(f);
    Vec3d p0 = to_double(mesh.position(mesh.to_vertex(h0)));
    Vec3d normal{};
    for (Halfedge h = mesh.next(h0); mesh.next(h) != h0; h = mesh.next(h)) {
      Vec3d p1 = to_double(mesh.position(mesh.to_vertex(h)));
      Vec3d p2 = to_double(mesh.position(mesh.to_vertex(mesh.next(h))));
      normal += cross(p1 - p0, p2 - p0);
      s.volume += dot(p0, cross(p1, p2)) / 6.0;
    }
    double area = 0.5 * norm(normal);
    s.area += area;
    if (area <= degenerate_area) ++s.degenerate_faces;
    if (n == 3) {
      Vec3d p1 = to_double(mesh.position(mesh.to_vertex(mesh.next(h0))));
      Vec3d p2 = to_double(mesh.position(mesh.to_vertex(mesh.prev(h0))));
      double q = triangle_quality(p0, p1, p2), a = triangle_min_angle(p0, p1, p2);
      s.quality_min = std::min(s.quality_min, q);
      s.min_angle_degrees = std::min(s.min_angle_degrees, a);
      quality_sum += q;
      min_angle_sum += a;
      ++triangles;
    }
  }
  if (triangles) {
    s.quality_mean = quality_sum / double(triangles);
    s.mean_min_angle_degrees = min_angle_sum / double(triangles);
  } else {
    s.min_angle_degrees = s.quality_min = 0;
  }

  std::size_t interior = 0, irregular = 0;
  s.valence_min = mesh.n_vertices() ? std::numeric_limits<std::size_t>::max() : 0;
  for (Vertex v : mesh.vertices()) {
    if (mesh.is_isolated(v)) continue;
    std::size_t k = mesh.valence(v);
    s.valence_min = std::min(s.valence_min, k);
    s.valence_max = std::max(s.valence_max, k);
    if (!mesh.is_boundary(v)) {
      ++interior;
      if (k != 6) ++irregular;
    }
  }
  if (s.valence_min == std::numeric_limits<std::size_t>::max()) s.valence_min = 0;
  s.valence_irregular_fraction = interior ? double(irregular) / double(interior) : 0;
  return s;
}

void add_statistics(const MeshStatistics& s, OperationReport& r) {
  const auto& t = s.topology;
  auto count = [](std::size_t n) { return static_cast<std::int64_t>(n); };
  r.add("vertices", count(t.vertices));
  r.add("edges", count(t.edges));
  r.add("faces", count(t.faces));
  r.add("halfedges", count(t.halfedges));
  r.add("triangles", count(s.triangles));
  r.add("quads", count(s.quads));
  r.add("polygons", count(s.polygons));
  r.add("isolated_vertices", count(t.isolated_vertices));
  r.add("boundary_loops", count(t.boundary_loops));
  r.add("boundary_edges", count(t.boundary_edges));
  r.add("components", count(t.components));
  r.add("euler_characteristic", t.euler_characteristic);
  r.add("genus", t.genus);
  r.add("degenerate_faces", count(s.degenerate_faces));
  r.add("multi_edges", count(s.multi_edges));
  r.add("edge_length_min", s.edge_length_min);
  r.add("edge_length_mean", s.edge_length_mean);
  r.add("edge_length_max", s.edge_length_max);
  r.add("edge_length_stddev", s.edge_length_stddev);
  r.add("min_angle_degrees", s.min_angle_degrees);
  r.add("mean_min_angle_degrees", s.mean_min_angle_degrees);
  r.add("quality_min", s.quality_min);
  r.add("quality_mean", s.quality_mean);
  r.add("area", s.area);
  r.add("volume", s.volume);
  r.add("bbox_diagonal", s.bbox_diagonal);
  r.add("valence_min", count(s.valence_min));
  r.add("valence_max", count(s.valence_max));
  r.add("valence_irregular_fraction", s.valence_irregular_fraction);
}

Operation report_operation() {
  Operation op;
  op.id = "report";
  op.title = "Mesh Report";
  op.category = "Measure";
  op.help =
      "Measures the mesh without changing it: element counts, boundary loops, connected components, Euler "
      "characteristic and genus, what building had to repair (non-manifold edges and vertices, flipped and "
      "skipped faces), degenerate faces, edge-length and triangle-quality statistics.";
  op.changes_mesh = false;
  op.run = [](Mesh& mesh, const ParamValues&, Progress& progress) {
    progress.update(0.5, "measuring");
    OperationReport report;
    add_statistics(mesh_statistics(mesh), report);
    return report;
  };
  return op;
}

}  // namespace hedge
