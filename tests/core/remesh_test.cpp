// Tests of isotropic remeshing: edge lengths, quality, distance to the input, features,
// boundaries, attributes, determinism, failure behaviour; figures on the real meshes.
#include "hedge/remesh.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <numbers>

#include "defect_counts.h"
#include "hedge/build.h"
#include "hedge/catalogue.h"
#include "hedge/distance.h"
#include "hedge/io.h"
#include "hedge/report.h"
#include "hedge/threads.h"
#include "hedge/validate.h"
#include "test_meshes.h"

namespace hedge {
namespace {

Mesh mesh_of(const Soup& soup) { return build(soup).mesh; }

// A UV sphere: slivers at the poles, valence 4 everywhere else: a poor mesh to start from.
Soup sphere_soup(int rings, int segments, double r) {
  Soup s;
  s.positions.push_back(Point{{0, 0, float(r)}});
  for (int i = 1; i < rings; ++i) {
    double theta = std::numbers::pi * i / rings;
    for (int j = 0; j < segments; ++j) {
      double phi = 2 * std::numbers::pi * j / segments;
      s.positions.push_back(to_float(
          Vec3d{{r * std::sin(theta) * std::cos(phi), r * std::sin(theta) * std::sin(phi), r * std::cos(theta)}}));
    }
  }
  s.positions.push_back(Point{{0, 0, float(-r)}});
  auto ring = [&](int i, int j) { return std::uint32_t(1 + (i - 1) * segments + (j % segments)); };
  std::uint32_t south = std::uint32_t(s.positions.size() - 1);
  for (int j = 0; j < segments; ++j) s.add_face({0, ring(1, j), ring(1, j + 1)});
  for (int i = 1; i + 1 < rings; ++i)
    for (int j = 0; j < segments; ++j) {
      s.add_face({ring(i, j), ring(i + 1, j), ring(i + 1, j + 1)});
      s.add_face({ring(i, j), ring(i + 1, j + 1), ring(i, j + 1)});
    }
  for (int j = 0; j < segments; ++j) s.add_face({ring(rings - 1, j), south, ring(rings - 1, j + 1)});
  return s;
}

// The cube [-1, 1]^3, each side an n x n grid of quads (polygons on purpose).
Soup cube_soup(int n) {
  Soup s;
  for (int axis = 0; axis < 3; ++axis)
    for (int sign = -1; sign <= 1; sign += 2) {
      std::uint32_t base = std::uint32_t(s.positions.size());
      int u = (axis + 1) % 3, v = (axis + 2) % 3;
      for (int j = 0; j <= n; ++j)
        for (int i = 0; i <= n; ++i) {
          Point p{};
          p[axis] = float(sign);
          p[u] = float(-1 + 2.0 * i / n);
          p[v] = float(-1 + 2.0 * j / n);
          s.positions.push_back(p);
        }
      auto id = [&](int i, int j) { return base + std::uint32_t(j * (n + 1) + i); };
      for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
          if (sign > 0)
            s.add_face({id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)});
          else
            s.add_face({id(i, j), id(i, j + 1), id(i + 1, j + 1), id(i + 1, j)});
        }
    }
  // Weld the shared vertices of the sides.
  std::vector<std::uint32_t> remap(s.positions.size());
  std::vector<Point> unique;
  for (std::size_t i = 0; i < s.positions.size(); ++i) {
    std::size_t k = 0;
    while (k < unique.size() && !(unique[k] == s.positions[i])) ++k;
    if (k == unique.size()) unique.push_back(s.positions[i]);
    remap[i] = std::uint32_t(k);
  }
  for (auto& c : s.corners) c = remap[c];
  s.positions = unique;
  return s;
}

// An open, wavy n x n grid over [0, 1]^2 with fine boundary edges (triangles).
Soup grid_soup(int n, double wave) {
  return test::height_field(n, 1.0, [wave](double x, double y) { return wave * std::sin(3 * x) * std::cos(2 * y); });
}

