// Tests of triangulate (triangulate.h): non-convex polygons are covered exactly by
// counter-clockwise triangles, counts, existing diagonals avoided, non-planar quads split along
// the smaller area, attributes kept per face, and faces of 10,000 and 100,000 corners.
#include "hedge/triangulate.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <map>
#include <numbers>
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

// One polygon face over the given points (in order).
Mesh polygon(const std::vector<Point>& points) {
  std::vector<Index> corners(points.size());
  for (Index i = 0; i < corners.size(); ++i) corners[i] = i;
  return make_mesh(points, {corners});
}

double shoelace(const std::vector<Point>& p) {
  double a = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const Point &u = p[i], &v = p[(i + 1) % p.size()];
    a += double(u[0]) * v[1] - double(v[0]) * u[1];
  }
  return 0.5 * a;
}

// Signed area of every triangle seen from +z: all must be positive (none flipped), and they
// must add up to the polygon's area (together with "none flipped": covering it exactly).
void expect_flat_cover(const Mesh& mesh, double area, double tolerance = 1e-6) {
  double sum = 0;
  for (Face f : mesh.faces()) {
    ASSERT_EQ(mesh.valence(f), 3u);
    const Halfedge h = mesh.halfedge(f);
    const Vec3d a = to_double(mesh.position(mesh.to_vertex(h)));
    const Vec3d b = to_double(mesh.position(mesh.to_vertex(mesh.next(h))));
    const Vec3d c = to_double(mesh.position(mesh.to_vertex(mesh.prev(h))));
    const double signed_area = 0.5 * cross(b - a, c - a)[2];
    EXPECT_GT(signed_area, 0) << "face " << f.idx() << " is flipped or degenerate";
    sum += signed_area;
  }
  EXPECT_NEAR(sum, area, tolerance * std::max(1.0, area));
}

void expect_valid(const Mesh& mesh) {
  Validation v = validate(mesh);
  EXPECT_TRUE(v.ok) << v.message;
}

TriangulateOptions method(TriangulationMethod m) {
  TriangulateOptions o;
  o.method = m;
  return o;
}

const TriangulationMethod kMethods[] = {TriangulationMethod::min_area, TriangulationMethod::ear_clipping};

std::vector<Point> star(int tips, float inner, float outer, float z = 0) {
  std::vector<Point> p;
  for (int i = 0; i < 2 * tips; ++i) {
    const double t = std::numbers::pi * i / tips;
    const float r = i % 2 ? inner : outer;
    p.push_back({{r * float(std::cos(t)), r * float(std::sin(t)), z}});
  }
  return p;
}

TEST(Triangulate, LShapedHexagon) {
  const std::vector<Point> l = {{{0, 0, 0}}, {{2, 0, 0}}, {{2, 1, 0}}, {{1, 1, 0}}, {{1, 2, 0}}, {{0, 2, 0}}};
  for (auto m : kMethods) {
    for (std::size_t start = 0; start < l.size(); ++start) {  // the reflex corner at every position
      std::vector<Point> rotated(l.begin() + start, l.end());
      rotated.insert(rotated.end(), l.begin(), l.begin() + start);
      Mesh mesh = polygon(rotated);
      TriangulateReport r = triangulate(mesh, method(m));
      expect_valid(mesh);
      EXPECT_EQ(r.polygons, 1u);
      EXPECT_EQ(r.triangles, 4u);
      EXPECT_EQ(r.relaxed, 0u);
      EXPECT_EQ(mesh.n_faces(), 4u);
      expect_flat_cover(mesh, 3.0);
    }
  }
}

TEST(Triangulate, StarShapedPolygons) {
  for (auto m : kMethods)
    for (int tips : {3, 5, 12, 40}) {
      const std::vector<Point> p = star(tips, 0.3f, 1.0f, 2.0f);
      Mesh mesh = polygon(p);
      TriangulateReport r = triangulate(mesh, method(m));
      expect_valid(mesh);
      EXPECT_EQ(mesh.n_faces(), std::size_t(2 * tips - 2)) << triangulation_method_name(m);
      EXPECT_EQ(r.relaxed + r.centroid_vertices, 0u);
      expect_flat_cover(mesh, shoelace(p), 1e-5);
    }
}

