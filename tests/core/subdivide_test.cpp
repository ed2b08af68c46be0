// Tests of subdivide (subdivide.h): stencils checked against hand-computed positions, element
// counts, boundaries, attributes, refusals, and the time of one Loop step on the dragon.
#include "hedge/subdivide.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <map>
#include <numbers>
#include <set>
#include <utility>
#include <vector>

#include "hedge/build.h"
#include "hedge/catalogue.h"
#include "hedge/error.h"
#include "hedge/io.h"
#include "hedge/normals.h"
#include "hedge/report.h"
#include "hedge/threads.h"
#include "hedge/topology.h"
#include "hedge/validate.h"
#include "parallel.h"
#include "test_meshes.h"

namespace {

using namespace hedge;
using test::make_mesh;

Mesh tetrahedron() {
  return make_mesh({{{0, 0, 0}}, {{1, 0, 0}}, {{0, 1, 0}}, {{0, 0, 1}}}, {{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {0, 3, 2}});
}

Mesh unit_cube() {
  return make_mesh(
      {{{0, 0, 0}}, {{1, 0, 0}}, {{1, 1, 0}}, {{0, 1, 0}}, {{0, 0, 1}}, {{1, 0, 1}}, {{1, 1, 1}}, {{0, 1, 1}}},
      {{0, 3, 2, 1}, {0, 1, 5, 4}, {1, 2, 6, 5}, {2, 3, 7, 6}, {3, 0, 4, 7}, {4, 5, 6, 7}});
}

// An n x n grid of unit squares split into triangles, in the plane z = 0 (open: one boundary loop).
Mesh grid(int n, bool triangles = true) {
  std::vector<Point> p;
  std::vector<std::vector<Index>> f;
  for (int y = 0; y <= n; ++y)
    for (int x = 0; x <= n; ++x) p.push_back({{float(x), float(y), 0}});
  auto id = [&](int x, int y) { return Index(y * (n + 1) + x); };
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      if (triangles) {
        f.push_back({id(x, y), id(x + 1, y), id(x + 1, y + 1)});
        f.push_back({id(x, y), id(x + 1, y + 1), id(x, y + 1)});
      } else {
        f.push_back({id(x, y), id(x + 1, y), id(x + 1, y + 1), id(x, y + 1)});
      }
    }
  return make_mesh(p, f);
}

void expect_point(const Point& got, const Vec3d& want, double tolerance = 1e-6) {
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(got[i], want[i], tolerance) << "component " << i;
}

Vec3d at(const Mesh& m, Index v) { return to_double(m.position(Vertex(v))); }

void expect_valid(const Mesh& mesh) {
  Validation v = validate(mesh);
  EXPECT_TRUE(v.ok) << v.message;
}

SubdivideOptions scheme(SubdivisionScheme s, int iterations = 1) {
  SubdivideOptions o;
  o.scheme = s;
  o.iterations = iterations;
  return o;
}

TEST(Subdivide, LoopTetrahedronMatchesHandStencils) {
  Mesh before = tetrahedron();
  Mesh mesh = before;
  SubdivideReport r = subdivide(mesh, scheme(SubdivisionScheme::loop));
  expect_valid(mesh);
  EXPECT_EQ(mesh.n_vertices(), 4u + 6u);  // V + E
  EXPECT_EQ(mesh.n_faces(), 16u);         // 4F
  EXPECT_EQ(mesh.n_edges(), 2u * 6 + 3 * 4);
  EXPECT_EQ(r.faces, 16u);
  EXPECT_TRUE(mesh.is_triangle_mesh());
  // Even vertices, valence 3: beta = 3/16, the vertex keeps 1 - 3 beta = 7/16.
  for (Index v = 0; v < 4; ++v) {
    Vec3d want = at(before, v) * (7.0 / 16.0);
    for (Index w = 0; w < 4; ++w)
      if (w != v) want += at(before, w) * (3.0 / 16.0);
    expect_point(mesh.position(Vertex(v)), want);
  }
  // Odd vertices: 3/8 for the edge's ends, 1/8 for the two opposite corners (the other two).
  for (Edge e : before.edges()) {
    Index a = before.vertex(e, 0).idx(), b = before.vertex(e, 1).idx();
    Vec3d want = (at(before, a) + at(before, b)) * (3.0 / 8.0);
    for (Index w = 0; w < 4; ++w)
      if (w != a && w != b) want += at(before, w) * (1.0 / 8.0);
    expect_point(mesh.position(Vertex(4 + e.idx())), want);
  }
  // Every new edge joins vertices that are close: no face got wired across the mesh.
  for (Edge e : mesh.edges())
    EXPECT_LT(distance(at(mesh, mesh.vertex(e, 0).idx()), at(mesh, mesh.vertex(e, 1).idx())), 0.8);
}

TEST(Subdivide, CatmullClarkCubeMatchesHandStencils) {
  Mesh mesh = unit_cube();
  subdivide(mesh, scheme(SubdivisionScheme::catmull_clark));
  expect_valid(mesh);
  EXPECT_EQ(mesh.n_vertices(), 8u + 12u + 6u);  // V + E + F
  EXPECT_EQ(mesh.n_faces(), 24u);               // sum of face sizes
  EXPECT_TRUE(mesh.is_quad_mesh());
  // Old vertices, n = 3: Q = mean of the 3 face centres, R = mean of the 3 edge midpoints,
  // (Q + 2R + 0 S) / 3. At the origin: Q = (1/3, 1/3, 1/3), R = (1/6, 1/6, 1/6) -> 2/9.
  const Mesh cube = unit_cube();
  for (Index v = 0; v < 8; ++v) {
    const Point& p = cube.position(Vertex(v));
    Vec3d want;
    for (int i = 0; i < 3; ++i) want[i] = p[i] > 0.5f ? 7.0 / 9.0 : 2.0 / 9.0;
    expect_point(mesh.position(Vertex(v)), want);
  }
  // Face points at the face centres (after the 20 vertex and edge points, in face order).
  expect_point(mesh.position(Vertex(20)), {{0.5, 0.5, 0}});
  expect_point(mesh.position(Vertex(25)), {{0.5, 0.5, 1}});
  // Edge points: (a + b + F1 + F2) / 4; for edge (0,0,0)-(1,0,0): faces z = 0 and y = 0.
  Edge e = cube.find_edge(Vertex(0), Vertex(1));
  ASSERT_TRUE(e.is_valid());
  expect_point(mesh.position(Vertex(8 + e.idx())), {{0.5, 0.125, 0.125}});
  for (Edge x : cube.edges()) {
    const Point& p = mesh.position(Vertex(8 + x.idx()));
    int at_half = 0, inner = 0;
    for (int i = 0; i < 3; ++i) {
      at_half += std::abs(p[i] - 0.5f) < 1e-6f;
      inner += std::abs(p[i] - 0.125f) < 1e-6f || std::abs(p[i] - 0.875f) < 1e-6f;
    }
    EXPECT_EQ(at_half, 1) << "edge " << x.idx();
    EXPECT_EQ(inner, 2) << "edge " << x.idx();
  }
}

TEST(Subdivide, CatmullClarkTwoStepsOnMixedPolygons) {
  // A pyramid: a quad base and four triangles.
  Mesh mesh = make_mesh({{{0, 0, 0}}, {{1, 0, 0}}, {{1, 1, 0}}, {{0, 1, 0}}, {{0.5f, 0.5f, 1}}},
                        {{0, 3, 2, 1}, {0, 1, 4}, {1, 2, 4}, {2, 3, 4}, {3, 0, 4}});
  subdivide(mesh, scheme(SubdivisionScheme::catmull_clark, 2));
  expect_valid(mesh);
  EXPECT_EQ(mesh.n_faces(), 16u * 4);  // 4 + 4 * 3 quads, then x4
  EXPECT_TRUE(mesh.is_quad_mesh());
  EXPECT_EQ(topology_stats(mesh).euler_characteristic, 2);
}

TEST(Subdivide, CountsFollowTheFormulasOverIterations) {
  for (auto s : {SubdivisionScheme::loop, SubdivisionScheme::sqrt3, SubdivisionScheme::midpoint,
                 SubdivisionScheme::catmull_clark}) {
    Mesh mesh = tetrahedron();
    std::size_t V = 4, E = 6, F = 4;
    for (int it = 1; it <= 3; ++it) {
      subdivide(mesh, scheme(s));
      expect_valid(mesh);
      switch (s) {
        case SubdivisionScheme::loop:
        case SubdivisionScheme::midpoint:
          V += E, E = 2 * E + 3 * F, F *= 4;
          break;
        case SubdivisionScheme::sqrt3:
          V += F, E += 3 * F, F *= 3;
          break;
        case SubdivisionScheme::catmull_clark: {
          std::size_t corners = 2 * E;  // closed mesh: every half-edge is a corner
          V += E + F, E = 2 * E + corners, F = corners;
          break;
        }
      }
      EXPECT_EQ(mesh.n_vertices(), V) << subdivision_scheme_name(s) << " step " << it;
      EXPECT_EQ(mesh.n_edges(), E) << subdivision_scheme_name(s) << " step " << it;
      EXPECT_EQ(mesh.n_faces(), F) << subdivision_scheme_name(s) << " step " << it;
      EXPECT_EQ(topology_stats(mesh).genus, 0);
      EXPECT_EQ(topology_stats(mesh).boundary_loops, 0u);
    }
    SubdivideOptions o = scheme(s, 3);
    EXPECT_EQ(subdivided_face_count(tetrahedron(), o), F) << subdivision_scheme_name(s);
  }
}

TEST(Subdivide, Sqrt3StencilsOnTetrahedron) {
  Mesh before = tetrahedron();
  Mesh mesh = before;
  subdivide(mesh, scheme(SubdivisionScheme::sqrt3));
  expect_valid(mesh);
  // Face points at the centroids.
  for (Face f : before.faces()) {
    Vec3d c{};
    for (Vertex v : before.vertices(f)) c += at(before, v.idx()) / 3.0;
    expect_point(mesh.position(Vertex(4 + f.idx())), c);
  }
  // Old vertices: (1 - a) v + a/n sum, a = (4 - 2 cos(2 pi / n)) / 9 = 5/9 for n = 3.
  for (Index v = 0; v < 4; ++v) {
    Vec3d want = at(before, v) * (4.0 / 9.0);
    for (Index w = 0; w < 4; ++w)
      if (w != v) want += at(before, w) * (5.0 / 27.0);
    expect_point(mesh.position(Vertex(v)), want);
  }
  // Every old edge was flipped: no two old vertices are joined any more; each old vertex has
  // valence 3 (its spokes), each face point valence 6 after the flip (3 spokes + 3 flipped edges).
  for (Index a = 0; a < 4; ++a) {
    for (Index b = a + 1; b < 4; ++b) EXPECT_FALSE(mesh.find_edge(Vertex(a), Vertex(b)).is_valid());
    EXPECT_EQ(mesh.valence(Vertex(a)), 3u);
  }
  for (Index f = 0; f < 4; ++f) EXPECT_EQ(mesh.valence(Vertex(4 + f)), 6u);
}

TEST(Subdivide, LoopBoundaryFollowsTheCurveRules) {
  Mesh before = grid(3);
  Mesh mesh = before;
  subdivide(mesh, scheme(SubdivisionScheme::loop));
  expect_valid(mesh);
  EXPECT_EQ(topology_stats(mesh).boundary_loops, 1u);
  EXPECT_EQ(topology_stats(mesh).boundary_edges, 2 * topology_stats(before).boundary_edges);
  for (Vertex v : mesh.vertices()) EXPECT_EQ(mesh.position(v)[2], 0.0f);  // planar stays planar
  // Boundary vertex (1, 0): 3/4 itself + 1/8 (0,0) + 1/8 (2,0) = (1, 0); the corner (0, 0):
  // 3/4 (0,0) + 1/8 (1,0) + 1/8 (0,1).
  expect_point(mesh.position(Vertex(1)), {{1, 0, 0}});
  expect_point(mesh.position(Vertex(0)), {{0.125, 0.125, 0}});
  // A boundary edge point is the midpoint.
  Edge b = before.find_edge(Vertex(0), Vertex(1));
  expect_point(mesh.position(Vertex(16 + b.idx())), {{0.5, 0, 0}});
  // Interior vertex (1, 1), valence 6, regular: beta = 1/16, weights 10/16 and 6 x 1/16.
  Vec3d want = at(before, 5) * (10.0 / 16.0);
  for (Vertex w : before.vertices(Vertex(5))) want += at(before, w.idx()) / 16.0;
  expect_point(mesh.position(Vertex(5)), want);
}

TEST(Subdivide, CatmullClarkBoundaryRules) {
  Mesh before = grid(2, false);  // 2 x 2 quads
  Mesh mesh = before;
  subdivide(mesh, scheme(SubdivisionScheme::catmull_clark));
  expect_valid(mesh);
  EXPECT_EQ(mesh.n_faces(), 16u);
  // Corner (0,0): 3/4 + 1/8 (1,0) + 1/8 (0,1). Centre (1,1), n = 4: stays (regular, symmetric).
  expect_point(mesh.position(Vertex(0)), {{0.125, 0.125, 0}});
  expect_point(mesh.position(Vertex(4)), {{1, 1, 0}});
  Edge b = before.find_edge(Vertex(0), Vertex(1));
  expect_point(mesh.position(Vertex(9 + b.idx())), {{0.5, 0, 0}});
  // Interior edge (1,0)-(1,1): (a + b + F1 + F2) / 4 = ((1,0) + (1,1) + (.5,.5) + (1.5,.5)) / 4.
  Edge i = before.find_edge(Vertex(1), Vertex(4));
  expect_point(mesh.position(Vertex(9 + i.idx())), {{1, 0.5, 0}});
}

TEST(Subdivide, Sqrt3CutsTheBoundaryInThreeEverySecondStep) {
  const Mesh before = grid(2);  // 8 triangles, 8 boundary edges
  // Step 1 keeps the boundary as it is.
  Mesh once = before;
  subdivide(once, scheme(SubdivisionScheme::sqrt3, 1));
  expect_valid(once);
  EXPECT_EQ(once.n_faces(), 24u);
  EXPECT_EQ(topology_stats(once).boundary_edges, 8u);
  for (Vertex v : before.vertices()) expect_point(once.position(v), at(before, v.idx()));

  // Step 2 cuts each boundary edge in three: 3 * 24 + 2 * 8 faces.
  Mesh twice = before;
  subdivide(twice, scheme(SubdivisionScheme::sqrt3, 2));
  expect_valid(twice);
  EXPECT_EQ(twice.n_faces(), 88u);
  EXPECT_EQ(subdivided_face_count(before, scheme(SubdivisionScheme::sqrt3, 2)), 88u);
  EXPECT_EQ(topology_stats(twice).boundary_edges, 24u);
  // Old boundary vertices: (4, 19, 4) / 27 along the boundary; on a straight side they stay,
  // the corner (0, 0) moves in to (4, 4) / 27.
  expect_point(twice.position(Vertex(1)), {{1, 0, 0}});
  expect_point(twice.position(Vertex(0)), {{4.0 / 27, 4.0 / 27, 0}});
  // New points on the side (0,0)-(1,0): (1, 16, 10) / 27 from the nearer end; every boundary
  // vertex of the result is one of the rule's points.
  std::vector<Vec3d> boundary_points;
  for (Vertex v : twice.vertices())
    if (twice.is_boundary(v)) boundary_points.push_back(at(twice, v.idx()));
  EXPECT_EQ(boundary_points.size(), 24u);
  auto has = [&](Vec3d want) {
    for (const Vec3d& p : boundary_points)
      if (norm(p - want) < 1e-6) return true;
    return false;
  };
  EXPECT_TRUE(has({{10.0 / 27, 1.0 / 27, 0}}));  // (0,1) + 16 (0,0) + 10 (1,0)
  EXPECT_TRUE(has({{18.0 / 27, 0, 0}}));         // 10 (0,0) + 16 (1,0) + (2,0)

  // Four steps: the boundary is cut twice; the face count follows 3F, then + 2 per boundary edge.
  Mesh four = before;
  subdivide(four, scheme(SubdivisionScheme::sqrt3, 4));
  expect_valid(four);
  EXPECT_EQ(topology_stats(four).boundary_edges, 72u);
  EXPECT_EQ(four.n_faces(), (88u * 3) * 3 + 2 * 24);
  EXPECT_EQ(subdivided_face_count(before, scheme(SubdivisionScheme::sqrt3, 4)), four.n_faces());
}

TEST(Subdivide, MidpointIsLinear) {
  // A cube whose top is two triangles: quads split around centroids, triangles 1 -> 4.
  Mesh before = make_mesh(
      {{{0, 0, 0}}, {{1, 0, 0}}, {{1, 1, 0}}, {{0, 1, 0}}, {{0, 0, 1}}, {{1, 0, 1}}, {{1, 1, 1}}, {{0, 1, 1}}},
      {{0, 3, 2, 1}, {0, 1, 5, 4}, {1, 2, 6, 5}, {2, 3, 7, 6}, {3, 0, 4, 7}, {4, 5, 6}, {4, 6, 7}});
  Mesh mesh = before;
  subdivide(mesh, scheme(SubdivisionScheme::midpoint));
  expect_valid(mesh);
  const std::size_t V = 8, E = before.n_edges();
  EXPECT_EQ(mesh.n_vertices(), V + E + 5);
  EXPECT_EQ(mesh.n_faces(), 5u * 4 + 2 * 4);
  for (Index v = 0; v < V; ++v) expect_point(mesh.position(Vertex(v)), at(before, v));
  for (Edge e : before.edges())
    expect_point(mesh.position(Vertex(V + e.idx())),
                 (at(before, before.vertex(e, 0).idx()) + at(before, before.vertex(e, 1).idx())) * 0.5);
  expect_point(mesh.position(Vertex(V + E)), {{0.5, 0.5, 0}});
  // Area is kept exactly by a linear refinement of planar faces.
  EXPECT_NEAR(mesh_statistics(mesh).area, 6.0, 1e-5);
}

// A vertex channel equal to the positions must follow the positions (same stencils), and the
// mesh's own "hedge:source" must stay on the old vertices only.
TEST(Subdivide, VertexAttributesFollowTheStencils) {
  for (auto s : {SubdivisionScheme::loop, SubdivisionScheme::sqrt3, SubdivisionScheme::catmull_clark}) {
    Mesh mesh = grid(3);
    mesh.position(Vertex(5))[2] = 0.7f;  // not flat, so the stencils matter
    ChannelArray* color = mesh.vertex_properties().add_channel("color", ScalarType::f32, 3);
    ChannelArray* quality = mesh.vertex_properties().add_channel("quality", ScalarType::f64, 1);
    auto source = mesh.add_vertex_property<std::uint32_t>("hedge:source", kInvalidIndex);
    for (Vertex v : mesh.vertices()) {
      std::memcpy(color->element(v.idx()), &mesh.position(v), sizeof(Point));
      const double q = mesh.position(v)[0];
      std::memcpy(quality->element(v.idx()), &q, sizeof q);
      source[v] = 100 + v.idx();
    }
    const std::size_t V = mesh.n_vertices();
    subdivide(mesh, scheme(s));
    expect_valid(mesh);
    color = mesh.vertex_properties().get_channel("color");
    quality = mesh.vertex_properties().get_channel("quality");
    source = mesh.get_vertex_property<std::uint32_t>("hedge:source");
    ASSERT_TRUE(color && quality && source);
    for (Vertex v : mesh.vertices()) {
      Point c;
      std::memcpy(&c, color->element(v.idx()), sizeof c);
      expect_point(c, to_double(mesh.position(v)), 1e-5);
      double q;
      std::memcpy(&q, quality->element(v.idx()), sizeof q);
      EXPECT_NEAR(q, mesh.position(v)[0], 1e-5);
      EXPECT_EQ(source[v], v.idx() < V ? 100 + v.idx() : kInvalidIndex) << subdivision_scheme_name(s);
    }
  }
}

// Corner UVs: each face gets its own chart (a seam everywhere) uv = (x + 10 f, y); face
// channel "material" = f. After a linear refinement every child corner must read its parent's
// chart at its own position, so seams stay seams.
TEST(Subdivide, CornerAndFaceAttributesStayInTheirFace) {
  for (auto s : {SubdivisionScheme::midpoint, SubdivisionScheme::loop, SubdivisionScheme::catmull_clark}) {
    Mesh mesh = s == SubdivisionScheme::catmull_clark ? grid(2, false) : grid(2);
    ChannelArray* uv = mesh.halfedge_properties().add_channel("uv", ScalarType::f32, 2);
    ChannelArray* material = mesh.face_properties().add_channel("material", ScalarType::i32, 1);
    for (Face f : mesh.faces()) {
      const std::int32_t id = std::int32_t(f.idx());
      std::memcpy(material->element(f.idx()), &id, sizeof id);
      for (Halfedge h : mesh.halfedges(f)) {
        const Point& p = mesh.position(mesh.to_vertex(h));
        const float value[2] = {p[0] + 10.0f * float(f.idx()), p[1]};
        std::memcpy(uv->element(h.idx()), value, sizeof value);
      }
    }
    const std::size_t F = mesh.n_faces();
    const Mesh before = mesh;
    subdivide(mesh, scheme(s));
    expect_valid(mesh);
    uv = mesh.halfedge_properties().get_channel("uv");
    material = mesh.face_properties().get_channel("material");
    ASSERT_TRUE(uv && material);
    std::vector<int> children(F, 0);
    for (Face f : mesh.faces()) {
      std::int32_t parent;
      std::memcpy(&parent, material->element(f.idx()), sizeof parent);
      ASSERT_GE(parent, 0);
      ASSERT_LT(std::size_t(parent), F);
      ++children[std::size_t(parent)];
      for (Halfedge h : mesh.halfedges(f)) {
        float value[2];
        std::memcpy(value, uv->element(h.idx()), sizeof value);
        // The corner's chart is its parent's; positions are linear only for midpoint, so
        // Loop and Catmull-Clark are checked for the chart (the offset) alone.
        EXPECT_NEAR(std::floor((value[0] + 1.0f) / 10.0f), parent, 0.0) << subdivision_scheme_name(s);
        if (s == SubdivisionScheme::midpoint) {
          const Point& p = mesh.position(mesh.to_vertex(h));
          EXPECT_NEAR(value[0], p[0] + 10.0f * float(parent), 1e-5f);
          EXPECT_NEAR(value[1], p[1], 1e-5f);
        }
      }
    }
    for (int c : children) EXPECT_EQ(c, 4);
    // Boundary half-edges hold zeros.
    for (Halfedge h : mesh.halfedges())
      if (mesh.is_boundary(h)) {
        float value[2];
        std::memcpy(value, uv->element(h.idx()), sizeof value);
        EXPECT_EQ(value[0], 0.0f);
        EXPECT_EQ(value[1], 0.0f);
      }
    (void)before;
  }
}

// Two closed tetrahedra glued along edge 0-1 (four faces on it) and a fin (a fifth face on
// it): build() splits the edge. Every scheme must give back the input's topology there: the
// edge stays shared by five faces (√3 flips it away: then nothing may be left open).
TEST(Subdivide, SeamsOfNonManifoldInputStayClosed) {
  Soup soup;
  soup.positions = {{{0, 0, 0}}, {{1, 0, 0}}, {{0, 1, 0}}, {{0, 0, 1}}, {{0, -1, 0}}, {{0, 0, -1}}};
  soup.positions.push_back({{0.5f, 0.5f, 0.5f}});
  for (std::uint32_t c : {0, 2, 1, 0, 1, 3, 1, 2, 3, 2, 0, 3, 0, 4, 1, 0, 1, 5, 1, 4, 5, 4, 0, 5, 0, 1, 6})
    soup.corners.push_back(c);
  soup.face_sizes.assign(9, 3);
  for (auto s : {SubdivisionScheme::loop, SubdivisionScheme::sqrt3, SubdivisionScheme::catmull_clark,
                 SubdivisionScheme::midpoint}) {
    Mesh mesh = build(soup).mesh;
    subdivide(mesh, scheme(s, 2));
    expect_valid(mesh);
    const Soup out = extract(mesh);
    std::map<std::pair<std::uint32_t, std::uint32_t>, int> faces_on_edge;
    const auto offsets = out.face_offsets();
    for (std::size_t f = 0; f < out.n_faces(); ++f)
      for (std::uint32_t k = offsets[f]; k < offsets[f + 1]; ++k) {
        const std::uint32_t a = out.corners[k], b = out.corners[k + 1 < offsets[f + 1] ? k + 1 : offsets[f]];
        ++faces_on_edge[{std::min(a, b), std::max(a, b)}];
      }
    std::size_t open = 0, glued = 0;
    for (const auto& [edge, n] : faces_on_edge) {
      open += n == 1;
      glued += n == 5;
    }
    if (s == SubdivisionScheme::sqrt3) {
      EXPECT_EQ(open, 2u * 3);  // only the fin's two free sides, cut in three by the second step
    } else {
      EXPECT_EQ(open, 4u * 2) << subdivision_scheme_name(s);  // the fin's free sides, halved twice
      EXPECT_EQ(glued, 4u) << subdivision_scheme_name(s);     // the glued edge, halved twice
    }
  }
}

// A quad that visits vertex 0 twice (0 1 0 2) is built on two copies of it, and its two
// sides along 0-1 become two mesh edges of one input edge. Their edge points stay apart:
// welded, the face's pieces around the two copies would be one face twice.
TEST(Subdivide, FaceVisitingAVertexTwiceGivesNoDuplicate) {
  Soup soup;
  soup.positions = {{{0, 0, 0}}, {{1, 0, 0}}, {{0, 1, 0}}, {{1, 1, 0}}};
  for (std::uint32_t c : {0, 1, 0, 2, 1, 3, 2}) soup.corners.push_back(c);
  soup.face_sizes = {4, 3};
  for (auto s : {SubdivisionScheme::midpoint, SubdivisionScheme::catmull_clark}) {
    const Operation& op = find_operation("subdivide");
    const RunResult result = run_operation(
        op, soup, resolve_params(op, std::map<std::string, std::string>{{"scheme", subdivision_scheme_name(s)}}),
        Progress::none());
    std::set<std::vector<std::uint32_t>> sets;
    const auto offsets = result.soup.face_offsets();
    for (std::size_t f = 0; f < result.soup.n_faces(); ++f) {
      std::vector<std::uint32_t> set(result.soup.corners.begin() + offsets[f],
                                     result.soup.corners.begin() + offsets[f + 1]);
      std::sort(set.begin(), set.end());
      EXPECT_TRUE(sets.insert(set).second) << subdivision_scheme_name(s) << ": face " << f << " repeats a vertex set";
    }
    // The quad gives 4 quads; the triangle 4 triangles (midpoint) or 3 quads (Catmull-Clark).
    EXPECT_EQ(sets.size(), s == SubdivisionScheme::midpoint ? 8u : 7u) << subdivision_scheme_name(s);
  }
}

Mesh grid_with_uv(int n) {
  Mesh mesh = grid(n);
  ChannelArray* uv = mesh.halfedge_properties().add_channel("uv", ScalarType::f32, 2);
  for (Face f : mesh.faces())
    for (Halfedge h : mesh.halfedges(f)) {
      const Point& p = mesh.position(mesh.to_vertex(h));
      const float value[2] = {p[0], p[1]};  // one continuous chart: uv = xy
      std::memcpy(uv->element(h.idx()), value, sizeof value);
    }
  return mesh;
}

TEST(Subdivide, Sqrt3CarriesCornersAndFaces) {
  Mesh mesh = grid_with_uv(2);
  ChannelArray* uv = mesh.halfedge_properties().get_channel("uv");
  auto flipped = mesh.add_face_property<bool>("hedge:flipped", false);
  flipped[Face(3)] = true;
  subdivide(mesh, scheme(SubdivisionScheme::sqrt3));
  expect_valid(mesh);
  uv = mesh.halfedge_properties().get_channel("uv");
  // The grid is flat and the boundary is kept, so after one step positions are still the
  // affine image of the chart only at corners whose uv came from their own position: check
  // face points (centroids) and old corners.
  std::size_t checked = 0;
  for (Face f : mesh.faces())
    for (Halfedge h : mesh.halfedges(f)) {
      float value[2];
      std::memcpy(value, uv->element(h.idx()), sizeof value);
      Vertex v = mesh.to_vertex(h);
      if (v.idx() >= 9 || mesh.is_boundary(v)) {  // face points and fixed boundary vertices
        EXPECT_NEAR(value[0], mesh.position(v)[0], 1e-5f);
        EXPECT_NEAR(value[1], mesh.position(v)[1], 1e-5f);
        ++checked;
      }
    }
  EXPECT_GT(checked, 0u);
  flipped = mesh.get_face_property<bool>("hedge:flipped");
  std::size_t n_flipped = 0;
  for (Face f : mesh.faces()) n_flipped += flipped[f];
  EXPECT_EQ(n_flipped, 3u);  // the three children of face 3

  // The second step of a run cuts the boundary: corners at the new boundary points
  // (vertices from 17 + 24 on) take the uv a third and two thirds along their edge.
  mesh = grid_with_uv(2);
  subdivide(mesh, scheme(SubdivisionScheme::sqrt3, 2));
  expect_valid(mesh);
  uv = mesh.halfedge_properties().get_channel("uv");
  std::size_t on_cut = 0;
  bool third = false, two_thirds = false;
  for (Face f : mesh.faces())
    for (Halfedge h : mesh.halfedges(f)) {
      if (mesh.to_vertex(h).idx() < 17 + 24) continue;
      float value[2];
      std::memcpy(value, uv->element(h.idx()), sizeof value);
      const bool on_side = value[0] < 1e-6f || value[0] > 2 - 1e-6f || value[1] < 1e-6f || value[1] > 2 - 1e-6f;
      EXPECT_TRUE(on_side) << value[0] << " " << value[1];
      third = third || (std::abs(value[0] - 1.0f / 3) < 1e-6f && value[1] == 0);
      two_thirds = two_thirds || (std::abs(value[0] - 2.0f / 3) < 1e-6f && value[1] == 0);
      ++on_cut;
    }
  EXPECT_GT(on_cut, 0u);
  EXPECT_TRUE(third && two_thirds);
}

TEST(Subdivide, RefreshesNormals) {
  // Flat-shaded cube: corner normals are the face normals (hard edges). After Catmull-Clark
  // each child corner keeps its parent face's normal; vertex normals are recomputed.
  Mesh mesh = unit_cube();
  ChannelArray* cn = mesh.halfedge_properties().add_channel("normal", ScalarType::f32, 3);
  mesh.vertex_properties().add_channel("normal", ScalarType::f32, 3);
  ChannelArray* material = mesh.face_properties().add_channel("material", ScalarType::i32, 1);
  std::vector<Vec3f> parent_normal;
  for (Face f : mesh.faces()) {
    const std::int32_t id = std::int32_t(f.idx());
    std::memcpy(material->element(f.idx()), &id, sizeof id);
    Vec3f n{};
    Halfedge h = mesh.halfedge(f);
    const Point& a = mesh.position(mesh.to_vertex(h));
    n = normalize(
        cross(mesh.position(mesh.to_vertex(mesh.next(h))) - a, mesh.position(mesh.to_vertex(mesh.prev(h))) - a));
    parent_normal.push_back(n);
    for (Halfedge x : mesh.halfedges(f)) std::memcpy(cn->element(x.idx()), &n, sizeof n);
  }
  subdivide(mesh, scheme(SubdivisionScheme::catmull_clark));
  cn = mesh.halfedge_properties().get_channel("normal");
  ChannelArray* vn = mesh.vertex_properties().get_channel("normal");
  material = mesh.face_properties().get_channel("material");
  for (Face f : mesh.faces()) {
    std::int32_t parent;
    std::memcpy(&parent, material->element(f.idx()), sizeof parent);
    for (Halfedge h : mesh.halfedges(f)) {
      Vec3f n;
      std::memcpy(&n, cn->element(h.idx()), sizeof n);
      expect_point(n, to_double(parent_normal[std::size_t(parent)]), 1e-6);
    }
  }
  for (Vertex v : mesh.vertices()) {
    Vec3f n;
    std::memcpy(&n, vn->element(v.idx()), sizeof n);
    EXPECT_NEAR(norm(n), 1.0f, 1e-5f);
    EXPECT_GT(dot(n, mesh.position(v) - Point{{0.5f, 0.5f, 0.5f}}), 0.0f);  // outward
  }
}

TEST(Subdivide, RefusesPolygonsForTriangleSchemesAndLeavesTheMesh) {
  for (auto s : {SubdivisionScheme::loop, SubdivisionScheme::sqrt3}) {
    Mesh mesh = unit_cube();
    try {
      subdivide(mesh, scheme(s));
      ADD_FAILURE() << "no error";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("triangulate"), std::string::npos) << e.what();
    }
    EXPECT_EQ(mesh.n_faces(), 6u);
    EXPECT_EQ(mesh.n_vertices(), 8u);
  }
}

