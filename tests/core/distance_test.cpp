// Tests of the closest-point tree and the Hausdorff sampler: against brute force, and on
// shapes whose distances are known.
#include "hedge/distance.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <numbers>
#include <random>

#include "hedge/build.h"
#include "hedge/io.h"
#include "test_meshes.h"

namespace hedge {
namespace {

Mesh mesh_of(const Soup& soup) { return build(soup).mesh; }

// An n x n grid of squares (two triangles each) over [0, size]^2 at height z.
Soup grid_soup(int n, double size, double z) {
  return test::height_field(n, size, [z](double, double) { return z; });
}

// A UV sphere of radius r around c.
Soup sphere_soup(int rings, int segments, double r, Vec3d c) {
  Soup s;
  s.positions.push_back(to_float(c + Vec3d{{0, 0, r}}));
  for (int i = 1; i < rings; ++i) {
    double theta = std::numbers::pi * i / rings;
    for (int j = 0; j < segments; ++j) {
      double phi = 2 * std::numbers::pi * j / segments;
      s.positions.push_back(to_float(
          c + Vec3d{{r * std::sin(theta) * std::cos(phi), r * std::sin(theta) * std::sin(phi), r * std::cos(theta)}}));
    }
  }
  s.positions.push_back(to_float(c + Vec3d{{0, 0, -r}}));
  auto ring = [&](int i, int j) { return std::uint32_t(1 + (i - 1) * segments + (j % segments)); };
  std::uint32_t south = std::uint32_t(s.positions.size() - 1);
  for (int j = 0; j < segments; ++j) s.add_face({0, ring(1, j), ring(1, j + 1)});
  for (int i = 1; i + 1 < rings; ++i)
    for (int j = 0; j < segments; ++j) s.add_face({ring(i, j), ring(i + 1, j), ring(i + 1, j + 1), ring(i, j + 1)});
  for (int j = 0; j < segments; ++j) s.add_face({ring(rings - 1, j), south, ring(rings - 1, j + 1)});
  return s;
}

double brute_force(const Vec3d& p, const std::vector<Point>& pos, const std::vector<std::array<Index, 3>>& tris) {
  double best = std::numeric_limits<double>::infinity();
  for (const auto& t : tris)
    best = std::min(
        best, closest_point_on_triangle(p, to_double(pos[t[0]]), to_double(pos[t[1]]), to_double(pos[t[2]])).distance);
  return best;
}

TEST(Distance, TriangleClosestPointMatchesDenseSampling) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int trial = 0; trial < 50; ++trial) {
    Vec3d a{{u(rng), u(rng), u(rng)}}, b{{u(rng), u(rng), u(rng)}}, c{{u(rng), u(rng), u(rng)}};
    if (trial % 10 == 0) c = a + (b - a) * 0.3;  // degenerate: collinear corners
    if (trial % 10 == 1) b = a;                  // degenerate: repeated corner
    Vec3d p{{2 * u(rng), 2 * u(rng), 2 * u(rng)}};
    ClosestPoint cp = closest_point_on_triangle(p, a, b, c);
    ASSERT_TRUE(std::isfinite(cp.distance));
    // The answer is a point of the triangle...
    Vec3d bary = cp.barycentric;
    EXPECT_NEAR(bary[0] + bary[1] + bary[2], 1.0, 1e-12);
    for (int k = 0; k < 3; ++k) EXPECT_GE(bary[k], -1e-12);
    EXPECT_NEAR(distance(cp.point, a * bary[0] + b * bary[1] + c * bary[2]), 0.0, 1e-12);
    // ...and no point of a fine barycentric grid is nearer.
    const int n = 60;
    double grid_best = std::numeric_limits<double>::infinity();
    for (int i = 0; i <= n; ++i)
      for (int j = 0; i + j <= n; ++j) {
        double s = double(i) / n, t = double(j) / n;
        grid_best = std::min(grid_best, distance(p, a * (1 - s - t) + b * s + c * t));
      }
    EXPECT_LE(cp.distance, grid_best + 1e-12);
    EXPECT_GE(cp.distance, grid_best - 0.05);
  }
}