struct Quality {
  double in_band = 0;  // fraction of edges within [0.8, 1.33] x target
  MeshStatistics stats;
  double hausdorff = 0;  // symmetric, relative to the input's bounding-box diagonal
};

Quality measure(const Mesh& input, const Mesh& out, double target, double sample_density = 4) {
  Quality q;
  std::size_t in = 0;
  for (Edge e : out.edges()) {
    double l = distance(to_double(out.position(out.vertex(e, 0))), to_double(out.position(out.vertex(e, 1))));
    if (l >= 0.8 * target && l <= 1.33 * target) ++in;
  }
  q.in_band = double(in) / double(out.n_edges());
  q.stats = mesh_statistics(out);
  HausdorffOptions options;
  options.sample_density = sample_density;
  q.hausdorff = hausdorff(input, out, options).max / mesh_statistics(input).bbox_diagonal;
  return q;
}

// The share of triangles with an angle under `degrees`.
double share_thinner(const Mesh& mesh, double degrees) {
  std::size_t thin = 0;
  for (Face f : mesh.faces()) {
    std::array<Vec3d, 3> p;
    int k = 0;
    for (Vertex v : mesh.vertices(f)) p[k++] = to_double(mesh.position(v));
    thin += triangle_min_angle(p[0], p[1], p[2]) < degrees;
  }
  return double(thin) / double(mesh.n_faces());
}

void expect_valid(const Mesh& mesh) {
  Validation v = validate(mesh);
  EXPECT_TRUE(v.ok) << v.message;
  EXPECT_FALSE(mesh.has_garbage());
  EXPECT_TRUE(mesh.is_triangle_mesh());
}

TEST(Remesh, SphereReachesTargetQuality) {
  Mesh input = mesh_of(sphere_soup(30, 40, 1.0));
  Mesh mesh = input;
  RemeshOptions options;
  options.target_edge_length = 0.08;
  RemeshReport report = remesh(mesh, options);
  expect_valid(mesh);
  EXPECT_DOUBLE_EQ(report.target_edge_length, 0.08);
  EXPECT_GT(report.splits + report.collapses + report.flips, 0u);
  Quality q = measure(input, mesh, 0.08);
  MeshStatistics before = mesh_statistics(input);
  EXPECT_GE(q.in_band, 0.9);
  EXPECT_GT(q.stats.mean_min_angle_degrees, before.mean_min_angle_degrees);
  // The UV sphere's valences are 6 but for the poles; a closed remeshed sphere needs
  // some 5s and 7s (Euler), so it only has to stay well below the usual 60-70% of scans.
  EXPECT_LT(q.stats.valence_irregular_fraction, 0.25);
  EXPECT_GT(q.stats.mean_min_angle_degrees, 45.0);
  EXPECT_GT(q.stats.min_angle_degrees, before.min_angle_degrees);
  EXPECT_LT(q.hausdorff, 0.01);
  EXPECT_EQ(q.stats.topology.boundary_loops, 0u);
  EXPECT_EQ(q.stats.topology.genus, 0);
  for (Vertex v : mesh.vertices()) EXPECT_NEAR(norm(to_double(mesh.position(v))), 1.0, 0.01);
}

TEST(Remesh, DefaultTargetIsTheMeanEdgeLength) {
  Mesh input = mesh_of(sphere_soup(12, 16, 1.0));
  double mean = mesh_statistics(input).edge_length_mean;
  Mesh mesh = input;
  RemeshReport report = remesh(mesh, RemeshOptions{});
  expect_valid(mesh);
  EXPECT_NEAR(report.target_edge_length, mean, 1e-6);
  EXPECT_NEAR(mesh_statistics(mesh).edge_length_mean, mean, 0.15 * mean);
}