TEST(Subdivide, RefusesHugeResultsBeforeStarting) {
  Mesh mesh = tetrahedron();
  SubdivideOptions o = scheme(SubdivisionScheme::loop, 6);
  o.max_faces = 1000;  // 4 * 4^6 = 16384
  EXPECT_THROW(subdivide(mesh, o), Error);
  EXPECT_EQ(mesh.n_faces(), 4u);
  // The catalogue's range stops at 6 iterations and the 200M limit applies by default.
  const Operation& op = find_operation("subdivide");
  EXPECT_THROW(resolve_params(op, std::map<std::string, std::string>{{"iterations", "7"}}), Error);
  EXPECT_GT(subdivided_face_count(mesh, scheme(SubdivisionScheme::loop, 6)), 0u);
}

TEST(Subdivide, CancellingLeavesTheMeshUntouched) {
  Mesh mesh = tetrahedron();
  Progress cancel([](double fraction, const std::string&) { return fraction < 0.5; });
  EXPECT_THROW(subdivide(mesh, scheme(SubdivisionScheme::loop, 3), cancel), Cancelled);
  EXPECT_EQ(mesh.n_faces(), 4u);
  expect_point(mesh.position(Vertex(1)), {{1, 0, 0}});
}

TEST(Subdivide, SkipsDeletedElementsAndKeepsIsolatedVertices) {
  Mesh mesh = grid(2);
  mesh.delete_face(Face(0));
  const Vertex lone = mesh.new_vertex();
  mesh.position(lone) = Point{{5, 5, 5}};
  subdivide(mesh, scheme(SubdivisionScheme::loop));
  expect_valid(mesh);
  EXPECT_EQ(mesh.n_faces(), 7u * 4);
  EXPECT_FALSE(mesh.has_garbage());
  std::size_t isolated = 0;
  for (Vertex v : mesh.vertices()) isolated += mesh.is_isolated(v);
  EXPECT_EQ(isolated, 1u);
}

