// Tests of smooth (smooth.h): noise goes down, uniform shrinks and Taubin does not, boundaries
// stay or slide along themselves, cotangent weights keep flat meshes flat and in place.
#include "hedge/smooth.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <map>
#include <random>
#include <utility>
#include <vector>

#include "hedge/build.h"
#include "hedge/catalogue.h"
#include "hedge/error.h"
#include "hedge/io.h"
#include "hedge/report.h"
#include "hedge/subdivide.h"
#include "hedge/validate.h"
#include "test_meshes.h"

namespace {

using namespace hedge;
using test::make_mesh;

// Unit sphere: an icosahedron refined `levels` times at the midpoints, projected outward.
Mesh sphere(int levels) {
  const float t = (1.0f + std::sqrt(5.0f)) / 2.0f;
  Mesh mesh = make_mesh({{{-1, t, 0}},
                         {{1, t, 0}},
                         {{-1, -t, 0}},
                         {{1, -t, 0}},
                         {{0, -1, t}},
                         {{0, 1, t}},
                         {{0, -1, -t}},
                         {{0, 1, -t}},
                         {{t, 0, -1}},
                         {{t, 0, 1}},
                         {{-t, 0, -1}},
                         {{-t, 0, 1}}},
                        {{0, 11, 5},  {0, 5, 1},  {0, 1, 7},  {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                         {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
                         {3, 8, 9},   {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}});
  SubdivideOptions o;
  o.scheme = SubdivisionScheme::midpoint;
  o.iterations = levels;
  subdivide(mesh, o);
  for (Point& p : mesh.positions()) p = normalize(p);
  return mesh;
}

// Moves every vertex along its radius by a seeded random amount in [-a, a].
void add_radial_noise(Mesh& mesh, float a, unsigned seed = 7) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-a, a);
  for (Point& p : mesh.positions()) p = p * (1.0f + u(rng));
}

// Sum over interior vertices of |mean of neighbours - vertex|: a roughness measure.
double roughness(const Mesh& mesh) {
  double sum = 0;
  for (Vertex v : mesh.vertices()) {
    if (mesh.is_boundary(v)) continue;
    Vec3d mean{};
    double n = 0;
    for (Vertex w : mesh.vertices(v)) {
      mean += to_double(mesh.position(w));
      n += 1;
    }
    sum += norm(mean / n - to_double(mesh.position(v)));
  }
  return sum;
}

// Relative spread of the distances to the origin: the noise of a noisy sphere.
double radius_spread(const Mesh& mesh) {
  double sum = 0, sum2 = 0, n = 0;
  for (Vertex v : mesh.vertices()) {
    const double r = norm(to_double(mesh.position(v)));
    sum += r;
    sum2 += r * r;
    n += 1;
  }
  const double mean = sum / n;
  return std::sqrt(std::max(0.0, sum2 / n - mean * mean)) / mean;
}

Mesh grid(int n, float noise, unsigned seed = 3) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-noise, noise);
  std::vector<Point> p;
  std::vector<std::vector<Index>> f;
  for (int y = 0; y <= n; ++y)
    for (int x = 0; x <= n; ++x) {
      const bool border = x == 0 || y == 0 || x == n || y == n;
      p.push_back({{float(x), float(y), border ? 0.0f : u(rng)}});
    }
  auto id = [&](int x, int y) { return Index(y * (n + 1) + x); };
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      f.push_back({id(x, y), id(x + 1, y), id(x + 1, y + 1)});
      f.push_back({id(x, y), id(x + 1, y + 1), id(x, y + 1)});
    }
  return make_mesh(p, f);
}

SmoothOptions method(SmoothingMethod m, int iterations = 10, double strength = 0.5) {
  SmoothOptions o;
  o.method = m;
  o.iterations = iterations;
  o.strength = strength;
  return o;
}

void expect_valid(const Mesh& mesh) {
  Validation v = validate(mesh);
  EXPECT_TRUE(v.ok) << v.message;
}

TEST(Smooth, AllMethodsReduceNoiseOnASphere) {
  Mesh noisy = sphere(3);
  add_radial_noise(noisy, 0.03f);
  // Roughness also counts the sphere's own curvature, so it cannot drop to zero; the spread of
  // the radii is the noise alone.
  const double before = roughness(noisy), spread = radius_spread(noisy);
  for (auto m : {SmoothingMethod::uniform, SmoothingMethod::cotangent, SmoothingMethod::taubin}) {
    Mesh mesh = noisy;
    SmoothReport r = smooth(mesh, method(m));
    expect_valid(mesh);
    EXPECT_LT(roughness(mesh), 0.7 * before) << smoothing_method_name(m);
    EXPECT_LT(radius_spread(mesh), 0.4 * spread) << smoothing_method_name(m);
    EXPECT_EQ(r.moved_vertices, mesh.n_vertices());
    EXPECT_GT(r.mean_displacement, 0);
  }
}