TEST(Remesh, CubeKeepsItsEdgesAndCorners) {
  Mesh input = mesh_of(cube_soup(7));
  Mesh mesh = input;
  RemeshOptions options;
  options.target_edge_length = 0.12;
  RemeshReport report = remesh(mesh, options);
  expect_valid(mesh);
  EXPECT_EQ(report.feature_edges, 12u * 7u);
  EXPECT_EQ(report.triangulated_faces, 6u * 49u);
  // Every vertex on the cube, and the cube's corners still there.
  for (Vertex v : mesh.vertices()) {
    Point p = mesh.position(v);
    double m = std::max({std::abs(p[0]), std::abs(p[1]), std::abs(p[2])});
    EXPECT_NEAR(m, 1.0, 1e-5);
  }
  int corners = 0;
  for (Vertex v : mesh.vertices()) {
    Point p = mesh.position(v);
    if (std::abs(std::abs(p[0]) - 1) < 1e-6 && std::abs(std::abs(p[1]) - 1) < 1e-6 &&
        std::abs(std::abs(p[2]) - 1) < 1e-6)
      ++corners;
  }
  EXPECT_EQ(corners, 8);
  // Sharp edges stay sharp: a rounded edge would be ~L/4 away from the cube's edges.
  HausdorffOptions dense;
  dense.sample_density = 20;
  HausdorffResult d = hausdorff(input, mesh, dense);
  EXPECT_LT(d.max, 1e-4);
  Quality q = measure(input, mesh, 0.12);
  EXPECT_GE(q.in_band, 0.9);
  EXPECT_GT(q.stats.mean_min_angle_degrees, 40.0);
}

TEST(Remesh, FeatureAngle180TurnsFeaturesOff) {
  Mesh mesh = mesh_of(cube_soup(4));
  RemeshOptions options;
  options.target_edge_length = 0.2;
  options.feature_angle = 180;
  RemeshReport report = remesh(mesh, options);
  expect_valid(mesh);
  EXPECT_EQ(report.feature_edges, 0u);
}

TEST(Remesh, BoundaryIsKept) {
  Mesh input = mesh_of(grid_soup(30, 0.1));
  Mesh mesh = input;
  RemeshOptions options;
  options.target_edge_length = 0.05;
  remesh(mesh, options);
  expect_valid(mesh);
  // Boundary vertices are exactly where they were, or on the straight boundary edges.
  double boundary_length = 0;
  for (Edge e : mesh.edges()) {
    if (!mesh.is_boundary(e)) continue;
    Vec3d a = to_double(mesh.position(mesh.vertex(e, 0))), b = to_double(mesh.position(mesh.vertex(e, 1)));
    boundary_length += distance(a, b);
  }
  for (Vertex v : mesh.vertices()) {
    if (!mesh.is_boundary(v)) continue;
    Point p = mesh.position(v);
    bool on_border =
        std::abs(p[0]) < 1e-6 || std::abs(p[0] - 1) < 1e-6 || std::abs(p[1]) < 1e-6 || std::abs(p[1] - 1) < 1e-6;
    EXPECT_TRUE(on_border) << p[0] << " " << p[1];
  }
  double input_length = 0;
  for (Edge e : input.edges())
    if (input.is_boundary(e))
      input_length +=
          distance(to_double(input.position(input.vertex(e, 0))), to_double(input.position(input.vertex(e, 1))));
  EXPECT_NEAR(boundary_length, input_length, 1e-4 * input_length);
  EXPECT_EQ(mesh_statistics(mesh).topology.boundary_loops, 1u);
  Quality q = measure(input, mesh, 0.05);
  EXPECT_LT(q.hausdorff, 0.01);
}

