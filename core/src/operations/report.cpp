// The report operation: counts, topology, edge lengths and triangle quality.
#include "hedge/report.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <vector>

#include "binding.h"

namespace hedge {

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

namespace {
//! The report takes no options.
struct ReportOptions {};
}  // namespace

Operation report_operation() {
  const char* help =
      "Measures the mesh without changing it: element counts, boundary loops, connected components, Euler "
      "characteristic and genus, what building had to repair (non-manifold edges and vertices, flipped and "
      "skipped faces), degenerate faces, edge-length and triangle-quality statistics.";
  using O = ReportOptions;
  using R = MeshStatistics;
  auto run = [](Mesh& mesh, const O&, Progress& progress) {
    progress.update(0.5, "measuring");
    return mesh_statistics(mesh);
  };
  auto topology = [](auto TopologyStats::*field) {
    return [field](const O&, const R& r) -> std::optional<Value> { return field_value(r.topology.*field); };
  };
  return Binding<O, R>("report", "Mesh Report", Category::measure, help, run)
      .measures_only()
      .result("vertices", topology(&TopologyStats::vertices))
      .result("edges", topology(&TopologyStats::edges))
      .result("faces", topology(&TopologyStats::faces))
      .result("halfedges", topology(&TopologyStats::halfedges))
      .result(&R::triangles, "triangles")
      .result(&R::quads, "quads")
      .result(&R::polygons, "polygons")
      .result("isolated_vertices", topology(&TopologyStats::isolated_vertices))
      .result("boundary_loops", topology(&TopologyStats::boundary_loops))
      .result("boundary_edges", topology(&TopologyStats::boundary_edges))
      .result("components", topology(&TopologyStats::components))
      .result("euler_characteristic", topology(&TopologyStats::euler_characteristic))
      .result("genus", topology(&TopologyStats::genus))
      .result(&R::degenerate_faces, "degenerate_faces")
      .result(&R::multi_edges, "multi_edges")
      .result(&R::edge_length_min, "edge_length_min")
      .result(&R::edge_length_mean, "edge_length_mean")
      .result(&R::edge_length_max, "edge_length_max")
      .result(&R::edge_length_stddev, "edge_length_stddev")
      .result(&R::min_angle_degrees, "min_angle_degrees")
      .result(&R::mean_min_angle_degrees, "mean_min_angle_degrees")
      .result(&R::quality_min, "quality_min")
      .result(&R::quality_mean, "quality_mean")
      .result(&R::area, "area")
      .result(&R::volume, "volume")
      .result(&R::bbox_diagonal, "bbox_diagonal")
      .result(&R::valence_min, "valence_min")
      .result(&R::valence_max, "valence_max")
      .result(&R::valence_irregular_fraction, "valence_irregular_fraction");
}

}  // namespace hedge