TEST(Triangulate, CountsOnMixedPolygons) {
  // A cube whose faces are a quad, pentagons, a hexagon (extra corners on the edges, where
  // three corners are collinear), and a triangle-free closed surface.
  Mesh mesh =
      make_mesh({{{0, 0, 0}},
                 {{1, 0, 0}},
                 {{1, 1, 0}},
                 {{0, 1, 0}},
                 {{0, 0, 1}},
                 {{1, 0, 1}},
                 {{1, 1, 1}},
                 {{0, 1, 1}},
                 {{0.5f, 0, 0}},
                 {{0.5f, 0, 1}}},
                {{0, 3, 2, 1, 8}, {0, 8, 1, 5, 9, 4}, {1, 2, 6, 5}, {2, 3, 7, 6}, {3, 0, 4, 7}, {4, 9, 5, 6, 7}});
  ASSERT_TRUE(validate(mesh).ok);
  for (auto m : kMethods) {
    Mesh copy = mesh;
    TriangulateReport r = triangulate(copy, method(m));
    expect_valid(copy);
    EXPECT_EQ(r.polygons, 6u);
    EXPECT_EQ(r.triangles, 3u + 4 + 2 + 2 + 2 + 3);  // n - 2 each
    EXPECT_EQ(copy.n_faces(), 16u);
    EXPECT_TRUE(copy.is_triangle_mesh());
    const MeshStatistics s = mesh_statistics(copy);
    EXPECT_NEAR(s.area, 6.0, 1e-5);
    EXPECT_NEAR(s.volume, 1.0, 1e-5);
    EXPECT_EQ(s.degenerate_faces, 0u) << triangulation_method_name(m);  // no triangle on the collinear corners
    EXPECT_EQ(s.multi_edges, 0u);
  }
}

TEST(Triangulate, AvoidsADiagonalThatExists) {
  // A flat pillow: the bottom quad 0 3 2 1 and two top triangles sharing the edge 0-2, so the
  // quad must take the diagonal 1-3 whatever its shape prefers.
  for (auto m : kMethods) {
    Mesh mesh = make_mesh({{{0, 0, 0}}, {{3, 0, 0}}, {{3, 1, 0}}, {{0, 1, 0}}}, {{0, 3, 2, 1}, {0, 1, 2}, {0, 2, 3}});
    ASSERT_TRUE(validate(mesh).ok);
    TriangulateReport r = triangulate(mesh, method(m));
    expect_valid(mesh);
    EXPECT_EQ(mesh.n_faces(), 4u);
    EXPECT_TRUE(mesh.find_edge(Vertex(1), Vertex(3)).is_valid());
    EXPECT_EQ(mesh_statistics(mesh).multi_edges, 0u);
    EXPECT_EQ(r.centroid_vertices, 0u);
  }
}

TEST(Triangulate, NonPlanarQuadTakesTheSmallerArea) {
  // Diagonal A-C gives area 1.414, B-D gives 1.366.
  Mesh mesh = polygon({{{0, 0, 0}}, {{1, 0, 0}}, {{1, 1, 1}}, {{0, 1, 0}}});
  triangulate(mesh, method(TriangulationMethod::min_area));
  expect_valid(mesh);
  EXPECT_TRUE(mesh.find_edge(Vertex(1), Vertex(3)).is_valid());
  EXPECT_NEAR(mesh_statistics(mesh).area, 0.5 + std::sqrt(3.0) / 2, 1e-6);
}