TEST(Remesh, BoundarySlidesWhenNotPreserved) {
  Mesh input = mesh_of(grid_soup(40, 0.0));  // boundary edges of 0.025
  Mesh mesh = input;
  RemeshOptions options;
  options.target_edge_length = 0.06;
  options.preserve_boundary = false;
  remesh(mesh, options);
  expect_valid(mesh);
  std::size_t boundary_edges = 0;
  for (Edge e : mesh.edges())
    if (mesh.is_boundary(e)) ++boundary_edges;
  EXPECT_LT(boundary_edges, 160u * 0.6);  // coarser than the input's 160
  EXPECT_GT(boundary_edges, 40u);
  for (Vertex v : mesh.vertices()) {
    if (!mesh.is_boundary(v)) continue;
    Point p = mesh.position(v);
    bool on_border =
        std::abs(p[0]) < 1e-5 || std::abs(p[0] - 1) < 1e-5 || std::abs(p[1]) < 1e-5 || std::abs(p[1] - 1) < 1e-5;
    EXPECT_TRUE(on_border) << p[0] << " " << p[1];
  }
  // The square's corners are where the boundary turns: they stay.
  int corners = 0;
  for (Vertex v : mesh.vertices()) {
    Point p = mesh.position(v);
    if ((p[0] == 0 || p[0] == 1) && (p[1] == 0 || p[1] == 1)) ++corners;
  }
  EXPECT_EQ(corners, 4);
  EXPECT_GE(measure(input, mesh, 0.06).in_band, 0.9);
}

TEST(Remesh, AdaptiveFollowsCurvature) {
  // An ellipsoid, long along x: the tips bend much more than the middle.
  Soup s = sphere_soup(40, 60, 1.0);
  for (Point& p : s.positions) p[0] *= 3, p[1] *= 0.6f, p[2] *= 0.6f;
  // Rotate so the poles of the UV grid are not at the tips.
  for (Point& p : s.positions) std::swap(p[0], p[2]);
  Mesh input = mesh_of(s);
  Mesh mesh = input;
  RemeshOptions options;
  options.target_edge_length = 0.12;
  options.adaptive = true;
  remesh(mesh, options);
  expect_valid(mesh);
  double tip_sum = 0, middle_sum = 0;
  int tips = 0, middles = 0;
  for (Edge e : mesh.edges()) {
    Vec3d a = to_double(mesh.position(mesh.vertex(e, 0))), b = to_double(mesh.position(mesh.vertex(e, 1)));
    double z = std::abs(0.5 * (a[2] + b[2]));
    if (z > 2.7) tip_sum += distance(a, b), ++tips;
    if (z < 0.5) middle_sum += distance(a, b), ++middles;
  }
  ASSERT_GT(tips, 0);
  ASSERT_GT(middles, 0);
  EXPECT_LT(tip_sum / tips, 0.7 * (middle_sum / middles));
  Mesh uniform = input;
  options.adaptive = false;
  remesh(uniform, options);
  EXPECT_LT(measure(input, mesh, 0.12).hausdorff, 0.01);
}