TEST(Subdivide, CatalogueEntry) {
  const Operation& op = find_operation("subdivide");
  EXPECT_EQ(op.category, Category::remeshing);
  ASSERT_NE(op.find_param("scheme"), nullptr);
  EXPECT_EQ(op.find_param("scheme")->choices, (std::vector<std::string>{"loop", "catmull_clark", "sqrt3", "midpoint"}));
  EXPECT_EQ(op.find_param("iterations")->default_value, Value(std::int64_t(1)));
  Mesh mesh = unit_cube();
  OperationReport r = op.run(
      mesh, resolve_params(op, std::map<std::string, std::string>{{"scheme", "catmull_clark"}, {"iterations", "2"}}),
      Progress::none());
  expect_valid(mesh);
  EXPECT_EQ(mesh.n_faces(), 96u);
  ASSERT_NE(r.find("faces"), nullptr);
  EXPECT_EQ(std::get<std::int64_t>(*r.find("faces")), 96);
}

// The whole pipeline the hosts use: soup with attributes -> build -> subdivide -> extract.
TEST(Subdivide, RunsThroughTheHostPipelineWithAttributes) {
  Soup soup;
  soup.positions = {{{0, 0, 0}}, {{1, 0, 0}}, {{1, 1, 0}}, {{0, 1, 0}},
                    {{0, 0, 1}}, {{1, 0, 1}}, {{1, 1, 1}}, {{0, 1, 1}}};
  for (auto f : std::vector<std::vector<std::uint32_t>>{
           {0, 3, 2, 1}, {0, 1, 5, 4}, {1, 2, 6, 5}, {2, 3, 7, 6}, {3, 0, 4, 7}, {4, 5, 6, 7}})
    soup.add_face(f);
  Channel& color = soup.add_channel("color", Domain::vertex, ScalarType::f32, 3);
  std::memcpy(color.data.data(), soup.positions.data(), color.data.size());
  Channel& uv = soup.add_channel("uv", Domain::corner, ScalarType::f32, 2);
  for (std::size_t c = 0; c < soup.n_corners(); ++c) {
    const float value[2] = {float(c), float(c / 4)};  // every face its own chart
    std::memcpy(uv.data.data() + c * sizeof value, value, sizeof value);
  }
  Channel& material = soup.add_channel("material", Domain::face, ScalarType::i32, 1);
  for (std::size_t f = 0; f < soup.n_faces(); ++f) material.as<std::int32_t>()[f] = std::int32_t(10 + f);

  const Operation& op = find_operation("subdivide");
  RunResult r = run_operation(
      op, soup, resolve_params(op, std::map<std::string, std::string>{{"scheme", "catmull_clark"}}), Progress::none());
  const Soup& out = r.soup;
  out.check();
  EXPECT_EQ(out.n_vertices(), 26u);
  EXPECT_EQ(out.n_faces(), 24u);
  const Channel* out_color = out.find("color", Domain::vertex);
  const Channel* out_uv = out.find("uv", Domain::corner);
  const Channel* out_material = out.find("material", Domain::face);
  ASSERT_TRUE(out_color && out_uv && out_material);
  EXPECT_EQ(out_uv->count(), 96u);
  for (std::size_t v = 0; v < out.n_vertices(); ++v)
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(out_color->as<float>()[3 * v + k], out.positions[v][k], 1e-6f);
  std::map<std::int32_t, int> children;
  for (std::size_t f = 0; f < out.n_faces(); ++f) ++children[out_material->as<std::int32_t>()[f]];
  for (std::int32_t m = 10; m < 16; ++m) EXPECT_EQ(children[m], 4);
  // Each child corner's uv is a blend of its parent face's uvs only: v = c / 4 of the parent.
  for (std::size_t f = 0; f < out.n_faces(); ++f) {
    const std::int32_t parent = out_material->as<std::int32_t>()[f] - 10;
    for (std::size_t k = 0; k < 4; ++k) EXPECT_EQ(out_uv->as<float>()[2 * (4 * f + k) + 1], float(parent));
  }
}