TEST(Triangulate, MinAreaPrefersWellShapedTrianglesOnPlanarPolygons) {
  // A 3 x 1 rectangle with extra corners along its long sides: all triangulations have the same
  // area; the best-shaped one cuts it into unit squares (45 degree triangles) and none uses
  // three collinear corners.
  Mesh strip =
      polygon({{{0, 0, 0}}, {{1, 0, 0}}, {{2, 0, 0}}, {{3, 0, 0}}, {{3, 1, 0}}, {{2, 1, 0}}, {{1, 1, 0}}, {{0, 1, 0}}});
  triangulate(strip, method(TriangulationMethod::min_area));
  expect_valid(strip);
  const MeshStatistics s = mesh_statistics(strip);
  EXPECT_EQ(s.degenerate_faces, 0u);
  EXPECT_NEAR(s.min_angle_degrees, 45.0, 1e-3);
  expect_flat_cover(strip, 3.0);
}

TEST(Triangulate, CornerAndFaceAttributesStayWithTheirPolygon) {
  // Two polygons (an L and a square) side by side, each with its own UV chart and material.
  Mesh mesh = make_mesh(
      {{{0, 0, 0}}, {{2, 0, 0}}, {{2, 1, 0}}, {{1, 1, 0}}, {{1, 2, 0}}, {{0, 2, 0}}, {{3, 0, 0}}, {{3, 1, 0}}},
      {{0, 1, 2, 3, 4, 5}, {1, 6, 7, 2}});
  ChannelArray* uv = mesh.halfedge_properties().add_channel("uv", ScalarType::f32, 2);
  ChannelArray* material = mesh.face_properties().add_channel("material", ScalarType::i32, 1);
  for (Face f : mesh.faces()) {
    const std::int32_t id = 7 + std::int32_t(f.idx());
    std::memcpy(material->element(f.idx()), &id, sizeof id);
    for (Halfedge h : mesh.halfedges(f)) {
      const Point& p = mesh.position(mesh.to_vertex(h));
      const float value[2] = {p[0] + 100.0f * float(f.idx()), p[1]};
      std::memcpy(uv->element(h.idx()), value, sizeof value);
    }
  }
  for (auto m : kMethods) {
    Mesh copy = mesh;
    triangulate(copy, method(m));
    expect_valid(copy);
    uv = copy.halfedge_properties().get_channel("uv");
    material = copy.face_properties().get_channel("material");
    std::map<std::int32_t, int> per_material;
    for (Face f : copy.faces()) {
      std::int32_t id;
      std::memcpy(&id, material->element(f.idx()), sizeof id);
      ++per_material[id];
      for (Halfedge h : copy.halfedges(f)) {
        float value[2];
        std::memcpy(value, uv->element(h.idx()), sizeof value);
        const Point& p = copy.position(copy.to_vertex(h));
        EXPECT_EQ(value[0], p[0] + 100.0f * float(id - 7));
        EXPECT_EQ(value[1], p[1]);
      }
    }
    EXPECT_EQ(per_material[7], 4);
    EXPECT_EQ(per_material[8], 2);
  }
}

// A comb: a long base with `teeth` thin rectangular teeth, every one a non-convex pocket
// (2 + 5 teeth corners; integer and half coordinates, so the geometry is exact).
std::vector<Point> comb(int teeth) {
  std::vector<Point> p;
  p.push_back({{0, 0, 0}});
  p.push_back({{float(2 * teeth), 0, 0}});
  for (int i = teeth - 1; i >= 0; --i) {
    const float x = float(2 * i);
    p.push_back({{x + 2, 1, 0}});
    p.push_back({{x + 1.5f, 1, 0}});
    p.push_back({{x + 1.5f, 5, 0}});
    p.push_back({{x + 0.5f, 5, 0}});
    p.push_back({{x + 0.5f, 1, 0}});
  }
  return p;
}

// A saw: a straight base and a top edge of n teeth (2 + n + 1 corners).
std::vector<Point> saw(int n) {
  std::vector<Point> p = {{{0, 0, 0}}, {{float(n), 0, 0}}};
  for (int x = n; x >= 0; --x) p.push_back({{float(x), float(1 + x % 2), 0}});
  return p;
}