TEST(Smooth, TaubinKeepsTheVolumeAndUniformShrinks) {
  Mesh noisy = sphere(3);
  add_radial_noise(noisy, 0.03f);
  const double volume = mesh_statistics(noisy).volume;
  ASSERT_GT(volume, 4.0);  // about 4/3 pi

  Mesh taubin = noisy;
  SmoothReport r = smooth(taubin, method(SmoothingMethod::taubin));
  const double taubin_volume = mesh_statistics(taubin).volume;
  EXPECT_NEAR(taubin_volume / volume, 1.0, 0.01);
  EXPECT_NEAR(r.mu, -0.5 / (1 - 0.1 * 0.5), 1e-12);

  Mesh uniform = noisy;
  smooth(uniform, method(SmoothingMethod::uniform));
  const double uniform_volume = mesh_statistics(uniform).volume;
  EXPECT_LT(uniform_volume / volume, 0.95);  // measurably smaller
  std::printf("[ figures  ] volume after 10 steps, lambda 0.5: uniform %.2f %%, taubin %.2f %% of the noisy sphere's\n",
              100 * uniform_volume / volume, 100 * taubin_volume / volume);
}

TEST(Smooth, TaubinStrengthIsLimitedForStability) {
  // Unlimited, λ = 1 gives μ = -1.11 and the highest frequencies grow by 3x per iteration.
  Mesh mesh = sphere(3);
  add_radial_noise(mesh, 0.05f);
  const double spread = radius_spread(mesh);
  SmoothReport r = smooth(mesh, method(SmoothingMethod::taubin, 100, 1.0));
  EXPECT_FALSE(r.message.empty());
  EXPECT_LE(r.lambda, 0.69);
  for (const Point& p : mesh.positions())
    for (int i = 0; i < 3; ++i) ASSERT_TRUE(std::isfinite(p[i]));
  EXPECT_LT(radius_spread(mesh), 0.25 * spread);
}

TEST(Smooth, BoundaryStaysFixedWhenPreserved) {
  Mesh before = grid(8, 0.3f);
  for (auto m : {SmoothingMethod::uniform, SmoothingMethod::cotangent, SmoothingMethod::taubin}) {
    Mesh mesh = before;
    SmoothReport r = smooth(mesh, method(m, 20));
    expect_valid(mesh);
    EXPECT_EQ(r.moved_vertices, 7u * 7u);
    for (Vertex v : mesh.vertices())
      if (mesh.is_boundary(v)) {
        EXPECT_EQ(mesh.position(v), before.position(v)) << smoothing_method_name(m);
      }
    EXPECT_LT(roughness(mesh), 0.5 * roughness(before)) << smoothing_method_name(m);
  }
}

TEST(Smooth, FreeBoundarySlidesAlongItself) {
  // The interior is noisy in z, the boundary is flat: a boundary vertex only listens to its two
  // boundary neighbours, so it never leaves the plane.
  Mesh before = grid(8, 0.3f);
  Mesh mesh = before;
  SmoothOptions o = method(SmoothingMethod::uniform, 20);
  o.preserve_boundary = false;
  SmoothReport r = smooth(mesh, o);
  expect_valid(mesh);
  EXPECT_EQ(r.moved_vertices, mesh.n_vertices());
  for (Vertex v : mesh.vertices())
    if (mesh.is_boundary(v)) {
      EXPECT_EQ(mesh.position(v)[2], 0.0f);
    }
  // One step: a vertex on a straight side stays on it; the corner (0, 0) goes half way to the
  // mean of (1, 0) and (0, 1).
  mesh = before;
  o.iterations = 1;
  smooth(mesh, o);
  for (Vertex v : mesh.vertices()) {
    const Point &p0 = before.position(v), &p = mesh.position(v);
    if (!mesh.is_boundary(v) || p0[0] == 0 || p0[0] == 8) continue;  // corners are cut
    if (p0[1] == 0) {
      EXPECT_EQ(p[1], 0.0f) << v.idx();
    }
  }
  EXPECT_EQ(mesh.position(Vertex(0)), (Point{{0.25f, 0.25f, 0}}));
}

