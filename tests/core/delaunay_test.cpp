// Tests of make_delaunay (delaunay.h): a bad diagonal gets flipped, a badly triangulated random
// point set becomes the Delaunay triangulation (empty circumcircles), features and seams stay,
// corner attributes follow their corners, real meshes end with no flippable bad edge.
#include "hedge/delaunay.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <map>
#include <numbers>
#include <random>
#include <utility>
#include <vector>

#include "hedge/build.h"
#include "hedge/catalogue.h"
#include "hedge/error.h"
#include "hedge/io.h"
#include "hedge/report.h"
#include "hedge/validate.h"
#include "test_meshes.h"

namespace {

using namespace hedge;
using test::make_mesh;

void expect_valid(const Mesh& mesh) {
  Validation v = validate(mesh);
  EXPECT_TRUE(v.ok) << v.message;
}

// Two triangles on the long diagonal of a flat rhombus: opposite angles ~152 degrees each.
Mesh rhombus(float lift = 0) {
  return make_mesh({{{0, 0, 0}}, {{4, 0, 0}}, {{2, 0.5f, 0}}, {{2, -0.5f, lift}}}, {{0, 1, 2}, {1, 0, 3}});
}

// Random points in the unit square, inserted one by one by splitting the triangle that holds
// them (1 -> 3, no flips): a valid but far from Delaunay triangulation.
Mesh random_points(int n, unsigned seed) {
  Mesh mesh = make_mesh({{{0, 0, 0}}, {{1, 0, 0}}, {{1, 1, 0}}, {{0, 1, 0}}}, {{0, 1, 2}, {0, 2, 3}});
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.02f, 0.98f);
  auto side = [](const Point& a, const Point& b, const Point& p) {
    return (double(b[0]) - a[0]) * (double(p[1]) - a[1]) - (double(b[1]) - a[1]) * (double(p[0]) - a[0]);
  };
  for (int i = 0; i < n; ++i) {
    const Point p{{u(rng), u(rng), 0}};
    for (Face f : mesh.faces()) {
      const Halfedge h = mesh.halfedge(f);
      const Point& a = mesh.position(mesh.to_vertex(h));
      const Point& b = mesh.position(mesh.to_vertex(mesh.next(h)));
      const Point& c = mesh.position(mesh.to_vertex(mesh.prev(h)));
      if (side(a, b, p) > 1e-9 && side(b, c, p) > 1e-9 && side(c, a, p) > 1e-9) {
        mesh.split_face(f, mesh.add_vertex(p));
        break;
      }
    }
  }
  return mesh;
}

// Every triangle's circumcircle holds no other vertex (global Delaunay, flat meshes).
std::size_t circumcircle_violations(const Mesh& mesh) {
  std::size_t bad = 0;
  for (Face f : mesh.faces()) {
    const Halfedge h = mesh.halfedge(f);
    const Vec3d a = to_double(mesh.position(mesh.to_vertex(h)));
    const Vec3d b = to_double(mesh.position(mesh.to_vertex(mesh.next(h))));
    const Vec3d c = to_double(mesh.position(mesh.to_vertex(mesh.prev(h))));
    const double d = 2 * (a[0] * (b[1] - c[1]) + b[0] * (c[1] - a[1]) + c[0] * (a[1] - b[1]));
    const double a2 = a[0] * a[0] + a[1] * a[1], b2 = b[0] * b[0] + b[1] * b[1], c2 = c[0] * c[0] + c[1] * c[1];
    const double x = (a2 * (b[1] - c[1]) + b2 * (c[1] - a[1]) + c2 * (a[1] - b[1])) / d;
    const double y = (a2 * (c[0] - b[0]) + b2 * (a[0] - c[0]) + c2 * (b[0] - a[0])) / d;
    const double r = std::hypot(a[0] - x, a[1] - y);
    for (Vertex v : mesh.vertices()) {
      const Point& p = mesh.position(v);
      if (std::hypot(p[0] - x, p[1] - y) < r * (1 - 1e-5)) ++bad;
    }
  }
  return bad;
}