TEST(Remesh, CarriesAttributesAndKeepsSeams) {
  // Vertex colour = (x, y, 0); corner uv = (x, y) left of x = 0.5 and (x + 1, y) right of it:
  // a seam the remesher must keep, with attributes that follow the moved vertices.
  Soup s = grid_soup(24, 0.0);
  Channel& color = s.add_channel("color", Domain::vertex, ScalarType::f32, 3);
  for (std::size_t i = 0; i < s.n_vertices(); ++i) {
    color.as<float>()[3 * i] = s.positions[i][0];
    color.as<float>()[3 * i + 1] = s.positions[i][1];
    color.as<float>()[3 * i + 2] = 0;
  }
  Channel& uv = s.add_channel("uv", Domain::corner, ScalarType::f32, 2);
  auto offsets = s.face_offsets();
  for (std::size_t f = 0; f < s.n_faces(); ++f) {
    double cx = 0;
    for (std::size_t k = offsets[f]; k < offsets[f + 1]; ++k) cx += s.positions[s.corners[k]][0] / 3.0;
    for (std::size_t k = offsets[f]; k < offsets[f + 1]; ++k) {
      const Point& p = s.positions[s.corners[k]];
      uv.as<float>()[2 * k] = p[0] + (cx > 0.5 ? 1.0f : 0.0f);
      uv.as<float>()[2 * k + 1] = p[1];
    }
  }
  Mesh mesh = mesh_of(s);
  RemeshOptions options;
  options.target_edge_length = 0.07;
  remesh(mesh, options);
  expect_valid(mesh);

  const ChannelArray* vc = mesh.vertex_properties().get_channel("color");
  const ChannelArray* hc = mesh.halfedge_properties().get_channel("uv");
  ASSERT_TRUE(vc && hc);
  for (Vertex v : mesh.vertices()) {
    const float* c = reinterpret_cast<const float*>(vc->element(v.idx()));
    EXPECT_NEAR(c[0], mesh.position(v)[0], 1e-4);
    EXPECT_NEAR(c[1], mesh.position(v)[1], 1e-4);
  }
  for (Face f : mesh.faces()) {
    double cx = 0;
    for (Vertex v : mesh.vertices(f)) cx += mesh.position(v)[0] / 3.0;
    for (Halfedge h : mesh.halfedges(f)) {
      const float* t = reinterpret_cast<const float*>(hc->element(h.idx()));
      const Point& p = mesh.position(mesh.to_vertex(h));
      EXPECT_NEAR(t[0], p[0] + (cx > 0.5 ? 1.0 : 0.0), 1e-4) << "face " << f.idx();
      EXPECT_NEAR(t[1], p[1], 1e-4);
    }
  }
  // The seam is still a line of edges at x = 0.5.
  std::size_t seam_edges = 0;
  for (Edge e : mesh.edges())
    if (std::abs(mesh.position(mesh.vertex(e, 0))[0] - 0.5f) < 1e-6 &&
        std::abs(mesh.position(mesh.vertex(e, 1))[0] - 0.5f) < 1e-6)
      ++seam_edges;
  EXPECT_GE(seam_edges, 14u);
  // A round trip to the soup keeps the channels.
  Soup out = extract(mesh);
  EXPECT_TRUE(out.find("uv", Domain::corner));
  EXPECT_TRUE(out.find("color", Domain::vertex));
}

// The same vertices in the same places and the same faces on them, in the same order.
void expect_same_mesh(const Mesh& a, const Mesh& b) {
  ASSERT_EQ(a.n_vertices(), b.n_vertices());
  ASSERT_EQ(a.n_faces(), b.n_faces());
  EXPECT_EQ(a.positions(), b.positions());
  for (Face f : a.faces()) {
    std::vector<Vertex> va, vb;
    for (Vertex v : a.vertices(f)) va.push_back(v);
    for (Vertex v : b.vertices(f)) vb.push_back(v);
    ASSERT_EQ(va, vb);
  }
}

TEST(Remesh, IsDeterministic) {
  Mesh input = mesh_of(sphere_soup(20, 30, 1.0));
  Mesh a = input, b = input;
  RemeshOptions options;
  options.target_edge_length = 0.1;
  remesh(a, options);
  remesh(b, options);
  expect_same_mesh(a, b);
}