TEST(Smooth, CotangentKeepsAFlatIrregularMeshInPlace) {
  // A jittered flat triangular lattice (angles near 60 degrees, so no weight is clamped):
  // cotangent weights reproduce linear functions, so interior vertices do not move, while the
  // uniform mean drags them around.
  const int n = 10;
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(-0.1f, 0.1f);
  std::vector<Point> p;
  std::vector<std::vector<Index>> f;
  for (int y = 0; y <= n; ++y)
    for (int x = 0; x <= n; ++x) {
      const bool border = x == 0 || y == 0 || x == n || y == n;
      const float jx = border ? 0 : u(rng), jy = border ? 0 : u(rng);
      p.push_back({{float(x) + 0.5f * float(y % 2) + jx, float(y) * 0.8660254f + jy, 0}});
    }
  auto id = [&](int x, int y) { return Index(y * (n + 1) + x); };
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      if (y % 2 == 0) {
        f.push_back({id(x, y), id(x + 1, y), id(x, y + 1)});
        f.push_back({id(x + 1, y), id(x + 1, y + 1), id(x, y + 1)});
      } else {
        f.push_back({id(x, y), id(x + 1, y), id(x + 1, y + 1)});
        f.push_back({id(x, y), id(x + 1, y + 1), id(x, y + 1)});
      }
    }
  Mesh mesh = make_mesh(p, f);
  ASSERT_TRUE(validate(mesh).ok);
  Mesh cot = mesh, uniform = mesh;
  smooth(cot, method(SmoothingMethod::cotangent, 10));
  smooth(uniform, method(SmoothingMethod::uniform, 10));
  double cot_drift = 0, uniform_drift = 0;
  for (Vertex v : mesh.vertices()) {
    cot_drift = std::max(cot_drift, double(distance(cot.position(v), mesh.position(v))));
    uniform_drift = std::max(uniform_drift, double(distance(uniform.position(v), mesh.position(v))));
  }
  EXPECT_LT(cot_drift, 1e-4);
  EXPECT_GT(uniform_drift, 0.02);
}

TEST(Smooth, CotangentHandlesPolygonsAndDegenerateTriangles) {
  // A flat quad grid with one collapsed (zero-area) triangle glued on: weights stay finite.
  Mesh mesh = make_mesh({{{0, 0, 0}},
                         {{1, 0, 0}},
                         {{2, 0, 0}},
                         {{0, 1, 0}},
                         {{1, 1, 0.5f}},
                         {{2, 1, 0}},
                         {{0, 2, 0}},
                         {{1, 2, 0}},
                         {{2, 2, 0}},
                         {{3, 2, 0}}},
                        {{0, 1, 4, 3}, {1, 2, 5, 4}, {3, 4, 7, 6}, {4, 5, 8, 7}, {5, 9, 8}});
  mesh.position(Vertex(9)) = mesh.position(Vertex(8));
  SmoothOptions o = method(SmoothingMethod::cotangent, 5);
  smooth(mesh, o);
  expect_valid(mesh);
  for (const Point& p : mesh.positions())
    for (int i = 0; i < 3; ++i) EXPECT_TRUE(std::isfinite(p[i]));
  EXPECT_LT(mesh.position(Vertex(4))[2], 0.5f);  // the bump went down
}

TEST(Smooth, KeepsConnectivityAndAttributes) {
  Mesh mesh = sphere(2);
  add_radial_noise(mesh, 0.05f);
  ChannelArray* color = mesh.vertex_properties().add_channel("color", ScalarType::u8, 4);
  for (std::size_t i = 0; i < color->bytes().size(); ++i) color->bytes()[i] = std::byte(i * 7);
  ChannelArray* uv = mesh.halfedge_properties().add_channel("uv", ScalarType::f32, 2);
  for (std::size_t i = 0; i < uv->bytes().size(); ++i) uv->bytes()[i] = std::byte(i * 3);
  const Mesh before = mesh;
  smooth(mesh, method(SmoothingMethod::cotangent, 3));
  expect_valid(mesh);
  ASSERT_EQ(mesh.n_halfedges(), before.n_halfedges());
  for (Halfedge h : mesh.halfedges()) {
    EXPECT_EQ(mesh.to_vertex(h), before.to_vertex(h));
    EXPECT_EQ(mesh.next(h), before.next(h));
  }
  EXPECT_EQ(mesh.vertex_properties().get_channel("color")->bytes(),
            before.vertex_properties().get_channel("color")->bytes());
  EXPECT_EQ(mesh.halfedge_properties().get_channel("uv")->bytes(),
            before.halfedge_properties().get_channel("uv")->bytes());
}

TEST(Smooth, RecomputesNormalChannels) {
  Mesh mesh = sphere(3);
  add_radial_noise(mesh, 0.03f);
  ChannelArray* vn = mesh.vertex_properties().add_channel("normal", ScalarType::f32, 3);
  ChannelArray* fn = mesh.face_properties().add_channel("normal", ScalarType::f32, 3);
  smooth(mesh, method(SmoothingMethod::taubin, 10));
  vn = mesh.vertex_properties().get_channel("normal");
  fn = mesh.face_properties().get_channel("normal");
  double worst = 1;
  for (Vertex v : mesh.vertices()) {
    Vec3f n;
    std::memcpy(&n, vn->element(v.idx()), sizeof n);
    EXPECT_NEAR(norm(n), 1.0f, 1e-5f);
    worst = std::min(worst, double(dot(n, normalize(mesh.position(v)))));  // a smooth sphere: radial
  }
  EXPECT_GT(worst, 0.98);
  for (Face f : mesh.faces()) {
    Vec3f n;
    std::memcpy(&n, fn->element(f.idx()), sizeof n);
    EXPECT_NEAR(norm(n), 1.0f, 1e-5f);
  }
}