// ---- creases (crease_angle) ------------------------------------------------------------------

SubdivideOptions creased(SubdivisionScheme s, double crease_angle, int iterations = 1) {
  SubdivideOptions o = scheme(s, iterations);
  o.crease_angle = crease_angle;
  return o;
}

Mesh triangulated_cube() {
  const Mesh cube = unit_cube();
  std::vector<Point> p;
  for (Vertex v : cube.vertices()) p.push_back(cube.position(v));
  std::vector<std::vector<Index>> f;
  for (Face x : cube.faces()) {
    std::vector<Index> c;
    for (Vertex v : cube.vertices(x)) c.push_back(v.idx());
    f.push_back({c[0], c[1], c[2]});
    f.push_back({c[0], c[2], c[3]});
  }
  return make_mesh(p, f);
}

bool at_side(float x) { return std::abs(x) < 1e-6f || std::abs(x - 1) < 1e-6f; }

//! Checks that every vertex lies on the unit cube's surface; returns how many lie on its
//! edges (two coordinates at 0 or 1).
std::size_t on_unit_cube(const Mesh& m) {
  std::size_t on_edges = 0;
  for (Vertex v : m.vertices()) {
    const Point& p = m.position(v);
    int sides = 0;
    for (int i = 0; i < 3; ++i) {
      EXPECT_GE(p[i], -1e-6f) << "vertex " << v.idx();
      EXPECT_LE(p[i], 1 + 1e-6f) << "vertex " << v.idx();
      sides += at_side(p[i]);
    }
    EXPECT_GE(sides, 1) << "vertex " << v.idx() << " (" << p[0] << ", " << p[1] << ", " << p[2] << ") is inside";
    on_edges += sides >= 2;
  }
  return on_edges;
}

// Every cube edge (90 degrees) is a crease at 60 and every corner has three: the corners stay,
// the edges refine as straight lines, the flat sides stay flat.
TEST(SubdivideCreases, CreasedCubeStaysTheCube) {
  for (auto s : {SubdivisionScheme::catmull_clark, SubdivisionScheme::loop, SubdivisionScheme::sqrt3}) {
    const bool sqrt3 = s == SubdivisionScheme::sqrt3;
    const Mesh before = s == SubdivisionScheme::catmull_clark ? unit_cube() : triangulated_cube();
    for (int iterations : sqrt3 ? std::vector<int>{1, 2, 4} : std::vector<int>{1, 3}) {
      Mesh mesh = before;
      const SubdivideOptions options = creased(s, 60, iterations);
      const SubdivideReport r = subdivide(mesh, options);
      expect_valid(mesh);
      EXPECT_EQ(r.crease_edges, 12u) << subdivision_scheme_name(s);  // not the triangulation's diagonals
      EXPECT_EQ(subdivided_face_count(before, options), mesh.n_faces()) << subdivision_scheme_name(s);
      for (Index v = 0; v < 8; ++v) EXPECT_EQ(mesh.position(Vertex(v)), before.position(Vertex(v)));
      // Each cube edge is cut into 2^iterations pieces (sqrt3: 3 every second step): its
      // inner points and the 8 corners.
      std::size_t pieces = sqrt3 ? 1 : std::size_t(1) << iterations;
      for (int it = 1; sqrt3 && it < iterations; it += 2) pieces *= 3;
      EXPECT_EQ(on_unit_cube(mesh), 8 + 12 * (pieces - 1)) << subdivision_scheme_name(s) << " x" << iterations;
      // The first step puts the points of the cube's edges at their midpoints.
      if (iterations == 1 && !sqrt3)
        for (Edge e : before.edges()) {
          const Vec3d mid = (at(before, before.vertex(e, 0).idx()) + at(before, before.vertex(e, 1).idx())) * 0.5;
          const int halves = (mid[0] == 0.5) + (mid[1] == 0.5) + (mid[2] == 0.5);
          if (halves == 1) expect_point(mesh.position(Vertex(8 + e.idx())), mid);
        }
      EXPECT_NEAR(mesh_statistics(mesh).area, 6.0, 1e-4) << subdivision_scheme_name(s);
    }
    // The control: without creases the same cube rounds off.
    Mesh smooth = before;
    EXPECT_EQ(subdivide(smooth, creased(s, 180)).crease_edges, 0u);
    EXPECT_NE(smooth.position(Vertex(0)), before.position(Vertex(0)));
  }
}

// The tetrahedron (0,0,0), (1,0,0), (0,1,0), (0,0,1): its three edges at the origin bend by
// 90 degrees, the three of the slanted face by 125.3. At 100 only the latter are creases:
// vertex 0 is smooth, vertices 1, 2, 3 are crease vertices (two creases each).
TEST(SubdivideCreases, HandComputedCreaseRules) {
  const Mesh before = tetrahedron();
  const Edge e01 = before.find_edge(Vertex(0), Vertex(1)), e12 = before.find_edge(Vertex(1), Vertex(2));
  ASSERT_TRUE(e01.is_valid() && e12.is_valid());

  // Per scheme, the smooth vertex 0 and the smooth edge 0-1. Loop, valence 3: 7/16 itself and
  // 3/16 each neighbour; 3/8 (0 + 1) + 1/8 (2 + 3). Catmull-Clark, n = 3: 1/3 itself, 1/9 each
  // neighbour and each of its face centroids (1/3,1/3,0), (1/3,0,1/3), (0,1/3,1/3), so
  // 1/9 + 2/27 = 5/27 per coordinate; ((0,0,0) + (1,0,0) + (1/3,1/3,0) + (1/3,0,1/3)) / 4.
  const struct {
    SubdivisionScheme scheme;
    Vec3d vertex0, edge01;
  } cases[] = {{SubdivisionScheme::loop, {{3.0 / 16, 3.0 / 16, 3.0 / 16}}, {{3.0 / 8, 1.0 / 8, 1.0 / 8}}},
               {SubdivisionScheme::catmull_clark, {{5.0 / 27, 5.0 / 27, 5.0 / 27}}, {{5.0 / 12, 1.0 / 12, 1.0 / 12}}}};
  for (const auto& c : cases) {
    Mesh mesh = before;
    EXPECT_EQ(subdivide(mesh, creased(c.scheme, 100)).crease_edges, 3u);
    expect_valid(mesh);
    expect_point(mesh.position(Vertex(0)), c.vertex0);
    expect_point(mesh.position(Vertex(4 + e01.idx())), c.edge01);
    // The same crease rules in both: vertex 1 is 6/8 (1,0,0) + 1/8 (0,1,0) + 1/8 (0,0,1), the
    // point of crease edge 1-2 its midpoint.
    expect_point(mesh.position(Vertex(1)), {{0.75, 0.125, 0.125}});
    expect_point(mesh.position(Vertex(4 + e12.idx())), {{0.5, 0.5, 0}});
  }

  // At 130 nothing is sharp enough, at 60 everything: all corners, so Loop is the midpoint rule.
  Mesh none = before;
  EXPECT_EQ(subdivide(none, creased(SubdivisionScheme::loop, 130)).crease_edges, 0u);
  expect_point(none.position(Vertex(1)), {{7.0 / 16, 3.0 / 16, 3.0 / 16}});
  Mesh all = before;
  EXPECT_EQ(subdivide(all, creased(SubdivisionScheme::loop, 60)).crease_edges, 6u);
  for (Index v = 0; v < 4; ++v) EXPECT_EQ(all.position(Vertex(v)), before.position(Vertex(v)));
  expect_point(all.position(Vertex(4 + e01.idx())), {{0.5, 0, 0}});
}

//! The first vertex at `want`, invalid when there is none.
Vertex find_point(const Mesh& m, const Vec3d& want, double tolerance = 1e-6) {
  for (Vertex v : m.vertices())
    if (norm(at(m, v.idx()) - want) < tolerance) return v;
  return Vertex();
}

bool has_point(const Mesh& m, const Vec3d& want) { return find_point(m, want).is_valid(); }

