// Tests of face and vertex normals (normals.h): vector areas, orientation, area weighting,
// polygons, deleted and isolated elements.
#include "hedge/normals.h"

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <utility>
#include <vector>

#include "hedge/error.h"
#include "hedge/validate.h"
#include "test_meshes.h"

namespace {

using namespace hedge;
using test::make_mesh;

void expect_near(const Vec3f& a, const Vec3f& b, float tolerance = 1e-6f) {
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(a[i], b[i], tolerance) << "component " << i;
}

// Unit cube, outward quads; the top face is split into two triangles when `mixed`.
Mesh cube(bool mixed) {
  std::vector<Point> p = {{{0, 0, 0}}, {{1, 0, 0}}, {{1, 1, 0}}, {{0, 1, 0}},
                          {{0, 0, 1}}, {{1, 0, 1}}, {{1, 1, 1}}, {{0, 1, 1}}};
  std::vector<std::vector<Index>> f = {{0, 3, 2, 1}, {0, 1, 5, 4}, {1, 2, 6, 5}, {2, 3, 7, 6}, {3, 0, 4, 7}};
  if (mixed) {
    f.push_back({4, 5, 6});
    f.push_back({4, 6, 7});
  } else {
    f.push_back({4, 5, 6, 7});
  }
  return make_mesh(p, f);
}

TEST(Normals, TriangleAreaVectorAndOrientation) {
  Mesh mesh = make_mesh({{{0, 0, 0}}, {{2, 0, 0}}, {{0, 2, 0}}}, {{0, 1, 2}});
  ASSERT_TRUE(validate(mesh)) << validate(mesh).message;
  expect_near(face_area_vector(mesh, Face(0)), {{0, 0, 2}});
  expect_near(face_normal(mesh, Face(0)), {{0, 0, 1}});
  Mesh reversed = make_mesh({{{0, 0, 0}}, {{2, 0, 0}}, {{0, 2, 0}}}, {{0, 2, 1}});
  expect_near(face_normal(reversed, Face(0)), {{0, 0, -1}});
}

TEST(Normals, NonConvexPolygonUsesItsTrueArea) {
  // An L-shaped hexagon of area 3 in the plane z = 5, far from the origin.
  Mesh mesh =
      make_mesh({{{0, 0, 5}}, {{2, 0, 5}}, {{2, 1, 5}}, {{1, 1, 5}}, {{1, 2, 5}}, {{0, 2, 5}}}, {{0, 1, 2, 3, 4, 5}});
  ASSERT_TRUE(validate(mesh)) << validate(mesh).message;
  expect_near(face_area_vector(mesh, Face(0)), {{0, 0, 3}});
  // Starting the fan at the reflex corner gives the same result.
  Mesh rotated =
      make_mesh({{{0, 0, 5}}, {{2, 0, 5}}, {{2, 1, 5}}, {{1, 1, 5}}, {{1, 2, 5}}, {{0, 2, 5}}}, {{3, 4, 5, 0, 1, 2}});
  expect_near(face_area_vector(rotated, Face(0)), {{0, 0, 3}});
}

TEST(Normals, NonPlanarQuadGetsNewellNormal) {
  // A twisted quad: Newell's normal is the average plane's, here +z by symmetry.
  Mesh mesh = make_mesh({{{0, 0, 0}}, {{1, 0, 0.25f}}, {{1, 1, 0}}, {{0, 1, 0.25f}}}, {{0, 1, 2, 3}});
  expect_near(face_normal(mesh, Face(0)), {{0, 0, 1}});
}

TEST(Normals, DegenerateFaceHasZeroNormal) {
  Mesh mesh = make_mesh({{{0, 0, 0}}, {{1, 1, 1}}, {{2, 2, 2}}}, {{0, 1, 2}});
  expect_near(face_normal(mesh, Face(0)), {{0, 0, 0}});
  expect_near(vertex_normals(mesh)[0], {{0, 0, 0}});
}

TEST(Normals, VertexNormalsAreAreaWeighted) {
  // A big triangle facing +z (area 2) and a small one facing +x (area 0.5) share edge 0-1.
  Mesh mesh = make_mesh({{{0, 0, 0}}, {{0, 1, 0}}, {{4, 0, 0}}, {{0, 0, 1}}}, {{0, 2, 1}, {0, 1, 3}});
  ASSERT_TRUE(validate(mesh)) << validate(mesh).message;
  auto n = vertex_normals(mesh);
  ASSERT_EQ(n.size(), 4u);
  const float s = 1.0f / std::sqrt(17.0f);
  expect_near(n[0], {{s, 0, 4 * s}});
  expect_near(n[1], {{s, 0, 4 * s}});
  expect_near(n[2], {{0, 0, 1}});
  expect_near(n[3], {{1, 0, 0}});
}

TEST(Normals, CubeCornersPointOutward) {
  for (bool mixed : {false, true}) {
    Mesh mesh = cube(mixed);
    ASSERT_TRUE(validate(mesh)) << validate(mesh).message;
    auto n = vertex_normals(mesh);
    for (Vertex v : mesh.vertices()) {
      const Point& p = mesh.position(v);
      for (int i = 0; i < 3; ++i) EXPECT_GT(n[v.idx()][i] * (p[i] - 0.5f), 0.0f) << "vertex " << v.idx();
      EXPECT_NEAR(norm(n[v.idx()]), 1.0f, 1e-6f);
    }
    if (!mixed) expect_near(n[6], normalize(Vec3f{{1, 1, 1}}));
  }
}

TEST(Normals, MatchPerVertexSumOfFaceAreaVectors) {
  Mesh mesh = cube(true);
  auto fast = vertex_normals(mesh);
  for (Vertex v : mesh.vertices()) {
    Vec3f sum{};
    for (Face f : mesh.faces(v)) sum += face_area_vector(mesh, f);
    expect_near(fast[v.idx()], normalize(sum));
  }
  auto fn = face_normals(mesh);
  ASSERT_EQ(fn.size(), mesh.faces_size());
  for (Face f : mesh.faces()) expect_near(fn[f.idx()], normalize(face_area_vector(mesh, f)));
}

TEST(Normals, DeletedFacesAndIsolatedVerticesContributeNothing) {
  Mesh mesh = make_mesh({{{0, 0, 0}}, {{0, 1, 0}}, {{4, 0, 0}}, {{0, 0, 1}}}, {{0, 2, 1}, {0, 1, 3}});
  const Vertex isolated = mesh.new_vertex();
  mesh.position(isolated) = Point{{7, 7, 7}};
  mesh.delete_face(Face(1));
  auto n = vertex_normals(mesh);
  ASSERT_EQ(n.size(), mesh.vertices_size());
  expect_near(n[0], {{0, 0, 1}});
  expect_near(n[3], {{0, 0, 0}});
  expect_near(n[isolated.idx()], {{0, 0, 0}});
  auto fn = face_normals(mesh);
  expect_near(fn[1], {{0, 0, 0}});
}

TEST(Normals, OutputSpanMustMatchVertexCount) {
  Mesh mesh = cube(false);
  std::vector<Vec3f> out(3);
  EXPECT_THROW(vertex_normals(mesh, out), Error);
  out.resize(mesh.vertices_size());
  vertex_normals(mesh, out);
  EXPECT_EQ(out, vertex_normals(mesh));
}

}  // namespace