TEST(Delaunay, FlatRhombusGetsItsShortDiagonal) {
  Mesh mesh = rhombus();
  const Edge e = mesh.find_edge(Vertex(0), Vertex(1));
  EXPECT_GT(opposite_angle_sum(mesh, e), std::numbers::pi);
  DelaunayReport r = make_delaunay(mesh);
  expect_valid(mesh);
  EXPECT_EQ(r.flips, 1u);
  EXPECT_EQ(r.before.non_delaunay, 1u);
  EXPECT_EQ(r.after.non_delaunay, 0u);
  EXPECT_FALSE(mesh.find_edge(Vertex(0), Vertex(1)).is_valid());
  EXPECT_TRUE(mesh.find_edge(Vertex(2), Vertex(3)).is_valid());
  EXPECT_NEAR(mesh_statistics(mesh).area, 2.0, 1e-6);
  // Running again changes nothing.
  EXPECT_EQ(make_delaunay(mesh).flips, 0u);
}

TEST(Delaunay, RandomPointSetBecomesDelaunay) {
  for (unsigned seed : {1u, 2u, 3u}) {
    Mesh mesh = random_points(400, seed);
    expect_valid(mesh);
    const std::size_t faces = mesh.n_faces();
    const std::size_t bad_before = circumcircle_violations(mesh);
    EXPECT_GT(bad_before, 0u);
    DelaunayReport r = make_delaunay(mesh);
    expect_valid(mesh);
    EXPECT_GT(r.flips, 0u);
    EXPECT_FALSE(r.budget_exhausted);
    EXPECT_EQ(mesh.n_faces(), faces);
    EXPECT_EQ(r.after.non_delaunay, 0u);
    for (Edge e : mesh.edges()) {
      if (!mesh.is_boundary(e)) {
        EXPECT_LE(opposite_angle_sum(mesh, e), std::numbers::pi + 1e-6);
      }
    }
    EXPECT_EQ(circumcircle_violations(mesh), 0u) << "seed " << seed;
    // Flips keep orientation: every triangle still faces +z.
    for (Face f : mesh.faces()) {
      const Halfedge h = mesh.halfedge(f);
      const Vec3d a = to_double(mesh.position(mesh.to_vertex(h)));
      const Vec3d b = to_double(mesh.position(mesh.to_vertex(mesh.next(h))));
      const Vec3d c = to_double(mesh.position(mesh.to_vertex(mesh.prev(h))));
      EXPECT_GT(cross(b - a, c - a)[2], 0);
    }
    EXPECT_NEAR(mesh_statistics(mesh).area, 1.0, 1e-5);
  }
}

TEST(Delaunay, CornerAttributesFollowTheirCorners) {
  Mesh mesh = random_points(200, 9);
  ChannelArray* uv = mesh.halfedge_properties().add_channel("uv", ScalarType::f32, 2);
  for (Halfedge h : mesh.halfedges())
    if (!mesh.is_boundary(h)) std::memcpy(uv->element(h.idx()), &mesh.position(mesh.to_vertex(h)), 2 * sizeof(float));
  DelaunayReport r = make_delaunay(mesh);
  EXPECT_GT(r.flips, 0u);
  EXPECT_EQ(r.after.non_delaunay, 0u);
  uv = mesh.halfedge_properties().get_channel("uv");
  for (Halfedge h : mesh.halfedges()) {
    if (mesh.is_boundary(h)) continue;
    float value[2];
    std::memcpy(value, uv->element(h.idx()), sizeof value);
    EXPECT_EQ(value[0], mesh.position(mesh.to_vertex(h))[0]);
    EXPECT_EQ(value[1], mesh.position(mesh.to_vertex(h))[1]);
  }
}