TEST(Triangulate, HugePolygonsFinishQuickly) {
  // Shapes whose corners are not nearly collinear in float precision (a 100,000-gon on a circle
  // is: its consecutive corners turn by less than float rounding, so no method can promise
  // positive slivers there).
  struct Case {
    const char* name;
    std::vector<Point> points;
  };
  const std::vector<Case> cases = {{"star, 10,000 corners", star(5000, 0.5f, 1.0f)},
                                   {"comb, 10,002 corners", comb(2000)},
                                   {"saw, 100,002 corners", saw(99999)},
                                   {"comb, 100,002 corners", comb(20000)}};
  for (const Case& c : cases) {
    for (auto m : kMethods) {
      Mesh mesh = polygon(c.points);
      const auto start = std::chrono::steady_clock::now();
      TriangulateReport r = triangulate(mesh, method(m));
      const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      std::printf("[ figures  ] triangulate %s (%s): %.3f s\n", c.name, triangulation_method_name(m), seconds);
      EXPECT_EQ(r.ear_clipped, 1u);  // min_area hands polygons above 100 corners to ear clipping
      EXPECT_EQ(mesh.n_faces(), c.points.size() - 2);
      EXPECT_EQ(r.relaxed + r.centroid_vertices, 0u) << c.name;
      expect_valid(mesh);
      expect_flat_cover(mesh, shoelace(c.points), 1e-6);
    }
  }
}

TEST(Triangulate, TrianglesOnlyMeshIsLeftAlone) {
  Mesh mesh = make_mesh({{{0, 0, 0}}, {{1, 0, 0}}, {{0, 1, 0}}}, {{0, 1, 2}});
  TriangulateReport r = triangulate(mesh, {});
  EXPECT_EQ(r.polygons, 0u);
  EXPECT_EQ(mesh.n_faces(), 1u);
}

TEST(Triangulate, CancellingLeavesTheMesh) {
  Mesh mesh = polygon(star(10, 0.4f, 1.0f));
  Progress cancel([](double, const std::string&) { return false; });
  EXPECT_THROW(triangulate(mesh, {}, cancel), Cancelled);
  EXPECT_EQ(mesh.n_faces(), 1u);
  EXPECT_EQ(mesh.valence(Face(0)), 20u);
}

TEST(Triangulate, CatalogueEntry) {
  const Operation& op = find_operation("triangulate");
  EXPECT_EQ(op.find_param("method")->choices, (std::vector<std::string>{"min_area", "ear_clipping"}));
  EXPECT_EQ(op.find_param("method")->default_value, Value(std::string("min_area")));
  Mesh mesh = polygon(star(6, 0.4f, 1.0f));
  OperationReport r = op.run(mesh, resolve_params(op, std::map<std::string, std::string>{}), Progress::none());
  expect_valid(mesh);
  EXPECT_EQ(std::get<std::int64_t>(*r.find("triangles")), 10);
}

TEST(Triangulate, CatmullClarkDragonQuads) {
  const std::string path = std::string(HEDGE_MESH_DIR) + "/dragon_res2.ply";
  if (!std::filesystem::exists(path)) GTEST_SKIP() << "dragon_res2.ply not found";
  Mesh quads = build(read_mesh(path)).mesh;
  SubdivideOptions cc;
  cc.scheme = SubdivisionScheme::catmull_clark;
  subdivide(quads, cc);
  ASSERT_TRUE(quads.is_quad_mesh());
  const double area = mesh_statistics(quads).area;
  for (auto m : kMethods) {
    Mesh mesh = quads;
    const auto start = std::chrono::steady_clock::now();
    const std::clock_t cpu = std::clock();
    TriangulateReport r = triangulate(mesh, method(m));
    std::printf("[ figures  ] triangulate %zu quads (%s): %.3f s wall, %.3f s CPU\n", quads.n_faces(),
                triangulation_method_name(m),
                std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(),
                double(std::clock() - cpu) / CLOCKS_PER_SEC);
    expect_valid(mesh);
    EXPECT_EQ(mesh.n_faces(), 2 * quads.n_faces());
    EXPECT_EQ(r.centroid_vertices, 0u);
    // Non-planar quads: min_area may only lower the area.
    const double after = mesh_statistics(mesh).area;
    EXPECT_NEAR(after / area, 1.0, 0.01);
  }
}

}  // namespace