// From 50,000 faces on, the collapses and flips run region by region on all threads. A
// fine sphere with a fin along part of its equator (edges of three faces, which build()
// splits into copies the weld joins again): the result is the same on one thread and on
// two, and it has no defect the input had not.
TEST(Remesh, RegionsGiveOneResultAtEveryThreadCount) {
  const int rings = 130, segments = 240;
  Soup soup = sphere_soup(rings, segments, 1.0);
  const auto equator = [&](int j) { return std::uint32_t(1 + (rings / 2 - 1) * segments + j); };
  const std::uint32_t first_out = std::uint32_t(soup.positions.size());
  for (int j = 0; j <= 40; ++j) soup.positions.push_back(to_float(to_double(soup.positions[equator(j)]) * 1.2));
  for (std::uint32_t j = 0; j < 40; ++j) {
    soup.add_face({equator(j), equator(j + 1), first_out + j});
    soup.add_face({equator(j + 1), first_out + j + 1, first_out + j});
  }
  ASSERT_GT(soup.n_faces(), 60000u);
  const test::DefectCounts before = test::count_defects(soup);
  ASSERT_EQ(before.non_manifold_edges, 40u);

  RemeshOptions options;
  options.iterations = 2;
  std::vector<Mesh> results;
  for (unsigned threads : {1u, 2u}) {
    set_thread_count(threads);
    Mesh mesh = mesh_of(soup);
    const RemeshReport report = remesh(mesh, options);
    set_thread_count(0);
    EXPECT_GT(report.collapses, 10000u);
    EXPECT_GT(report.flips, 10000u);
    expect_valid(mesh);
    const test::DefectCounts after = test::count_defects(extract(mesh));
    EXPECT_EQ(after.non_manifold_edges, before.non_manifold_edges);
    EXPECT_EQ(after.non_manifold_vertices, before.non_manifold_vertices);
    EXPECT_EQ(after.duplicate_faces, 0u);
    results.push_back(std::move(mesh));
  }
  expect_same_mesh(results[0], results[1]);
}

TEST(Remesh, FailureLeavesTheMeshUntouched) {
  Mesh input = mesh_of(cube_soup(3));
  Mesh mesh = input;
  RemeshOptions bad;
  bad.iterations = 0;
  EXPECT_THROW(remesh(mesh, bad), Error);
  bad = RemeshOptions{};
  bad.feature_angle = 200;
  EXPECT_THROW(remesh(mesh, bad), Error);
  bad = RemeshOptions{};
  bad.target_edge_length = -1;
  EXPECT_THROW(remesh(mesh, bad), Error);
  Mesh empty;
  EXPECT_THROW(remesh(empty, RemeshOptions{}), Error);

  // Cancelled halfway: the mesh is as it was (polygons included).
  int calls = 0;
  Progress cancel([&](double, const std::string&) { return ++calls < 8; });
  RemeshOptions options;
  options.target_edge_length = 0.1;
  EXPECT_THROW(remesh(mesh, options, cancel), Cancelled);
  EXPECT_EQ(mesh.n_faces(), input.n_faces());
  EXPECT_EQ(mesh.positions(), input.positions());
  EXPECT_TRUE(validate(mesh).ok);
  EXPECT_FALSE(mesh.is_triangle_mesh());
}

// One polygon of 100,000 corners on a circle: its mean edge length on its own disc would make
// billions of triangles. Refused at once, naming the parameter, the mesh untouched; a sensible
// target still works.
TEST(Remesh, RefusesTargetsThatWouldMakeTooManyTriangles) {
  Soup soup;
  const int n = 100000;
  std::vector<std::uint32_t> corners;
  for (int k = 0; k < n; ++k) {
    const double a = 2 * std::numbers::pi * k / n;
    soup.positions.push_back(Point{{float(std::cos(a)), float(std::sin(a)), 0}});
    corners.push_back(std::uint32_t(k));
  }
  soup.add_face(corners);
  Mesh mesh = mesh_of(soup);
  const Mesh input = mesh;
  try {
    remesh(mesh, RemeshOptions{});
    FAIL() << "accepted";
  } catch (const Error& e) {
    EXPECT_THAT(e.what(), testing::HasSubstr("(the mean edge length of the input)"));
    EXPECT_THAT(e.what(), testing::HasSubstr("more than the limit of 200000000; give a larger target_edge_length"));
  }
  EXPECT_EQ(mesh.n_faces(), 1u);
  EXPECT_EQ(mesh.positions(), input.positions());

  Mesh cube = mesh_of(cube_soup(2));  // area 24
  RemeshOptions options;
  options.target_edge_length = 0.1;  // about 5,500 triangles
  options.max_faces = 5000;
  EXPECT_THROW(remesh(cube, options), Error);
  options.max_faces = 6000;
  options.iterations = 1;
  EXPECT_NO_THROW(remesh(cube, options));
  EXPECT_TRUE(validate(cube).ok);
}