// The same tetrahedron under sqrt3 at 100 degrees: the slanted face's edges 1-2, 2-3, 3-1 are
// creases, kept through the first step (the edges at vertex 0 are flipped) and cut in three by
// the second with Kobbelt's boundary stencils, as if the triangle 1-2-3 were a boundary.
TEST(SubdivideCreases, Sqrt3CreasesFollowTheBoundaryRules) {
  const Mesh before = tetrahedron();
  Mesh once = before;
  EXPECT_EQ(subdivide(once, creased(SubdivisionScheme::sqrt3, 100)).crease_edges, 3u);
  expect_valid(once);
  EXPECT_EQ(once.n_faces(), 12u);
  // Vertex 0 smooth: 4/9 itself, 5/27 each neighbour; the crease vertices wait.
  expect_point(once.position(Vertex(0)), {{5.0 / 27, 5.0 / 27, 5.0 / 27}});
  for (Index v = 1; v < 4; ++v) EXPECT_EQ(once.position(Vertex(v)), before.position(Vertex(v)));
  for (Index a = 1; a < 4; ++a) {
    EXPECT_FALSE(once.find_edge(Vertex(0), Vertex(a)).is_valid()) << a;  // flipped
    for (Index b = a + 1; b < 4; ++b) EXPECT_TRUE(once.find_edge(Vertex(a), Vertex(b)).is_valid()) << a << b;
  }

  Mesh twice = before;
  const SubdivideOptions two = creased(SubdivisionScheme::sqrt3, 100, 2);
  subdivide(twice, two);
  expect_valid(twice);
  // 3 x 12 triangles, and each crease cut in three adds two triangles on either side.
  EXPECT_EQ(twice.n_faces(), 36u + 3 * 4);
  EXPECT_EQ(subdivided_face_count(before, two), twice.n_faces());
  // Vertex 1 on the curve 2-1-3: (4, 19, 4) / 27.
  expect_point(twice.position(Vertex(1)), {{19.0 / 27, 4.0 / 27, 4.0 / 27}});
  // On crease 1-2, from vertex 1: (3 + 16 x 1 + 10 x 2) / 27; from vertex 2: (3 + 16 x 2 + 10 x 1) / 27.
  EXPECT_TRUE(has_point(twice, {{16.0 / 27, 10.0 / 27, 1.0 / 27}}));
  EXPECT_TRUE(has_point(twice, {{10.0 / 27, 16.0 / 27, 1.0 / 27}}));
  // The creases' 9 pieces join the curve's 9 points in one loop: each crease vertex, then the
  // points a third and two thirds on towards the next (in 27ths).
  const Vec3d loop[9] = {{{19, 4, 4}},  {{16, 10, 1}}, {{10, 16, 1}}, {{4, 19, 4}}, {{1, 16, 10}},
                         {{1, 10, 16}}, {{4, 4, 19}},  {{10, 1, 16}}, {{16, 1, 10}}};
  std::vector<Vertex> curve;
  for (const Vec3d& p : loop) {
    curve.push_back(find_point(twice, p / 27.0));
    ASSERT_TRUE(curve.back().is_valid()) << p[0] << " " << p[1] << " " << p[2];
  }
  for (std::size_t i = 0; i < 9; ++i)
    EXPECT_TRUE(twice.find_edge(curve[i], curve[(i + 1) % 9]).is_valid()) << "piece " << i;

  // At 60 every edge is a crease and every vertex a corner: the corners stay, the pieces of
  // each edge are its thirds.
  Mesh all = before;
  EXPECT_EQ(subdivide(all, creased(SubdivisionScheme::sqrt3, 60, 2)).crease_edges, 6u);
  expect_valid(all);
  for (Index v = 0; v < 4; ++v) EXPECT_EQ(all.position(Vertex(v)), before.position(Vertex(v)));
  EXPECT_TRUE(has_point(all, {{1.0 / 3, 0, 0}}));
  EXPECT_TRUE(has_point(all, {{2.0 / 3, 0, 0}}));
  EXPECT_TRUE(has_point(all, {{0, 1.0 / 3, 2.0 / 3}}));
}

// Default and 180 are the crease-free rules, bit for bit, and so is an angle no edge exceeds.
TEST(SubdivideCreases, NoCreaseIsTheOldResult) {
  for (auto s : {SubdivisionScheme::loop, SubdivisionScheme::catmull_clark, SubdivisionScheme::sqrt3}) {
    Mesh reference = tetrahedron();
    subdivide(reference, scheme(s, 2));
    for (double angle : {180.0, 130.0}) {
      Mesh mesh = tetrahedron();
      subdivide(mesh, creased(s, angle, 2));
      ASSERT_EQ(mesh.n_vertices(), reference.n_vertices());
      for (Vertex v : mesh.vertices()) EXPECT_EQ(mesh.position(v), reference.position(v)) << angle;
    }
  }
  // A flat grid bends nowhere, even at 0 degrees.
  Mesh flat = grid(3), reference = grid(3);
  subdivide(reference, scheme(SubdivisionScheme::loop));
  EXPECT_EQ(subdivide(flat, creased(SubdivisionScheme::loop, 0)).crease_edges, 0u);
  for (Vertex v : flat.vertices()) EXPECT_EQ(flat.position(v), reference.position(v));
}

// A fan of 8 triangles around the origin, ring vertex k at angle 45k degrees and height
// |sin(22.5 k degrees)|: the spoke to ring vertex 0 bends by 57 degrees, every other spoke by
// 25 or less. At 40 the centre is a dart (one crease: the smooth rule) and ring vertex 0 a
// corner (its two boundary edges and the crease: fixed); the other ring vertices follow the
// boundary rule.
Mesh dart_fan() {
  std::vector<Point> p = {{{0, 0, 0}}};
  for (int k = 0; k < 8; ++k) {
    const double t = 2 * std::numbers::pi * k / 8;
    p.push_back({{float(std::cos(t)), float(std::sin(t)), float(std::abs(std::sin(t / 2)))}});
  }
  std::vector<std::vector<Index>> f;
  for (Index k = 0; k < 8; ++k) f.push_back({0, 1 + k, 1 + (k + 1) % 8});
  return make_mesh(p, f);
}

//! The smooth rules of Loop and sqrt3 both keep 1 - t of the vertex and give t / n to each of
//! its n neighbours.
Vec3d ring_rule(const Mesh& m, Vertex v, double t) {
  const double n = double(m.valence(v));
  Vec3d want = at(m, v.idx()) * (1 - t);
  for (Vertex w : m.vertices(v)) want += at(m, w.idx()) * (t / n);
  return want;
}

Vec3d loop_smooth(const Mesh& m, Vertex v) {
  const double n = double(m.valence(v));
  const double c = 3.0 / 8.0 + 0.25 * std::cos(2.0 * std::numbers::pi / n), beta = (5.0 / 8.0 - c * c) / n;
  return ring_rule(m, v, n * beta);
}

TEST(SubdivideCreases, DartIsSmoothCornerIsFixed) {
  const Mesh before = dart_fan();
  Mesh mesh = before;
  EXPECT_EQ(subdivide(mesh, creased(SubdivisionScheme::loop, 40)).crease_edges, 1u);
  expect_valid(mesh);
  expect_point(mesh.position(Vertex(0)), loop_smooth(before, Vertex(0)), 1e-5);  // dart
  EXPECT_EQ(mesh.position(Vertex(1)), before.position(Vertex(1)));               // corner
  // Ring vertex 2 on the boundary: 6/8 itself, 1/8 ring vertices 1 and 3.
  expect_point(mesh.position(Vertex(2)), at(before, 2) * 0.75 + (at(before, 1) + at(before, 3)) * 0.125, 1e-6);
  // The crease's point is its midpoint; the next spoke's is Loop's 3/8, 3/8, 1/8, 1/8.
  const Edge crease = before.find_edge(Vertex(0), Vertex(1)), spoke = before.find_edge(Vertex(0), Vertex(2));
  const Index V = 9;
  expect_point(mesh.position(Vertex(V + crease.idx())), (at(before, 0) + at(before, 1)) * 0.5);
  expect_point(mesh.position(Vertex(V + spoke.idx())),
               (at(before, 0) + at(before, 2)) * 0.375 + (at(before, 1) + at(before, 3)) * 0.125);

  // Second step of the same run: the crease's two halves are still creases, so its point
  // (vertex V + crease) is a crease vertex between the centre and ring vertex 1, and the
  // centre is still a dart; nothing is measured again.
  Mesh twice = before;
  subdivide(twice, creased(SubdivisionScheme::loop, 40, 2));
  expect_valid(twice);
  const Index m = V + crease.idx();
  expect_point(twice.position(Vertex(m)), at(mesh, m) * 0.75 + (at(mesh, 0) + at(mesh, 1)) * 0.125, 1e-6);
  expect_point(twice.position(Vertex(0)), loop_smooth(mesh, Vertex(0)), 1e-5);
  EXPECT_EQ(twice.position(Vertex(1)), before.position(Vertex(1)));
  // Without creases the centre and ring vertex 1 would move differently.
  Mesh smooth = before;
  subdivide(smooth, scheme(SubdivisionScheme::loop));
  EXPECT_NE(smooth.position(Vertex(1)), before.position(Vertex(1)));
}

Vec3d sqrt3_smooth(const Mesh& m, Vertex v) {
  return ring_rule(m, v, (4 - 2 * std::cos(2 * std::numbers::pi / double(m.valence(v)))) / 9);
}

// The fan under sqrt3: the dart and the corner end the crease, so when the second step cuts
// it its two new points are its thirds (the curve rule has no neighbour beyond either end).
TEST(SubdivideCreases, Sqrt3DartIsSmoothCornerIsFixed) {
  const Mesh before = dart_fan();
  Mesh once = before, twice = before;
  EXPECT_EQ(subdivide(once, creased(SubdivisionScheme::sqrt3, 40)).crease_edges, 1u);
  subdivide(twice, creased(SubdivisionScheme::sqrt3, 40, 2));
  expect_valid(once);
  expect_valid(twice);
  expect_point(once.position(Vertex(0)), sqrt3_smooth(before, Vertex(0)), 1e-6);  // dart
  expect_point(twice.position(Vertex(0)), sqrt3_smooth(once, Vertex(0)), 1e-6);
  EXPECT_EQ(twice.position(Vertex(1)), before.position(Vertex(1)));  // corner
  ASSERT_TRUE(once.find_edge(Vertex(0), Vertex(1)).is_valid());      // the crease was not flipped
  EXPECT_FALSE(once.find_edge(Vertex(0), Vertex(2)).is_valid());     // a smooth spoke was
  expect_point(twice.position(Vertex(2)),  // ring vertex 2: (4, 19, 4) / 27 along the boundary
               (at(once, 1) * 4 + at(once, 2) * 19 + at(once, 3) * 4) / 27.0, 1e-6);
  const Vec3d c = at(once, 0), corner = at(once, 1);
  EXPECT_TRUE(has_point(twice, (c * 2 + corner) / 3.0));
  EXPECT_TRUE(has_point(twice, (c + corner * 2) / 3.0));
}

// A sheet folded along x = 2 (z = |x - 2|, a 90 degree ridge) with uv = xy and a vertex
// colour equal to the position: with the crease the sheet stays two planes, the ridge's
// ends (boundary corners) stay, and the attributes follow the crease stencils.
Mesh folded_sheet(bool triangles) {
  Mesh mesh = grid(4, triangles);
  for (Vertex v : mesh.vertices()) mesh.position(v)[2] = std::abs(mesh.position(v)[0] - 2);
  ChannelArray* uv = mesh.halfedge_properties().add_channel("uv", ScalarType::f32, 2);
  for (Face f : mesh.faces())
    for (Halfedge h : mesh.halfedges(f)) {
      const Point& p = mesh.position(mesh.to_vertex(h));
      const float value[2] = {p[0], p[1]};
      std::memcpy(uv->element(h.idx()), value, sizeof value);
    }
  ChannelArray* color = mesh.vertex_properties().add_channel("color", ScalarType::f32, 3);
  for (Vertex v : mesh.vertices()) std::memcpy(color->element(v.idx()), &mesh.position(v), sizeof(Point));
  return mesh;
}