TEST(Distance, TreeMatchesBruteForceOnRandomSoup) {
  std::mt19937 rng(42);
  std::uniform_real_distribution<float> u(0, 10);
  std::normal_distribution<float> small(0, 0.3f);
  std::vector<Point> pos;
  std::vector<std::array<Index, 3>> tris;
  for (int t = 0; t < 2000; ++t) {
    Point c{{u(rng), u(rng), u(rng)}};
    for (int k = 0; k < 3; ++k) pos.push_back(c + Point{{small(rng), small(rng), small(rng)}});
    Index base = Index(pos.size() - 3);
    tris.push_back({base, base + 1, base + 2});
  }
  // A few coincident and degenerate triangles to exercise the builder's fallbacks.
  for (int t = 0; t < 20; ++t) tris.push_back(tris[5]);
  tris.push_back({0, 0, 1});

  TriangleTree tree(pos, tris);
  ASSERT_EQ(tree.n_triangles(), tris.size());
  std::uniform_real_distribution<double> q(-3, 13);
  for (int i = 0; i < 2000; ++i) {
    Vec3d p{{q(rng), q(rng), q(rng)}};
    double expected = brute_force(p, pos, tris);
    ClosestPoint cp = tree.closest_point(p);
    ASSERT_TRUE(cp.found());
    EXPECT_DOUBLE_EQ(cp.distance, expected);
    // The reported triangle and barycentrics give the reported point.
    auto corners = tree.corners(cp.triangle);
    Vec3d from_bary = corners[0] * cp.barycentric[0] + corners[1] * cp.barycentric[1] + corners[2] * cp.barycentric[2];
    EXPECT_NEAR(distance(from_bary, cp.point), 0.0, 1e-9);
    EXPECT_NEAR(distance(p, cp.point), cp.distance, 1e-12);
    // A hint (right or wrong) does not change the answer.
    ClosestPoint hinted = tree.closest_point_with_hint(p, Index(rng() % tris.size()));
    EXPECT_DOUBLE_EQ(hinted.distance, expected);
    // A bound below the distance finds nothing; one above finds the same.
    EXPECT_FALSE(tree.closest_point(p, expected * 0.99).found());
    EXPECT_DOUBLE_EQ(tree.closest_point(p, expected * 1.01 + 1e-9).distance, expected);
  }
}

TEST(Distance, SoupTreeChecksIndices) {
  std::vector<Point> pos(3);
  std::vector<std::array<Index, 3>> tris = {{0, 1, 3}};
  EXPECT_THROW(TriangleTree(pos, tris), Error);
  TriangleTree empty;
  EXPECT_FALSE(empty.closest_point(Vec3d{}).found());
}

TEST(Distance, MeshTreeFansPolygonsAndMapsFaces) {
  Mesh sphere = mesh_of(sphere_soup(12, 16, 1.0, Vec3d{{1, 2, 3}}));  // quads and triangles
  TriangleTree tree(sphere);
  EXPECT_EQ(tree.n_triangles(), 2 * 16 + 2 * 16 * 10);
  // Points far outside: distance is |p - c| - r up to the facets' sag.
  for (double d : {2.0, 5.0, 10.0}) {
    Vec3d p = Vec3d{{1, 2, 3}} + normalize(Vec3d{{0.3, -0.5, 0.8}}) * d;
    ClosestPoint cp = tree.closest_point(p);
    EXPECT_NEAR(cp.distance, d - 1.0, 0.04);
    EXPECT_GE(cp.distance, d - 1.0 - 1e-6);  // the polyhedron is inside the sphere
    Face f = tree.face(cp.triangle);
    ASSERT_TRUE(f.is_valid());
    EXPECT_LT(f.idx(), sphere.faces_size());
  }
  // From the centre, every face is about r away.
  EXPECT_NEAR(tree.closest_point(Vec3d{{1, 2, 3}}).distance, 1.0, 0.04);
}

TEST(Distance, ParallelPlanes) {
  Mesh a = mesh_of(grid_soup(20, 1.0, 0.0));
  Mesh b = mesh_of(grid_soup(7, 1.0, 0.25));
  HausdorffResult r = hausdorff(a, b);
  EXPECT_NEAR(r.a_to_b.max, 0.25, 1e-6);
  EXPECT_NEAR(r.a_to_b.mean, 0.25, 1e-6);
  EXPECT_NEAR(r.b_to_a.max, 0.25, 1e-6);
  EXPECT_NEAR(r.b_to_a.rms, 0.25, 1e-6);
  EXPECT_NEAR(r.max, 0.25, 1e-6);
  EXPECT_GT(r.a_to_b.samples, a.n_vertices() + a.n_edges());
}