TEST(Delaunay, FeatureEdgesStay) {
  // The rhombus folded along its long diagonal by 45 degrees.
  Mesh mesh = rhombus(-0.5f);
  const Edge e = mesh.find_edge(Vertex(0), Vertex(1));
  EXPECT_GT(opposite_angle_sum(mesh, e), std::numbers::pi);
  EXPECT_NEAR(dihedral_angle_degrees(mesh, e), 45.0, 1e-4);
  DelaunayReport r = make_delaunay(mesh);
  EXPECT_EQ(r.flips, 0u);
  EXPECT_EQ(r.after.features, 1u);
  EXPECT_TRUE(mesh.find_edge(Vertex(0), Vertex(1)).is_valid());
  // With a larger feature angle the flip is allowed (the new edge bends by about 13 degrees).
  DelaunayOptions o;
  o.feature_angle = 90;
  r = make_delaunay(mesh, o);
  EXPECT_EQ(r.flips, 1u);
  expect_valid(mesh);
}

TEST(Delaunay, SeamsStay) {
  {
    Mesh mesh = rhombus();
    ChannelArray* uv = mesh.halfedge_properties().add_channel("uv", ScalarType::f32, 2);
    const float far[2] = {5, 5};
    std::memcpy(uv->element(mesh.find_halfedge(Vertex(1), Vertex(0)).idx()), far, sizeof far);  // corner at 0 in face 1
    DelaunayReport r = make_delaunay(mesh);
    EXPECT_EQ(r.flips, 0u);
    EXPECT_EQ(r.after.seams, 1u);
  }
  {
    Mesh mesh = rhombus();
    ChannelArray* material = mesh.face_properties().add_channel("material", ScalarType::i32, 1);
    const std::int32_t one = 1;
    std::memcpy(material->element(1), &one, sizeof one);
    EXPECT_EQ(make_delaunay(mesh).flips, 0u);
  }
}

TEST(Delaunay, FaceNormalsAreNotSeamsAndAreRecomputed) {
  Mesh mesh = rhombus(-0.2f);  // slightly bent: the two face normals differ
  ChannelArray* fn = mesh.face_properties().add_channel("normal", ScalarType::f32, 3);
  for (Face f : mesh.faces()) {
    const Halfedge h = mesh.halfedge(f);
    const Point& a = mesh.position(mesh.to_vertex(h));
    const Vec3f n = normalize(
        cross(mesh.position(mesh.to_vertex(mesh.next(h))) - a, mesh.position(mesh.to_vertex(mesh.prev(h))) - a));
    std::memcpy(fn->element(f.idx()), &n, sizeof n);
  }
  EXPECT_EQ(make_delaunay(mesh).flips, 1u);
  fn = mesh.face_properties().get_channel("normal");
  for (Face f : mesh.faces()) {
    const Halfedge h = mesh.halfedge(f);
    const Point& a = mesh.position(mesh.to_vertex(h));
    const Vec3f want = normalize(
        cross(mesh.position(mesh.to_vertex(mesh.next(h))) - a, mesh.position(mesh.to_vertex(mesh.prev(h))) - a));
    Vec3f n;
    std::memcpy(&n, fn->element(f.idx()), sizeof n);
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(n[k], want[k], 1e-6f);
  }
}