TEST(SubdivideCreases, FoldStaysAFoldAndCarriesAttributes) {
  const std::pair<SubdivisionScheme, int> runs[] = {{SubdivisionScheme::loop, 2},
                                                    {SubdivisionScheme::catmull_clark, 2},
                                                    {SubdivisionScheme::sqrt3, 2},
                                                    {SubdivisionScheme::sqrt3, 4}};
  for (const auto& [s, iterations] : runs) {
    const std::string name = std::string(subdivision_scheme_name(s)) + " x" + std::to_string(iterations);
    Mesh mesh = folded_sheet(s != SubdivisionScheme::catmull_clark);
    const std::size_t corners_before = mesh.halfedge_properties().get_channel("uv")->size();
    EXPECT_EQ(subdivide(mesh, creased(s, 60, iterations)).crease_edges, 4u) << name;
    expect_valid(mesh);
    for (Vertex v : mesh.vertices()) {
      const Point& p = mesh.position(v);
      EXPECT_NEAR(p[2], std::abs(p[0] - 2), 1e-5f) << name << " vertex " << v.idx();
    }
    // The ridge's ends, (2, 0) and (2, 4), are corners; the ridge vertex (2, 2) stays on it.
    EXPECT_EQ(mesh.position(Vertex(2)), (Point{{2, 0, 0}})) << name;
    EXPECT_EQ(mesh.position(Vertex(22)), (Point{{2, 4, 0}})) << name;
    expect_point(mesh.position(Vertex(12)), {{2, 2, 0}});

    const ChannelArray* uv = mesh.halfedge_properties().get_channel("uv");
    const ChannelArray* color = mesh.vertex_properties().get_channel("color");
    ASSERT_TRUE(uv && color) << name;
    EXPECT_GT(uv->size(), corners_before);
    for (Vertex v : mesh.vertices()) {
      Point c;
      std::memcpy(&c, color->element(v.idx()), sizeof c);
      expect_point(c, to_double(mesh.position(v)), 1e-5);
    }
    // Corners on the ridge: positions and uvs both move along the line x = 2 by linear rules.
    std::size_t on_ridge = 0;
    for (Face f : mesh.faces())
      for (Halfedge h : mesh.halfedges(f)) {
        const Point& p = mesh.position(mesh.to_vertex(h));
        if (p[0] != 2.0f) continue;
        float value[2];
        std::memcpy(value, uv->element(h.idx()), sizeof value);
        EXPECT_NEAR(value[0], 2.0f, 1e-6f) << name;
        EXPECT_NEAR(value[1], p[1], 1e-5f) << name;
        ++on_ridge;
      }
    // The ridge's vertices after two steps: 17 (loop, catmull_clark), 13 (sqrt3; 37 after
    // four), each in 2 or more faces.
    EXPECT_GT(on_ridge, s != SubdivisionScheme::sqrt3 ? 33u : iterations == 2 ? 25u : 73u) << name;
  }
}

TEST(SubdivideCreases, Refusals) {
  Mesh mesh = tetrahedron();
  for (auto s : {SubdivisionScheme::loop, SubdivisionScheme::sqrt3})
    for (double bad : {-1.0, 181.0, std::nan("")}) {
      try {
        subdivide(mesh, creased(s, bad));
        ADD_FAILURE() << "no error for " << bad;
      } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("crease_angle must be from 0 to 180"), std::string::npos) << e.what();
      }
    }
  EXPECT_EQ(mesh.n_faces(), 4u);
  EXPECT_EQ(mesh.position(Vertex(1)), (Point{{1, 0, 0}}));
  // midpoint is linear: creases change nothing.
  Mesh plain = unit_cube(), with = unit_cube();
  subdivide(plain, scheme(SubdivisionScheme::midpoint));
  EXPECT_EQ(subdivide(with, creased(SubdivisionScheme::midpoint, 60)).crease_edges, 12u);
  for (Vertex v : plain.vertices()) EXPECT_EQ(plain.position(v), with.position(v));
}

TEST(SubdivideCreases, CatalogueParameter) {
  const Operation& op = find_operation("subdivide");
  const ParamSpec* p = op.find_param("crease_angle");
  ASSERT_NE(p, nullptr);
  EXPECT_EQ(p->type, ParamType::real);
  EXPECT_EQ(p->default_value, Value(180.0));
  EXPECT_EQ(p->range.min, 0);
  EXPECT_EQ(p->range.max, 180);
  EXPECT_FALSE(p->help.empty());
  Mesh mesh = unit_cube();
  OperationReport r = op.run(
      mesh, resolve_params(op, std::map<std::string, std::string>{{"scheme", "catmull_clark"}, {"crease_angle", "60"}}),
      Progress::none());
  expect_valid(mesh);
  ASSERT_NE(r.find("crease_edges"), nullptr);
  EXPECT_EQ(std::get<std::int64_t>(*r.find("crease_edges")), 12);
  EXPECT_EQ(on_unit_cube(mesh), 8u + 12u);
  EXPECT_THROW(resolve_params(op, std::map<std::string, std::string>{{"crease_angle", "181"}}), Error);
  // The default adds nothing to the report.
  Mesh plain = unit_cube();
  r = op.run(plain, resolve_params(op, std::map<std::string, std::string>{{"scheme", "catmull_clark"}}),
             Progress::none());
  EXPECT_EQ(r.find("crease_edges"), nullptr);
}

Mesh load(const std::string& name) {
  const std::string path = std::string(HEDGE_MESH_DIR) + "/" + name;
  if (!std::filesystem::exists(path)) return Mesh();
  return build(read_mesh(path)).mesh;
}

// Creases are measured on the input only. On the bunny at 30 degrees, measuring the first
// step's result again would find other creases (halves of some creases flatten below 30),
// so a second call differs from a second step; in the one call of two steps, the point of
// every input crease keeps the curve rule between its edge's ends.
TEST(SubdivideCreases, CreasesAreMeasuredOnceOnTheInput) {
  const Mesh bunny = load("bunny.off");
  if (bunny.is_empty()) GTEST_SKIP() << "bunny.off not found";
  const std::vector<Vec3f> normal = face_normals(bunny);
  std::vector<Edge> creases;
  for (Edge e : bunny.edges()) {
    if (bunny.is_boundary(e)) continue;
    const Vec3d a = to_double(normal[bunny.face(Mesh::halfedge(e, 0)).idx()]);
    const Vec3d b = to_double(normal[bunny.face(Mesh::halfedge(e, 1)).idx()]);
    if (angle_between(a, b) * 180 / std::numbers::pi > 30) creases.push_back(e);
  }
  Mesh once = bunny, twice = bunny;
  const SubdivideReport r = subdivide(once, creased(SubdivisionScheme::loop, 30));
  subdivide(twice, creased(SubdivisionScheme::loop, 30, 2));
  expect_valid(twice);
  ASSERT_EQ(r.crease_edges, creases.size());
  ASSERT_GT(creases.size(), 100u);
  const Index V = Index(bunny.vertices_size());
  for (Edge e : creases) {
    const Index m = V + e.idx(), a = bunny.vertex(e, 0).idx(), b = bunny.vertex(e, 1).idx();
    expect_point(twice.position(Vertex(m)), at(once, m) * 0.75 + (at(once, a) + at(once, b)) * 0.125, 1e-5);
  }
  Mesh again = once;
  subdivide(again, creased(SubdivisionScheme::loop, 30));
  std::size_t differ = 0;
  for (Vertex v : twice.vertices()) differ += again.position(v) != twice.position(v);
  EXPECT_GT(differ, 0u);
}

// The crease rules read a table made once before the steps: the result is the same at
// every thread count (small grain so the bunny takes the multi-threaded paths).
TEST(SubdivideCreases, SameResultAtEveryThreadCount) {
  const Mesh bunny = load("bunny.off");
  if (bunny.is_empty()) GTEST_SKIP() << "bunny.off not found";
  for (auto s : {SubdivisionScheme::loop, SubdivisionScheme::catmull_clark, SubdivisionScheme::sqrt3}) {
    Mesh reference;
    for (unsigned threads : {1u, 2u, 3u, 8u}) {
      hedge::testing::set_parallel_grain(64);
      const std::size_t splits = hedge::testing::parallel_splits();
      Mesh mesh = bunny;
      SubdivideOptions o = creased(s, 30, 2);
      o.threads = threads;
      const SubdivideReport r = subdivide(mesh, o);
      hedge::testing::set_parallel_grain(0);
      EXPECT_GT(r.crease_edges, 0u);
      if (threads == 1) {
        reference = mesh;
        continue;
      }
      EXPECT_GT(hedge::testing::parallel_splits(), splits);
      ASSERT_EQ(mesh.n_vertices(), reference.n_vertices());
      EXPECT_EQ(
          std::memcmp(mesh.positions().data(), reference.positions().data(), sizeof(Point) * mesh.positions().size()),
          0)
          << subdivision_scheme_name(s) << " at " << threads << " threads";
    }
  }
}

// sqrt3 creases on a real scan with 1,271 boundary loops and split non-manifold edges: the
// creases, boundaries and seams all meet, and the result stays valid, sized as forecast.
TEST(SubdivideCreases, Sqrt3OnAMessyScan) {
  const Mesh scan = load("dragon_res3.ply");
  if (scan.is_empty()) GTEST_SKIP() << "dragon_res3.ply not found";
  for (int iterations : {2, 3}) {
    Mesh mesh = scan;
    const SubdivideOptions options = creased(SubdivisionScheme::sqrt3, 30, iterations);
    const SubdivideReport r = subdivide(mesh, options);
    expect_valid(mesh);
    EXPECT_GT(r.crease_edges, 1000u);
    EXPECT_EQ(mesh.n_faces(), subdivided_face_count(scan, options));
    EXPECT_EQ(extract(mesh).n_faces(), mesh.n_faces());
  }
}

TEST(Subdivide, BunnyAllSchemes) {
  Mesh bunny = load("bunny.off");
  if (bunny.is_empty()) GTEST_SKIP() << "bunny.off not found";
  const double area = mesh_statistics(bunny).area;
  for (auto s : {SubdivisionScheme::loop, SubdivisionScheme::sqrt3, SubdivisionScheme::catmull_clark,
                 SubdivisionScheme::midpoint}) {
    Mesh mesh = bunny;
    subdivide(mesh, scheme(s, 2));
    expect_valid(mesh);
    EXPECT_EQ(mesh.n_faces(), subdivided_face_count(bunny, scheme(s, 2)));
    // Smoothing schemes shrink a little; nothing should blow up.
    const double ratio = mesh_statistics(mesh).area / area;
    EXPECT_GT(ratio, 0.8) << subdivision_scheme_name(s);
    EXPECT_LT(ratio, 1.05) << subdivision_scheme_name(s);
    // Soup round trip keeps the same face count.
    EXPECT_EQ(extract(mesh).n_faces(), mesh.n_faces());
  }
}