TEST(Distance, ShiftedPlaneSeesTheOverhang) {
  // b covers [0.5, 1.5] x [0, 1]: a's points at x = 0 are 0.5 away horizontally and 0.1 vertically.
  Mesh a = mesh_of(grid_soup(10, 1.0, 0.0));
  Soup sb = grid_soup(10, 1.0, 0.1);
  for (Point& p : sb.positions) p[0] += 0.5f;
  Mesh b = mesh_of(sb);
  HausdorffResult r = hausdorff(a, b);
  double expected = std::sqrt(0.5 * 0.5 + 0.1 * 0.1);
  EXPECT_NEAR(r.a_to_b.max, expected, 1e-6);
  EXPECT_NEAR(r.b_to_a.max, expected, 1e-6);
  EXPECT_NEAR(r.a_to_b.worst_sample[0], 0.0, 1e-6);
}

TEST(Distance, SphereAgainstAPoint) {
  // A tiny triangle at the centre stands for the point: every sample of the sphere is r away.
  Mesh sphere = mesh_of(sphere_soup(24, 32, 2.0, Vec3d{{0, 0, 0}}));
  Soup dot;
  dot.positions = {Point{{0, 0, 0}}, Point{{1e-6f, 0, 0}}, Point{{0, 1e-6f, 0}}};
  dot.add_face({0, 1, 2});
  Mesh point = mesh_of(dot);
  HausdorffResult r = hausdorff(sphere, point);
  EXPECT_NEAR(r.a_to_b.max, 2.0, 1e-5);  // vertices lie on the sphere
  EXPECT_LT(r.a_to_b.mean, 2.0);         // face samples lie inside it
  EXPECT_GT(r.a_to_b.mean, 1.98);
  // From the centre the nearest facet is a bit closer than r (facets lie inside the sphere).
  EXPECT_LE(r.b_to_a.max, 2.0);
  EXPECT_GT(r.b_to_a.max, 1.97);
  EXPECT_NEAR(r.max, 2.0, 1e-5);
}

TEST(Distance, DeterministicAcrossThreadsAndSeeds) {
  Mesh a = mesh_of(sphere_soup(16, 24, 1.0, Vec3d{}));
  Mesh b = mesh_of(sphere_soup(9, 11, 1.05, Vec3d{{0.02, 0, 0}}));
  HausdorffOptions one;
  one.threads = 1;
  HausdorffOptions two;
  two.threads = 2;
  HausdorffResult r1 = hausdorff(a, b, one), r2 = hausdorff(a, b, two), r3 = hausdorff(a, b, two);
  EXPECT_EQ(r1.max, r2.max);
  EXPECT_EQ(r1.a_to_b.mean, r2.a_to_b.mean);
  EXPECT_EQ(r1.b_to_a.rms, r2.b_to_a.rms);
  EXPECT_EQ(r2.a_to_b.mean, r3.a_to_b.mean);
  EXPECT_EQ(r1.a_to_b.samples, r2.a_to_b.samples);
  // More samples: the estimate of the mean converges, the count grows with the density.
  HausdorffOptions dense = two;
  dense.sample_density = 40;
  HausdorffResult rd = hausdorff(a, b, dense);
  EXPECT_GT(rd.a_to_b.samples, 5 * r2.a_to_b.samples);
  EXPECT_NEAR(rd.a_to_b.mean, r2.a_to_b.mean, 0.1 * r2.a_to_b.mean);
  EXPECT_GE(rd.max, r2.max * 0.99);
}

TEST(Distance, RejectsEmptyMeshes) {
  Mesh empty;
  Mesh a = mesh_of(grid_soup(2, 1.0, 0.0));
  EXPECT_THROW(hausdorff(a, empty), Error);
  EXPECT_THROW(hausdorff(empty, a), Error);
}