TEST(Smooth, RefusalsAndCancellationLeaveTheMesh) {
  Mesh mesh = sphere(1);
  add_radial_noise(mesh, 0.05f);
  const std::vector<Point> before = mesh.positions();
  EXPECT_THROW(smooth(mesh, method(SmoothingMethod::uniform, 0)), Error);
  EXPECT_THROW(smooth(mesh, method(SmoothingMethod::uniform, 10, 0.0)), Error);
  EXPECT_THROW(smooth(mesh, method(SmoothingMethod::uniform, 10, 1.5)), Error);
  Progress cancel([](double fraction, const std::string&) { return fraction < 0.5; });
  EXPECT_THROW(smooth(mesh, method(SmoothingMethod::taubin, 10), cancel), Cancelled);
  EXPECT_EQ(mesh.positions(), before);
}

TEST(Smooth, SkipsDeletedAndIsolatedVertices) {
  Mesh mesh = grid(4, 0.2f);
  mesh.delete_face(Face(10));  // an inner face: a hole, every vertex stays manifold
  const Vertex lone = mesh.new_vertex();
  mesh.position(lone) = Point{{9, 9, 9}};
  smooth(mesh, method(SmoothingMethod::cotangent, 5));
  EXPECT_EQ(mesh.position(lone), (Point{{9, 9, 9}}));
  mesh.garbage_collect();
  expect_valid(mesh);
}

TEST(Smooth, CatalogueEntry) {
  const Operation& op = find_operation("smooth");
  EXPECT_EQ(op.category, Category::smoothing);
  EXPECT_EQ(op.find_param("method")->choices, (std::vector<std::string>{"uniform", "cotangent", "taubin"}));
  EXPECT_EQ(op.find_param("method")->default_value, Value(std::string("uniform")));
  EXPECT_EQ(op.find_param("iterations")->default_value, Value(std::int64_t(10)));
  EXPECT_EQ(op.find_param("iterations")->range.max, 1000);
  EXPECT_EQ(op.find_param("strength")->default_value, Value(0.5));
  EXPECT_EQ(op.find_param("preserve_boundary")->default_value, Value(true));
  Mesh mesh = sphere(2);
  add_radial_noise(mesh, 0.05f);
  OperationReport r =
      op.run(mesh, resolve_params(op, std::map<std::string, std::string>{{"method", "taubin"}, {"iterations", "5"}}),
             Progress::none());
  expect_valid(mesh);
  ASSERT_NE(r.find("mu"), nullptr);
}

TEST(Smooth, CataloguePassBandReachesTaubin) {
  const Operation& op = find_operation("smooth");
  EXPECT_EQ(op.find_param("pass_band")->default_value, Value(0.1));
  EXPECT_EQ(op.find_param("pass_band")->range.max, 0.5);
  Mesh mesh = sphere(2);
  add_radial_noise(mesh, 0.05f);
  OperationReport r = op.run(
      mesh,
      resolve_params(
          op, std::map<std::string, std::string>{{"method", "taubin"}, {"strength", "0.5"}, {"pass_band", "0.2"}}),
      Progress::none());
  ASSERT_NE(r.find("mu"), nullptr);
  EXPECT_NEAR(std::get<double>(*r.find("mu")), -0.5 / (1 - 0.2 * 0.5), 1e-12);
  EXPECT_THROW(resolve_params(op, std::map<std::string, std::string>{{"pass_band", "0.9"}}), Error);
}

TEST(Smooth, DragonTimings) {
  const std::string path = std::string(HEDGE_MESH_DIR) + "/dragon.ply";
  if (!std::filesystem::exists(path)) GTEST_SKIP() << "dragon.ply not found";
  const Mesh dragon = build(read_mesh(path)).mesh;
  for (auto m : {SmoothingMethod::uniform, SmoothingMethod::cotangent, SmoothingMethod::taubin}) {
    Mesh mesh = dragon;
    const auto start = std::chrono::steady_clock::now();
    const std::clock_t cpu = std::clock();
    smooth(mesh, method(m, 10));
    std::printf("[ figures  ] smooth %s, 10 iterations on the dragon (%zu vertices): %.3f s wall, %.3f s CPU\n",
                smoothing_method_name(m), dragon.n_vertices(),
                std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(),
                double(std::clock() - cpu) / CLOCKS_PER_SEC);
    expect_valid(mesh);
  }
}

}  // namespace