TEST(Subdivide, DragonLoopTiming) {
  const std::string path = std::string(HEDGE_MESH_DIR) + "/dragon.ply";
  if (!std::filesystem::exists(path)) GTEST_SKIP() << "dragon.ply not found";
  Mesh dragon = build(read_mesh(path)).mesh;
  ASSERT_GT(dragon.n_faces(), 800000u);
  // Wall time on two threads, and the process CPU time (the honest figure when other jobs
  // share the cores).
  double best = 1e9, best_cpu = 1e9;
  Mesh mesh;
  for (int run = 0; run < 3; ++run) {
    mesh = dragon;
    const auto start = std::chrono::steady_clock::now();
    const std::clock_t cpu_start = std::clock();
    subdivide(mesh, scheme(SubdivisionScheme::loop));
    best_cpu = std::min(best_cpu, double(std::clock() - cpu_start) / CLOCKS_PER_SEC);
    best = std::min(best, std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  }
  std::printf("[ figures  ] Loop subdivision of the dragon (%zu -> %zu faces): %.3f s wall, %.3f s CPU (best of 3)\n",
              dragon.n_faces(), mesh.n_faces(), best, best_cpu);
  EXPECT_EQ(mesh.n_faces(), 4 * dragon.n_faces());
  expect_valid(mesh);
}

// ---- selection_only --------------------------------------------------------------------------

//! Marks the faces for which `pick(centroid)` holds as selected (the "selected" face channel).
template <class Pick>
std::size_t select_faces(Mesh& mesh, Pick pick) {
  ChannelArray* channel = mesh.face_properties().get_channel("selected");
  if (!channel) channel = mesh.face_properties().add_channel("selected", ScalarType::u8, 1);
  std::size_t count = 0;
  for (Face f : mesh.faces()) {
    Vec3d centre{};
    for (Vertex v : mesh.vertices(f)) centre += to_double(mesh.position(v));
    const std::uint8_t on = pick(centre * (1.0 / double(mesh.valence(f)))) ? 1 : 0;
    *reinterpret_cast<std::uint8_t*>(channel->element(f.idx())) = on;
    count += on;
  }
  return count;
}

bool is_selected(const Mesh& mesh, Face f) {
  const ChannelArray* channel = mesh.face_properties().get_channel("selected");
  return channel && *reinterpret_cast<const std::uint8_t*>(channel->element(f.idx())) != 0;
}

using Corners = std::vector<std::array<float, 3>>;

//! The faces with selection flag `want`, each as its corner positions in order from the
//! smallest one on, sorted: what the host sees of them whatever the numbering.
std::vector<Corners> faces_where(const Mesh& mesh, bool want) {
  std::vector<Corners> out;
  for (Face f : mesh.faces()) {
    if (is_selected(mesh, f) != want) continue;
    Corners c;
    for (Vertex v : mesh.vertices(f)) c.push_back({mesh.position(v)[0], mesh.position(v)[1], mesh.position(v)[2]});
    std::rotate(c.begin(), std::min_element(c.begin(), c.end()), c.end());
    out.push_back(c);
  }
  std::sort(out.begin(), out.end());
  return out;
}

//! Selects the faces left of the median vertex x: about half of a real mesh.
std::size_t select_left_half(Mesh& mesh) {
  std::vector<float> xs;
  for (Vertex v : mesh.vertices()) xs.push_back(mesh.position(v)[0]);
  std::nth_element(xs.begin(), xs.begin() + std::ptrdiff_t(xs.size() / 2), xs.end());
  const double median = xs[xs.size() / 2];
  return select_faces(mesh, [&](const Vec3d& c) { return c[0] < median; });
}

SubdivideOptions selection_only(SubdivisionScheme s, int iterations = 1) {
  SubdivideOptions o = scheme(s, iterations);
  o.selection_only = true;
  return o;
}

//! What selection_only promises, checked on `after`, refined from `before` with options `o`.
void expect_selection_contract(const Mesh& before, const Mesh& after, const SubdivideOptions& o) {
  SCOPED_TRACE(std::string(subdivision_scheme_name(o.scheme)) + ", " + std::to_string(o.iterations) + " steps");
  expect_valid(after);
  // Unselected faces: the same corners in the same order, at bit-identical positions.
  EXPECT_EQ(faces_where(after, false), faces_where(before, false));
  // The selection grew by refinement.
  EXPECT_GT(faces_where(after, true).size(), faces_where(before, true).size());
  // No face repeats a vertex (a closure that wrapped around would).
  for (Face f : after.faces()) {
    std::vector<Index> corners;
    for (Vertex v : after.vertices(f)) corners.push_back(v.idx());
    std::sort(corners.begin(), corners.end());
    ASSERT_EQ(std::adjacent_find(corners.begin(), corners.end()), corners.end()) << "face " << f.idx();
  }
  // Watertight where it was: no new hole, and every boundary edge lies on the input's boundary
  // (a crack along the border would add boundary edges between the old boundary's vertices).
  const TopologyStats t0 = topology_stats(before), t1 = topology_stats(after);
  EXPECT_EQ(t1.boundary_loops, t0.boundary_loops);
  EXPECT_EQ(t1.components, t0.components);
  EXPECT_EQ(t1.euler_characteristic, t0.euler_characteristic);
  // Old vertices keep their indices; those on an unselected face stay, bit for bit.
  for (Vertex v : before.vertices()) {
    bool on_unselected = false;
    for (Face f : before.faces(v)) on_unselected = on_unselected || !is_selected(before, f);
    if (on_unselected) {
      EXPECT_EQ(std::memcmp(&after.position(v), &before.position(v), sizeof(Point)), 0) << "vertex " << v.idx();
    }
  }
}

const std::vector<SubdivisionScheme> kAllSchemes = {SubdivisionScheme::loop, SubdivisionScheme::catmull_clark,
                                                    SubdivisionScheme::sqrt3, SubdivisionScheme::midpoint};
const std::vector<SubdivisionScheme> kPolygonSchemes = {SubdivisionScheme::catmull_clark, SubdivisionScheme::midpoint};

TEST(SubdivideSelection, HalfAGridKeepsTheOtherHalf) {
  for (bool triangles : {true, false}) {
    Mesh before = grid(6, triangles);
    select_faces(before, [](const Vec3d& c) { return c[0] < 3.3; });
    for (auto s : triangles ? kAllSchemes : kPolygonSchemes)
      for (int iterations : {1, 2, 3}) {
        Mesh mesh = before;
        const SubdivideOptions o = selection_only(s, iterations);
        const SubdivideReport r = subdivide(mesh, o);
        expect_selection_contract(before, mesh, o);
        EXPECT_EQ(r.faces, mesh.n_faces());
        EXPECT_LE(mesh.n_faces(), subdivided_face_count(before, o));  // an upper bound
        // Every face is selected or as it was: children of selected faces stay selected.
        EXPECT_EQ(faces_where(mesh, false).size(), faces_where(before, false).size());
      }
  }
}

TEST(SubdivideSelection, BunnyHalfSelected) {
  Mesh bunny = load("bunny.off");
  if (bunny.is_empty()) GTEST_SKIP() << "bunny.off not found";
  Mesh quads = bunny;
  subdivide(quads, scheme(SubdivisionScheme::catmull_clark));
  ASSERT_GT(select_left_half(bunny), bunny.n_faces() / 3);
  ASSERT_GT(select_left_half(quads), quads.n_faces() / 3);
  for (const Mesh* input : {&bunny, &quads})
    for (auto s : input == &bunny ? kAllSchemes : kPolygonSchemes)
      for (int iterations : {1, 2}) {
        Mesh mesh = *input;
        const SubdivideOptions o = selection_only(s, iterations);
        subdivide(mesh, o);
        expect_selection_contract(*input, mesh, o);
        EXPECT_EQ(topology_stats(mesh).boundary_edges, topology_stats(*input).boundary_edges);
        EXPECT_LE(mesh.n_faces(), subdivided_face_count(*input, o));
        EXPECT_EQ(extract(mesh).n_faces(), mesh.n_faces());
      }
}

TEST(SubdivideSelection, EverythingSelectedIsTheWholeRun) {
  std::vector<std::pair<std::string, Mesh>> inputs = {
      {"open grid", grid(4)}, {"quad grid", grid(4, false)}, {"cube", unit_cube()}, {"tetrahedron", tetrahedron()}};
  if (Mesh bunny = load("bunny.off"); !bunny.is_empty()) inputs.emplace_back("bunny", std::move(bunny));
  for (auto& [name, input] : inputs) {
    select_faces(input, [](const Vec3d&) { return true; });
    for (auto s : input.is_triangle_mesh() ? kAllSchemes : kPolygonSchemes)
      for (int iterations : {1, 2}) {
        SCOPED_TRACE(name + ", " + subdivision_scheme_name(s) + ", " + std::to_string(iterations) + " steps");
        Mesh whole = input, selected = input;
        subdivide(whole, scheme(s, iterations));
        subdivide(selected, selection_only(s, iterations));
        test::expect_same_elements(selected, whole);
        EXPECT_EQ(subdivided_face_count(input, selection_only(s, iterations)), whole.n_faces());
      }
  }
}

// The closures, face by face, on strips where the selected face has 0 to 3 split edges.
TEST(SubdivideSelection, TrianglesClosedRedGreen) {
  // A fan of triangles around vertex 0 on an open disc: selecting one triangle leaves its
  // outer (boundary) edge split, its two spokes whole: 1 edge point, 2 triangles.
  const Mesh fan = make_mesh({{{0, 0, 0}}, {{1, 0, 0}}, {{0, 1, 0}}, {{-1, 0, 0}}, {{0, -1, 0}}},
                             {{0, 1, 2}, {0, 2, 3}, {0, 3, 4}, {0, 4, 1}});
  for (auto s : {SubdivisionScheme::loop, SubdivisionScheme::midpoint}) {
    Mesh mesh = fan;
    select_faces(mesh, [](const Vec3d& c) { return c[0] > 0 && c[1] > 0; });
    const Mesh before = mesh;
    subdivide(mesh, selection_only(s));
    expect_selection_contract(before, mesh, selection_only(s));
    EXPECT_EQ(mesh.n_vertices(), 6u);
    EXPECT_EQ(mesh.n_faces(), 3u + 2u);
    // Two adjacent triangles selected: each has its boundary edge and the shared spoke split.
    mesh = fan;
    select_faces(mesh, [](const Vec3d& c) { return c[1] > 0; });
    const Mesh two = mesh;
    subdivide(mesh, selection_only(s));
    expect_selection_contract(two, mesh, selection_only(s));
    EXPECT_EQ(mesh.n_vertices(), 5u + 3u);
    EXPECT_EQ(mesh.n_faces(), 2u + 3u + 3u);
  }
  // The quad c0 c1 m m' of a triangle with one whole edge is cut along its shorter diagonal:
  // in a long flat triangle (0,0)-(10,0)-(0,1) with edge (0,0)-(10,0) whole, from (0,0) to the
  // middle of the far edge, not from (10,0) across the whole length.
  Mesh pair = make_mesh({{{0, 0, 0}}, {{10, 0, 0}}, {{0, 1, 0}}, {{5, -1, 0}}}, {{0, 1, 2}, {1, 0, 3}});
  select_faces(pair, [](const Vec3d& c) { return c[1] > 0; });
  subdivide(pair, selection_only(SubdivisionScheme::midpoint));
  expect_valid(pair);
  ASSERT_EQ(pair.n_faces(), 1u + 3u);
  bool short_diagonal = false, long_diagonal = false;
  for (Edge e : pair.edges()) {
    const Vec3d a = to_double(pair.position(pair.vertex(e, 0))), b = to_double(pair.position(pair.vertex(e, 1)));
    auto joins = [&](const Vec3d& p, const Vec3d& q) { return (a == p && b == q) || (a == q && b == p); };
    short_diagonal = short_diagonal || joins({{0, 0, 0}}, {{5, 0.5, 0}});
    long_diagonal = long_diagonal || joins({{10, 0, 0}}, {{0, 0.5, 0}});
  }
  EXPECT_TRUE(short_diagonal);
  EXPECT_FALSE(long_diagonal);
}

TEST(SubdivideSelection, PolygonsClosedAroundTheirFacePoint) {
  // A 3 x 3 grid of quads: the middle quad of the bottom row has its bottom edge on the
  // boundary (split) and three whole edges: 1 edge point, a face point, 2 pieces.
  const Mesh quads = grid(3, false);
  for (auto s : kPolygonSchemes) {
    Mesh mesh = quads;
    select_faces(mesh, [](const Vec3d& c) { return c[0] > 1 && c[0] < 2 && c[1] < 1; });
    const Mesh one = mesh;
    subdivide(mesh, selection_only(s));
    expect_selection_contract(one, mesh, selection_only(s));
    EXPECT_EQ(mesh.n_vertices(), 16u + 2u);
    EXPECT_EQ(mesh.n_faces(), 8u + 2u);
    std::multiset<std::size_t> sizes;
    for (Face f : mesh.faces())
      if (is_selected(mesh, f)) sizes.insert(mesh.valence(f));
    EXPECT_EQ(sizes, (std::multiset<std::size_t>{4, 5}));
    // The centre quad of the 3 x 3 grid: no edge split, so it stays as it is.
    mesh = quads;
    select_faces(mesh, [](const Vec3d& c) { return c[0] > 1 && c[0] < 2 && c[1] > 1 && c[1] < 2; });
    const Mesh centre = mesh;
    subdivide(mesh, selection_only(s));
    expect_valid(mesh);
    EXPECT_EQ(faces_where(mesh, true), faces_where(centre, true));
    EXPECT_EQ(mesh.n_vertices(), 16u);
    // The left column: each quad has three split edges and one whole (its right side);
    // every piece is a quad or, over the whole edge, a pentagon.
    mesh = quads;
    select_faces(mesh, [](const Vec3d& c) { return c[0] < 1; });
    const Mesh column = mesh;
    subdivide(mesh, selection_only(s));
    expect_selection_contract(column, mesh, selection_only(s));
    for (Face f : mesh.faces())
      if (is_selected(mesh, f)) {
        EXPECT_GE(mesh.valence(f), 4u);
        EXPECT_LE(mesh.valence(f), 5u);
      }
  }
  // A Catmull–Clark triangle with one split edge (its boundary edge; both spokes of the fan
  // are whole): two quads through the opposite corner.
  Mesh fan = make_mesh({{{0, 0, 0}}, {{1, 0, 0}}, {{0, 1, 0}}, {{-1, 0, 0}}, {{0, -1, 0}}},
                       {{0, 1, 2}, {0, 2, 3}, {0, 3, 4}, {0, 4, 1}});
  select_faces(fan, [](const Vec3d& c) { return c[0] > 0 && c[1] > 0; });
  const Mesh before = fan;
  subdivide(fan, selection_only(SubdivisionScheme::catmull_clark));
  expect_selection_contract(before, fan, selection_only(SubdivisionScheme::catmull_clark));
  EXPECT_EQ(fan.n_faces(), 3u + 2u);
  for (Face f : fan.faces())
    if (is_selected(fan, f)) {
      EXPECT_EQ(fan.valence(f), 4u);
    }
}

TEST(SubdivideSelection, AttributesFollowTheNormalRules) {
  // uv = xy on a flat grid: midpoint subdivision is linear, so every corner of every piece
  // (closures included) keeps uv = xy; faces keep their parent's material, and children of
  // selected faces are selected.
  Mesh mesh = grid_with_uv(4);
  ChannelArray* material = mesh.face_properties().add_channel("material", ScalarType::i32, 1);
  for (Face f : mesh.faces()) *reinterpret_cast<std::int32_t*>(material->element(f.idx())) = std::int32_t(f.idx());
  select_faces(mesh, [](const Vec3d& c) { return c[0] + c[1] < 4; });
  std::map<std::int32_t, std::uint8_t> parent_selected;
  for (Face f : mesh.faces()) parent_selected[std::int32_t(f.idx())] = is_selected(mesh, f);
  const Mesh before = mesh;
  for (auto s : {SubdivisionScheme::midpoint, SubdivisionScheme::catmull_clark, SubdivisionScheme::sqrt3}) {
    mesh = before;
    subdivide(mesh, selection_only(s, 2));
    expect_selection_contract(before, mesh, selection_only(s, 2));
    const ChannelArray* uv = mesh.halfedge_properties().get_channel("uv");
    material = mesh.face_properties().get_channel("material");
    ASSERT_TRUE(uv && material);
    for (Face f : mesh.faces()) {
      const std::int32_t parent = *reinterpret_cast<const std::int32_t*>(material->element(f.idx()));
      EXPECT_EQ(is_selected(mesh, f), parent_selected[parent] != 0);
      for (Halfedge h : mesh.halfedges(f)) {
        float value[2];
        std::memcpy(value, uv->element(h.idx()), sizeof value);
        const Point& p = mesh.position(mesh.to_vertex(h));
        // Catmull–Clark and sqrt3 move the vertices inside the selection; uv stays linear.
        if (s == SubdivisionScheme::midpoint) {
          EXPECT_NEAR(value[0], p[0], 1e-5f);
          EXPECT_NEAR(value[1], p[1], 1e-5f);
        } else if (!is_selected(mesh, f)) {
          EXPECT_EQ(value[0], p[0]);
          EXPECT_EQ(value[1], p[1]);
        }
      }
    }
  }
}

TEST(SubdivideSelection, OnlySelectedFacesMustBeTriangles) {
  // A pyramid: its quad base unselected, its triangles selected: loop and sqrt3 refine them.
  const Mesh pyramid = make_mesh({{{0, 0, 0}}, {{1, 0, 0}}, {{1, 1, 0}}, {{0, 1, 0}}, {{0.5f, 0.5f, 1}}},
                                 {{0, 3, 2, 1}, {0, 1, 4}, {1, 2, 4}, {2, 3, 4}, {3, 0, 4}});
  for (auto s : {SubdivisionScheme::loop, SubdivisionScheme::sqrt3})
    for (int iterations : {1, 2}) {
      Mesh mesh = pyramid;
      select_faces(mesh, [](const Vec3d& c) { return c[2] > 0; });
      const Mesh before = mesh;
      subdivide(mesh, selection_only(s, iterations));
      expect_selection_contract(before, mesh, selection_only(s, iterations));
      EXPECT_EQ(topology_stats(mesh).boundary_loops, 0u);
      // Selecting the base too is refused, and leaves the mesh.
      mesh = pyramid;
      select_faces(mesh, [](const Vec3d&) { return true; });
      try {
        subdivide(mesh, selection_only(s));
        ADD_FAILURE() << "no error";
      } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("1 selected face has more than 3 corners"), std::string::npos) << e.what();
      }
      EXPECT_EQ(mesh.n_faces(), 5u);
    }
}