TEST(Delaunay, ExistingDiagonalBlocksTheFlip) {
  // A tetrahedron's faces are all there: flipping any edge would duplicate another.
  Mesh mesh =
      make_mesh({{{0, 0, 0}}, {{1, 0, 0}}, {{0, 1, 0}}, {{0, 0, 1}}}, {{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {0, 3, 2}});
  DelaunayOptions o;
  o.feature_angle = 180;
  DelaunayReport r = make_delaunay(mesh, o);
  EXPECT_EQ(r.flips, 0u);
  expect_valid(mesh);
}

TEST(Delaunay, RefusesPolygonsAndLeavesTheMesh) {
  Mesh mesh = make_mesh({{{0, 0, 0}}, {{1, 0, 0}}, {{1, 1, 0}}, {{0, 1, 0}}, {{2, 0, 0}}}, {{0, 1, 2, 3}, {1, 4, 2}});
  EXPECT_THROW(make_delaunay(mesh), Error);
  EXPECT_EQ(mesh.n_faces(), 2u);
  Mesh flat = random_points(50, 4);
  const Mesh before = flat;
  Progress cancel(
      [](double, const std::string& stage) { return stage != "flipping edges" && stage != "checking edges"; });
  EXPECT_THROW(make_delaunay(flat, {}, cancel), Cancelled);
  for (Halfedge h : flat.halfedges()) EXPECT_EQ(flat.to_vertex(h), before.to_vertex(h));
}

TEST(Delaunay, FlipBudgetIsReported) {
  Mesh mesh = random_points(300, 5);
  DelaunayOptions o;
  o.flip_budget_per_edge = 0.01;
  DelaunayReport r = make_delaunay(mesh, o);
  EXPECT_TRUE(r.budget_exhausted);
  EXPECT_GT(r.after.flippable, 0u);
  expect_valid(mesh);
}

TEST(Delaunay, CatalogueEntry) {
  const Operation& op = find_operation("make_delaunay");
  EXPECT_EQ(op.category, Category::cleaning);
  ASSERT_NE(op.find_param("feature_angle"), nullptr);
  EXPECT_EQ(op.find_param("feature_angle")->default_value, Value(30.0));
  EXPECT_EQ(op.find_param("feature_angle")->range.max, 180);
  Mesh mesh = random_points(100, 6);
  OperationReport r = op.run(mesh, resolve_params(op, std::map<std::string, std::string>{}), Progress::none());
  expect_valid(mesh);
  EXPECT_GT(std::get<std::int64_t>(*r.find("flips")), 0);
  EXPECT_EQ(std::get<std::int64_t>(*r.find("non_delaunay_after")), 0);
}

void real_mesh(const std::string& name) {
  const std::string path = std::string(HEDGE_MESH_DIR) + "/" + name;
  if (!std::filesystem::exists(path)) GTEST_SKIP() << name << " not found";
  Mesh mesh = build(read_mesh(path)).mesh;
  const std::size_t faces = mesh.n_faces();
  const MeshStatistics stats_before = mesh_statistics(mesh);
  const double area = stats_before.area;
  const auto start = std::chrono::steady_clock::now();
  const std::clock_t cpu = std::clock();
  DelaunayReport r = make_delaunay(mesh);
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  expect_valid(mesh);
  EXPECT_EQ(mesh.n_faces(), faces);
  EXPECT_FALSE(r.budget_exhausted);
  // Every edge left non-Delaunay has a reason: no flippable one remains.
  EXPECT_EQ(r.after.flippable, 0u);
  EXPECT_LT(r.after.non_delaunay, r.before.non_delaunay);
  EXPECT_EQ(delaunay_census(mesh).flippable, 0u);
  const MeshStatistics stats_after = mesh_statistics(mesh);
  EXPECT_NEAR(stats_after.area / area, 1.0, 0.01);
  EXPECT_GE(stats_after.mean_min_angle_degrees, stats_before.mean_min_angle_degrees);
  std::printf("[ figures  ] make_delaunay %s: mean smallest angle %.2f -> %.2f degrees, mean quality %.4f -> %.4f\n",
              name.c_str(), stats_before.mean_min_angle_degrees, stats_after.mean_min_angle_degrees,
              stats_before.quality_mean, stats_after.quality_mean);
  std::printf(
      "[ figures  ] make_delaunay %s (%zu faces): %zu flips, non-Delaunay edges %zu -> %zu (features %zu, seams %zu, "
      "blocked %zu, folds %zu), %.3f s wall, %.3f s CPU\n",
      name.c_str(), faces, r.flips, r.before.non_delaunay, r.after.non_delaunay, r.after.features, r.after.seams,
      r.after.blocked, r.after.folds, wall, double(std::clock() - cpu) / CLOCKS_PER_SEC);
}

TEST(Delaunay, Bunny) { real_mesh("bunny.off"); }
TEST(Delaunay, DragonRes4) { real_mesh("dragon_res4.ply"); }
TEST(Delaunay, Dragon) { real_mesh("dragon.ply"); }

}  // namespace