// A coarse mesh far above the target (an octahedron of edge 1.4, target 0.05): the split pass
// refines in even rounds, so the result stays near area / (sqrt(3)/4 L^2) = 6,400 triangles
// (splitting each edge to the end at once, fans to the far corners made 390,000 triangles in
// the first iteration and 8,300 after five).
TEST(Remesh, CoarseInputRefinesEvenly) {
  Soup soup;
  for (Point p :
       {Point{{1, 0, 0}}, Point{{-1, 0, 0}}, Point{{0, 1, 0}}, Point{{0, -1, 0}}, Point{{0, 0, 1}}, Point{{0, 0, -1}}})
    soup.positions.push_back(p);
  for (auto f : std::vector<std::vector<std::uint32_t>>{
           {0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4}, {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}})
    soup.add_face(f);
  Mesh mesh = mesh_of(soup);
  RemeshOptions options;
  options.target_edge_length = 0.05;
  options.iterations = 1;
  const RemeshReport first = remesh(mesh, options);
  EXPECT_LT(first.splits, 30000u);
  EXPECT_LT(mesh.n_faces(), 20000u);
  mesh = mesh_of(soup);
  options.iterations = 5;
  remesh(mesh, options);
  EXPECT_TRUE(validate(mesh).ok);
  EXPECT_GT(mesh.n_faces(), 5000u);
  EXPECT_LT(mesh.n_faces(), 8000u);
}

TEST(Remesh, CatalogueEntry) {
  const Operation& op = find_operation("remesh");
  EXPECT_EQ(op.title, "Isotropic Remesh");
  EXPECT_EQ(op.category, Category::remeshing);
  ASSERT_EQ(op.params.size(), 6u);
  EXPECT_EQ(op.params[0].id, "target_edge_length");
  EXPECT_EQ(op.params[1].id, "iterations");
  EXPECT_EQ(op.params[2].id, "feature_angle");
  EXPECT_EQ(op.params[3].id, "preserve_boundary");
  EXPECT_EQ(op.params[4].id, "adaptive");
  EXPECT_EQ(op.params[5].id, "selection_only");
  EXPECT_EQ(op.params[1].default_value, Value(std::int64_t(5)));
  EXPECT_EQ(op.params[2].default_value, Value(45.0));
  RunResult r =
      run_operation(op, sphere_soup(10, 12, 1.0),
                    resolve_params(op, std::map<std::string, std::string>{{"iterations", "3"}}), Progress::none());
  EXPECT_GT(r.soup.n_faces(), 0u);
  ASSERT_TRUE(r.report.find("splits"));
  EXPECT_THROW(resolve_params(op, std::map<std::string, std::string>{{"iterations", "0"}}), Error);
}