TEST(SubdivideSelection, NothingSelectedChangesNothing) {
  for (bool with_channel : {false, true}) {
    Mesh mesh = unit_cube();  // quads: loop would refuse them, but nothing is to be refined
    if (with_channel) select_faces(mesh, [](const Vec3d&) { return false; });
    const Mesh before = mesh;
    const SubdivideReport r = subdivide(mesh, selection_only(SubdivisionScheme::loop, 2));
    test::expect_same_elements(mesh, before);
    EXPECT_EQ(r.faces, 6u);
    EXPECT_EQ(r.faces_before, 6u);
    EXPECT_EQ(subdivided_face_count(before, selection_only(SubdivisionScheme::loop, 2)), 6u);
  }
  // Through the catalogue, the binding says so.
  Soup soup = extract(unit_cube());
  soup.add_channel("selected", Domain::face, ScalarType::u8, 1);
  const Operation& op = find_operation("subdivide");
  const RunResult result = run_operation(
      op, soup, resolve_params(op, std::map<std::string, std::string>{{"selection_only", "true"}}), Progress::none());
  EXPECT_EQ(result.soup.n_faces(), 6u);
  EXPECT_NE(std::find(result.report.messages.begin(), result.report.messages.end(),
                      "selection_only: nothing is selected, so the mesh is unchanged"),
            result.report.messages.end());
}

TEST(SubdivideSelection, CreasesAndBoundariesInsideTheSelection) {
  // An open grid with a fold, half selected: creases inside the selection keep their rules,
  // the border holds; sqrt3's second step cuts only the selected part of the boundary.
  for (bool triangles : {true, false}) {
    Mesh before = folded_sheet(triangles);
    select_faces(before, [](const Vec3d& c) { return c[1] < 1.5; });
    for (auto s : triangles ? kAllSchemes : kPolygonSchemes)
      for (int iterations : {1, 2}) {
        Mesh mesh = before;
        SubdivideOptions o = selection_only(s, iterations);
        o.crease_angle = 30;
        const SubdivideReport r = subdivide(mesh, o);
        expect_selection_contract(before, mesh, o);
        EXPECT_GT(r.crease_edges, 0u);
        EXPECT_LE(mesh.n_faces(), subdivided_face_count(before, o));
      }
  }
}

// The two glued tetrahedra and the fin of SeamsOfNonManifoldInputStayClosed, through the
// host pipeline (build, subdivide, extract): with one tetrahedron selected, the glued edge
// has selected and unselected faces on its copies, so none of them is split and the weld
// finds the five faces on one edge again; nothing else opens.
TEST(SubdivideSelection, SplitNonManifoldEdgesStayWhole) {
  Soup soup;
  soup.positions = {{{0, 0, 0}}, {{1, 0, 0}}, {{0, 1, 0}}, {{0, 0, 1}}, {{0, -1, 0}}, {{0, 0, -1}}};
  soup.positions.push_back({{0.5f, 0.5f, 0.5f}});
  for (std::uint32_t c : {0, 2, 1, 0, 1, 3, 1, 2, 3, 2, 0, 3, 0, 4, 1, 0, 1, 5, 1, 4, 5, 4, 0, 5, 0, 1, 6})
    soup.corners.push_back(c);
  soup.face_sizes.assign(9, 3);
  std::uint8_t* selected = soup.add_channel("selected", Domain::face, ScalarType::u8, 1).as<std::uint8_t>();
  for (std::size_t f = 0; f < 4; ++f) selected[f] = 1;
  const Operation& op = find_operation("subdivide");
  for (auto s : kAllSchemes)
    for (int iterations : {1, 2}) {
      SCOPED_TRACE(std::string(subdivision_scheme_name(s)) + ", " + std::to_string(iterations) + " steps");
      const RunResult r = run_operation(
          op, soup,
          resolve_params(op, std::map<std::string, std::string>{{"scheme", subdivision_scheme_name(s)},
                                                                {"iterations", std::to_string(iterations)},
                                                                {"selection_only", "true"}}),
          Progress::none());
      const Soup& out = r.soup;
      std::map<std::pair<std::uint32_t, std::uint32_t>, int> faces_on_edge;
      const auto offsets = out.face_offsets();
      for (std::size_t f = 0; f < out.n_faces(); ++f)
        for (std::uint32_t k = offsets[f]; k < offsets[f + 1]; ++k) {
          const std::uint32_t a = out.corners[k], b = out.corners[k + 1 < offsets[f + 1] ? k + 1 : offsets[f]];
          ++faces_on_edge[{std::min(a, b), std::max(a, b)}];
        }
      std::size_t open = 0, glued = 0, other = 0;
      for (const auto& [edge, n] : faces_on_edge) {
        open += n == 1;
        glued += n == 5;
        other += n != 1 && n != 2 && n != 5;
      }
      EXPECT_EQ(open, 2u);  // the fin's free sides, unselected
      EXPECT_EQ(glued, 1u);
      EXPECT_EQ(other, 0u);
      EXPECT_GT(out.n_faces(), soup.n_faces());
      // The unselected faces come back as they were.
      const std::uint8_t* out_selected = out.find("selected", Domain::face)->as<std::uint8_t>();
      std::multiset<std::vector<std::uint32_t>> kept;
      for (std::size_t f = 0; f < out.n_faces(); ++f)
        if (!out_selected[f]) kept.insert({out.corners.begin() + offsets[f], out.corners.begin() + offsets[f + 1]});
      EXPECT_EQ(kept.size(), 5u);
      for (std::size_t f = 4; f < 9; ++f) {
        bool found = false;
        for (const auto& corners : kept) {
          std::vector<std::uint32_t> want(soup.corners.begin() + 3 * f, soup.corners.begin() + 3 * f + 3);
          for (int turn = 0; turn < 3 && !found; ++turn) {
            std::vector<Point> a, b;
            for (std::uint32_t c : corners) a.push_back(out.positions[c]);
            for (std::uint32_t c : want) b.push_back(soup.positions[c]);
            found = a == b;
            std::rotate(want.begin(), want.begin() + 1, want.end());
          }
        }
        EXPECT_TRUE(found) << "input face " << f;
      }
    }
}

// A real scan with holes and split non-manifold edges, half selected.
TEST(SubdivideSelection, MessyScanHalfSelected) {
  Mesh scan = load("dragon_res3.ply");
  if (scan.is_empty()) GTEST_SKIP() << "dragon_res3.ply not found";
  select_left_half(scan);
  for (auto s : kAllSchemes) {
    Mesh mesh = scan;
    const SubdivideOptions o = selection_only(s, 2);
    subdivide(mesh, o);
    expect_selection_contract(scan, mesh, o);
    EXPECT_LE(mesh.n_faces(), subdivided_face_count(scan, o));
    EXPECT_EQ(extract(mesh).n_faces(), mesh.n_faces());
  }
}

TEST(SubdivideSelection, SameResultAtEveryThreadCount) {
  Mesh bunny = load("bunny.off");
  if (bunny.is_empty()) GTEST_SKIP() << "bunny.off not found";
  select_left_half(bunny);
  for (auto s : kAllSchemes) {
    Mesh reference;
    for (unsigned threads : {1u, 3u}) {
      hedge::testing::set_parallel_grain(64);
      Mesh mesh = bunny;
      SubdivideOptions o = selection_only(s, 2);
      o.threads = threads;
      subdivide(mesh, o);
      hedge::testing::set_parallel_grain(0);
      if (threads == 1) {
        reference = mesh;
        continue;
      }
      SCOPED_TRACE(subdivision_scheme_name(s));
      test::expect_same_elements(mesh, reference);
    }
  }
}

TEST(SubdivideSelection, CatalogueParameter) {
  const Operation& op = find_operation("subdivide");
  const ParamSpec* p = op.find_param("selection_only");
  ASSERT_NE(p, nullptr);
  EXPECT_EQ(p->default_value, Value(false));
}

}  // namespace