TEST(Distance, RealMeshFigures) {
  // Speed is measured here, not asserted: tree build and query rates on the biggest mesh.
  for (const char* name : {"bunny.off", "dragon.ply"}) {
    std::string path = std::string(HEDGE_MESH_DIR) + "/" + name;
    if (!std::filesystem::exists(path)) GTEST_SKIP() << path << " not present";
    Mesh mesh = mesh_of(read_mesh(path));
    auto t0 = std::chrono::steady_clock::now();
    TriangleTree tree(mesh);
    auto t1 = std::chrono::steady_clock::now();
    // Queries near the surface, each vertex pushed off by a bit, as remeshing and
    // simplification ask them.
    std::mt19937 rng(3);
    std::normal_distribution<double> off(0, 1e-3 * norm(tree.box_max() - tree.box_min()));
    std::size_t queries = 0;
    double worst = 0;
    for (Vertex v : mesh.vertices()) {
      if (v.idx() % 4) continue;
      Vec3d p = to_double(mesh.position(v)) + Vec3d{{off(rng), off(rng), off(rng)}};
      ClosestPoint cp = tree.closest_point(p);
      worst = std::max(worst, cp.distance);
      ++queries;
    }
    auto t2 = std::chrono::steady_clock::now();
    HausdorffResult self = hausdorff(mesh, mesh);
    auto t3 = std::chrono::steady_clock::now();
    EXPECT_LT(self.max, 1e-9 * norm(tree.box_max() - tree.box_min()));
    auto ms = [](auto a, auto b) { return std::chrono::duration<double, std::milli>(b - a).count(); };
    std::printf(
        "[ figures  ] %s: %zu triangles, tree %.1f ms (%.1f MB), %zu queries %.1f ms (%.2f us each), "
        "self-Hausdorff %zu+%zu samples %.1f ms\n",
        name, tree.n_triangles(), ms(t0, t1), double(tree.heap_bytes()) / 1e6, queries, ms(t1, t2),
        1e3 * ms(t1, t2) / double(queries), self.a_to_b.samples, self.b_to_a.samples, ms(t2, t3));
  }
}

}  // namespace
namespace {

// Every face with its corners in reverse order (its normal turned over).
Soup reversed(Soup s) {
  const auto offsets = s.face_offsets();
  for (std::size_t f = 0; f < s.n_faces(); ++f)
    std::reverse(s.corners.begin() + std::ptrdiff_t(offsets[f]), s.corners.begin() + std::ptrdiff_t(offsets[f + 1]));
  return s;
}

// Two grids as one soup.
Soup two_layers(const Soup& a, const Soup& b) {
  Soup s = a;
  const auto n = std::uint32_t(s.positions.size());
  s.positions.insert(s.positions.end(), b.positions.begin(), b.positions.end());
  s.face_sizes.insert(s.face_sizes.end(), b.face_sizes.begin(), b.face_sizes.end());
  for (std::uint32_t c : b.corners) s.corners.push_back(c + n);
  return s;
}

}  // namespace

TEST(Distance, FlippedFaces) {
  const Mesh sphere = mesh_of(sphere_soup(12, 16, 1.0, Vec3d{{0, 0, 0}}));
  EXPECT_EQ(flipped_faces(sphere, TriangleTree(sphere)), 0u);
  const Mesh inside_out = mesh_of(reversed(sphere_soup(12, 16, 1.0, Vec3d{{0, 0, 0}})));
  EXPECT_EQ(flipped_faces(inside_out, TriangleTree(sphere)), inside_out.n_faces());

  // A face-down grid just above a face-up one is turned over against it...
  const Mesh below = mesh_of(grid_soup(10, 1.0, 0.0));
  const Mesh down = mesh_of(reversed(grid_soup(10, 1.0, 0.004)));
  EXPECT_EQ(flipped_faces(down, TriangleTree(below)), down.n_faces());
  // ...unless the reference has a face-down layer close by (a thin sheet seen from both
  // sides): the nearest triangle is ambiguous there.
  const Mesh sheet = mesh_of(two_layers(grid_soup(10, 1.0, 0.0), reversed(grid_soup(10, 1.0, 0.01))));
  EXPECT_EQ(flipped_faces(down, TriangleTree(sheet)), 0u);
  const Mesh far_apart = mesh_of(two_layers(grid_soup(10, 1.0, 0.0), reversed(grid_soup(10, 1.0, 0.5))));
  EXPECT_EQ(flipped_faces(down, TriangleTree(far_apart)), down.n_faces());
}

}  // namespace hedge