// Real meshes: the quality targets of the brief, on what loads fast enough for a unit test.
// The low resolutions of the dragon are non-manifold with many holes: build() splits them
// into copies that must stay welded (fixed) and boundaries that stay as they are, so the
// share of edges in the band is printed there, not asserted.
void check_real(const char* name, int iterations, bool band, bool min_angle = false, bool larger_min_angle = false) {
  std::string path = std::string(HEDGE_MESH_DIR) + "/" + name;
  if (!std::filesystem::exists(path)) GTEST_SKIP() << path << " not present";
  Mesh input = mesh_of(read_mesh(path));
  Mesh mesh = input;
  RemeshOptions options;
  options.iterations = iterations;
  auto t0 = std::chrono::steady_clock::now();
  RemeshReport report = remesh(mesh, options);
  double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  expect_valid(mesh);
  Quality q = measure(input, mesh, report.target_edge_length);
  MeshStatistics before = mesh_statistics(input);
  std::printf(
      "[ figures  ] %s: %zu -> %zu faces in %.2f s (%d iterations); in band %.1f%%; min angle %.2f -> %.2f deg, "
      "mean min angle %.1f -> %.1f deg; irregular valence %.1f%% -> %.1f%%; Hausdorff %.4f%% of the diagonal\n",
      name, input.n_faces(), mesh.n_faces(), seconds, iterations, 100 * q.in_band, before.min_angle_degrees,
      q.stats.min_angle_degrees, before.mean_min_angle_degrees, q.stats.mean_min_angle_degrees,
      100 * before.valence_irregular_fraction, 100 * q.stats.valence_irregular_fraction, 100 * q.hausdorff);
  if (band) {
    EXPECT_GE(q.in_band, 0.9);
  }
  if (larger_min_angle) {
    EXPECT_GT(q.stats.min_angle_degrees, before.min_angle_degrees);
  }
  if (min_angle) {
    // The scan's own worst triangles lie between vertices remeshing must keep (boundary,
    // non-manifold copies), so the smallest angle can at best stay; the share of thin
    // triangles must drop.
    EXPECT_GE(q.stats.min_angle_degrees, before.min_angle_degrees);
    const double thin_before = share_thinner(input, 10), thin_after = share_thinner(mesh, 10);
    std::printf("[ figures  ] %s: triangles with an angle under 10 deg: %.3f%% -> %.3f%%\n", name, 100 * thin_before,
                100 * thin_after);
    EXPECT_LT(thin_after, thin_before);
  }
  EXPECT_GT(q.stats.mean_min_angle_degrees, before.mean_min_angle_degrees);
  EXPECT_LT(q.stats.valence_irregular_fraction, before.valence_irregular_fraction);
  EXPECT_LT(q.hausdorff, 0.01);
}

// A closed scan with no degenerate triangle: its smallest angle (13.2 degrees) must grow.
TEST(Remesh, Bunny) { check_real("bunny.off", 5, true, false, true); }
TEST(Remesh, DragonRes3NonManifold) { check_real("dragon_res3.ply", 5, false); }
// The quality gates on a real scan of 202k faces with the catalogue's defaults: at
// least 90 % of the edges within [0.8, 1.33] x target, a smallest angle no smaller, fewer thin
// triangles, a larger mean smallest angle, fewer irregular vertices, Hausdorff under 1 % of
// the diagonal.
TEST(Remesh, DragonRes2QualityGates) { check_real("dragon_res2.ply", 5, true, true); }
TEST(Remesh, DragonRes4NonManifold) { check_real("dragon_res4.ply", 5, false); }

// Speed figures (printed, not asserted): 3 iterations at the mean edge length, as the
// benchmark against CGAL's isotropic_remeshing runs them.
TEST(Remesh, DragonFigures) {
  for (const char* name : {"dragon_res2.ply", "dragon.ply"}) {
    std::string path = std::string(HEDGE_MESH_DIR) + "/" + name;
    if (!std::filesystem::exists(path)) GTEST_SKIP() << path << " not present";
    Mesh input = mesh_of(read_mesh(path));
    Mesh mesh = input;
    RemeshOptions options;
    options.iterations = 3;
    auto t0 = std::chrono::steady_clock::now();
    RemeshReport report = remesh(mesh, options);
    double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    expect_valid(mesh);
    Quality q = measure(input, mesh, report.target_edge_length, 1);
    std::printf(
        "[ figures  ] %s: %zu -> %zu faces, 3 iterations in %.2f s (%zu splits, %zu collapses, %zu flips); "
        "in band %.1f%%; mean min angle %.1f deg; irregular %.1f%%; Hausdorff %.4f%% of the diagonal\n",
        name, input.n_faces(), mesh.n_faces(), seconds, report.splits, report.collapses, report.flips, 100 * q.in_band,
        q.stats.mean_min_angle_degrees, 100 * q.stats.valence_irregular_fraction, 100 * q.hausdorff);
  }
}

}  // namespace
}  // namespace hedge
