// Tests of hole filling (fill_holes.h): every hole within the limit closed, watertight
// results, large holes skipped, smooth faired patches, attributes carried, huge holes.
#include "hedge/fill_holes.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <map>
#include <numbers>
#include <set>
#include <vector>

#include "defect_counts.h"
#include "hedge/build.h"
#include "hedge/catalogue.h"
#include "hedge/io.h"
#include "hedge/provenance.h"
#include "hedge/repair.h"
#include "hedge/report.h"
#include "hedge/topology.h"
#include "hedge/validate.h"
#include "test_meshes.h"

namespace hedge {
namespace {

std::vector<std::size_t> loop_lengths(const Mesh& mesh) {
  std::vector<char> seen(mesh.halfedges_size(), 0);
  std::vector<std::size_t> out;
  for (Halfedge h : mesh.halfedges()) {
    if (!mesh.is_boundary(h) || seen[h.idx()]) continue;
    std::size_t n = 0;
    for (Halfedge g : mesh.loop(h)) {
      seen[g.idx()] = 1;
      ++n;
    }
    out.push_back(n);
  }
  return out;
}

// Closed: no boundary half-edge, so every edge has two faces.
bool watertight(const Mesh& mesh) {
  for (Halfedge h : mesh.halfedges())
    if (mesh.is_boundary(h)) return false;
  return true;
}

std::size_t multi_edges(const Mesh& mesh) { return mesh_statistics(mesh).multi_edges; }

// Shape of the triangles with index >= first (the patch) and edge lengths of the others.
struct PatchStats {
  std::size_t triangles = 0;
  double min_angle = 180, mean_min_angle = 0, mean_quality = 0, mean_edge = 0, mean_edge_outside = 0;
};
PatchStats patch_stats(const Mesh& mesh, std::size_t first) {
  PatchStats s;
  std::size_t edges = 0, outside = 0;
  for (Face f : mesh.faces()) {
    std::vector<Vec3d> p;
    for (Vertex v : mesh.vertices(f)) p.push_back(to_double(mesh.position(v)));
    const bool patch = f.idx() >= first;
    for (std::size_t i = 0; i < p.size(); ++i) {
      const double l = distance(p[i], p[(i + 1) % p.size()]);
      (patch ? s.mean_edge : s.mean_edge_outside) += l;
      ++(patch ? edges : outside);
    }
    if (!patch || p.size() != 3) continue;
    const double a = triangle_min_angle(p[0], p[1], p[2]);
    s.min_angle = std::min(s.min_angle, a);
    s.mean_min_angle += a;
    s.mean_quality += triangle_quality(p[0], p[1], p[2]);
    ++s.triangles;
  }
  if (s.triangles) {
    s.mean_min_angle /= double(s.triangles);
    s.mean_quality /= double(s.triangles);
  }
  if (edges) s.mean_edge /= double(edges);
  if (outside) s.mean_edge_outside /= double(outside);
  return s;
}

// A unit sphere with the cap above polar angle `hole_degrees` removed (a hole of
// `segments` edges); the south pole is closed by a fan. Outward orientation.
Soup sphere_with_hole(int segments, double hole_degrees) {
  Soup s;
  const double step = 2 * std::numbers::pi / segments;
  const double theta0 = hole_degrees * std::numbers::pi / 180;
  const int rings = int(std::round((std::numbers::pi - theta0) / step));
  for (int k = 0; k < rings; ++k) {
    const double theta = theta0 + (std::numbers::pi - theta0) * k / rings;
    for (int j = 0; j < segments; ++j) {
      const double phi = j * step;
      s.positions.push_back(Point{
          {float(std::sin(theta) * std::cos(phi)), float(std::sin(theta) * std::sin(phi)), float(std::cos(theta))}});
    }
  }
  const std::uint32_t pole = std::uint32_t(s.positions.size());
  s.positions.push_back(Point{{0, 0, -1}});
  auto id = [&](int k, int j) { return std::uint32_t(k * segments + (j % segments)); };
  for (int k = 0; k + 1 < rings; ++k)
    for (int j = 0; j < segments; ++j) {
      s.add_face({id(k, j), id(k + 1, j), id(k + 1, j + 1)});
      s.add_face({id(k, j), id(k + 1, j + 1), id(k, j + 1)});
    }
  for (int j = 0; j < segments; ++j) s.add_face({id(rings - 1, j), pole, id(rings - 1, j + 1)});
  return s;
}

// An n x n grid of unit squares (triangulated) in the plane z = 0, with the squares whose
// centre lies within `hole_radius` of the middle left out.
Soup grid_with_hole(int n, double hole_radius) {
  Soup s;
  for (int y = 0; y <= n; ++y)
    for (int x = 0; x <= n; ++x) s.positions.push_back(Point{{float(x), float(y), 0}});
  auto id = [&](int x, int y) { return std::uint32_t(y * (n + 1) + x); };
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      double cx = x + 0.5 - n / 2.0, cy = y + 0.5 - n / 2.0;
      if (std::hypot(cx, cy) < hole_radius) continue;
      s.add_face({id(x, y), id(x + 1, y), id(x + 1, y + 1)});
      s.add_face({id(x, y), id(x + 1, y + 1), id(x, y + 1)});
    }
  return s;
}

Mesh load(const std::string& name) { return build(read_mesh(std::string(HEDGE_MESH_DIR) + "/" + name)).mesh; }

bool have(const std::string& name) { return std::filesystem::exists(std::string(HEDGE_MESH_DIR) + "/" + name); }

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

TEST(FillHoles, SingleHoleInAPlaneAndItsBorder) {
  // MeshLab's behaviour: every loop within the limit is a hole, the sheet's border too.
  Mesh mesh = build(grid_with_hole(12, 3)).mesh;
  ASSERT_EQ(loop_lengths(mesh).size(), 2u);
  FillHolesReport r = fill_holes(mesh);
  ASSERT_VALID(mesh);
  EXPECT_EQ(r.holes_found, 2u);
  EXPECT_EQ(r.holes_filled, 2u);
  EXPECT_EQ(r.holes_skipped, 0u);
  EXPECT_TRUE(watertight(mesh));
  EXPECT_EQ(multi_edges(mesh), 0u);
  EXPECT_GT(r.vertices_added, 0u);  // refined: the outer patch is large
  EXPECT_EQ(topology_stats(mesh).genus, 0);
}

TEST(FillHoles, PatchIsSizedAndShapedLikeItsSurroundings) {
  Mesh mesh = build(grid_with_hole(30, 8)).mesh;
  const std::size_t first = mesh.faces_size();
  FillHolesOptions options;
  options.max_hole_edges = 100;  // the hole, not the sheet's border
  FillHolesReport r = fill_holes(mesh, options);
  ASSERT_VALID(mesh);
  ASSERT_EQ(r.holes_filled, 1u);
  const PatchStats s = patch_stats(mesh, first);
  std::printf(
      "[ fill_holes ] round hole in a grid: %zu triangles, mean edge %.3f (around: %.3f), min angle %.1f, "
      "mean min angle %.1f, mean quality %.3f\n",
      s.triangles, s.mean_edge, s.mean_edge_outside, s.min_angle, s.mean_min_angle, s.mean_quality);
  EXPECT_GT(s.mean_edge, 0.7 * s.mean_edge_outside);
  EXPECT_LT(s.mean_edge, 1.4 * s.mean_edge_outside);
  EXPECT_GT(s.mean_quality, 0.7);
  EXPECT_GT(s.min_angle, 10.0);
  for (Vertex v : mesh.vertices()) EXPECT_EQ(mesh.position(v)[2], 0.0f);  // a flat hole stays flat
}

TEST(FillHoles, MaxHoleEdgesLeavesLargeHolesOpen) {
  Mesh mesh = build(grid_with_hole(12, 3)).mesh;
  std::vector<std::size_t> before = loop_lengths(mesh);
  std::size_t small = std::min(before[0], before[1]), large = std::max(before[0], before[1]);
  FillHolesOptions options;
  options.max_hole_edges = small;
  FillHolesReport r = fill_holes(mesh, options);
  ASSERT_VALID(mesh);
  EXPECT_EQ(r.holes_filled, 1u);
  EXPECT_EQ(r.holes_skipped, 1u);
  EXPECT_EQ(r.holes_too_large, 1u);
  EXPECT_EQ(r.largest_skipped_edges, large);
  EXPECT_EQ(loop_lengths(mesh), std::vector<std::size_t>{large});
  ASSERT_FALSE(r.messages.empty());
}

TEST(FillHoles, UnrefinedFillAddsOnlyTriangles) {
  Mesh mesh = build(grid_with_hole(10, 2.5)).mesh;
  const std::size_t faces = mesh.n_faces(), vertices = mesh.n_vertices();
  FillHolesOptions options;
  options.refine = false;
  options.fair = false;
  options.max_hole_edges = 30;
  FillHolesReport r = fill_holes(mesh, options);
  ASSERT_VALID(mesh);
  ASSERT_EQ(r.holes_filled, 1u);
  std::size_t hole = 0;
  for (std::size_t n : loop_lengths(build(grid_with_hole(10, 2.5)).mesh)) hole = n <= 30 ? n : hole;
  EXPECT_EQ(mesh.n_vertices(), vertices);
  EXPECT_EQ(mesh.n_faces(), faces + hole - 2);  // a polygon of n corners takes n - 2 triangles
  EXPECT_EQ(r.triangles_added, hole - 2);
  EXPECT_TRUE(mesh.is_triangle_mesh());
  // A flat hole gets a flat patch: no new triangle bends out of the plane.
  for (Vertex v : mesh.vertices()) EXPECT_EQ(mesh.position(v)[2], 0.0f);
}

TEST(FillHoles, FairedPatchFollowsTheSphere) {
  for (FairingWeights weights : {FairingWeights::cotangent, FairingWeights::uniform}) {
    Mesh mesh = build(sphere_with_hole(48, 40)).mesh;
    const std::size_t original = mesh.n_vertices();
    FillHolesOptions options;
    options.weights = weights;
    FillHolesReport r = fill_holes(mesh, options);
    ASSERT_VALID(mesh);
    ASSERT_EQ(r.holes_filled, 1u);
    EXPECT_TRUE(watertight(mesh));
    ASSERT_GT(r.vertices_added, 50u);
    double worst = 0, flat_worst = 0;
    for (Vertex v : mesh.vertices()) {
      if (v.idx() < original) continue;
      worst = std::max(worst, std::abs(double(norm(mesh.position(v))) - 1.0));
    }
    // Without fairing the patch is a flat disc: the cap's height off the sphere.
    flat_worst = 1 - std::cos(40 * std::numbers::pi / 180);
    std::printf(
        "[ fill_holes ] sphere cap of 40 degrees, %s weights: %zu new vertices, worst radius error %.4f "
        "(flat patch %.4f)\n",
        weights == FairingWeights::cotangent ? "cotangent" : "uniform", r.vertices_added, worst, flat_worst);
    EXPECT_LT(worst, weights == FairingWeights::uniform ? 0.02 : 0.03);
    // Triangles sized like the sphere's (edge ~ 2 pi / 48 = 0.13).
    MeshStatistics s = mesh_statistics(mesh);
    EXPECT_LT(s.edge_length_max, 0.4);
    EXPECT_GT(s.min_angle_degrees, 5.0);
  }
}

TEST(FillHoles, FairedPatchFollowsAParaboloid) {
  // z = r^2 / 40 over a 20 x 20 grid with an 8 x 8 hole: Δ²z = 0, so a consistent
  // bi-Laplacian puts the patch back on it.
  auto height = [](double x, double y) { return ((x - 10) * (x - 10) + (y - 10) * (y - 10)) / 40; };
  Soup soup;
  for (int y = 0; y <= 20; ++y)
    for (int x = 0; x <= 20; ++x) soup.positions.push_back(Point{{float(x), float(y), float(height(x, y))}});
  for (std::uint32_t y = 0; y < 20; ++y)
    for (std::uint32_t x = 0; x < 20; ++x) {
      if (x >= 6 && x < 14 && y >= 6 && y < 14) continue;
      const std::uint32_t a = y * 21 + x, b = a + 1, c = a + 22, d = a + 21;
      soup.add_face({a, b, c});
      soup.add_face({a, c, d});
    }
  for (FairingWeights weights : {FairingWeights::cotangent, FairingWeights::uniform}) {
    Mesh mesh = build(soup).mesh;
    FillHolesOptions options;
    options.max_hole_edges = 40;
    options.weights = weights;
    FillHolesReport r = fill_holes(mesh, options);
    ASSERT_VALID(mesh);
    ASSERT_EQ(r.holes_filled, 1u);
    double worst = 0;
    for (Vertex v : mesh.vertices())
      if (v.idx() >= soup.n_vertices()) {
        const Point& p = mesh.position(v);
        worst = std::max(worst, std::abs(p[2] - height(p[0], p[1])));
      }
    std::printf("[ fill_holes ] paraboloid, hole of 8 x 8 (depth 0.8), %s weights: worst height error %.4f\n",
                weights == FairingWeights::cotangent ? "cotangent" : "uniform", worst);
    EXPECT_LT(worst, weights == FairingWeights::cotangent ? 0.02 : 0.1);
  }
}

TEST(FillHoles, AttributesAreCarried) {
  Soup soup = grid_with_hole(10, 2.5);
  const std::size_t nv = soup.n_vertices(), nf = soup.n_faces(), nc = soup.n_corners();
  // add_channel may move the channels: take references once all are added.
  soup.add_channel("quality", Domain::vertex, ScalarType::f32, 1);
  soup.add_channel("material", Domain::face, ScalarType::i32, 1);
  soup.add_channel("uv", Domain::corner, ScalarType::f32, 2);
  Channel& quality = *soup.find("quality", Domain::vertex);
  Channel& material = *soup.find("material", Domain::face);
  Channel& uv = *soup.find("uv", Domain::corner);
  ASSERT_EQ(quality.count(), nv);
  for (std::size_t v = 0; v < nv; ++v) quality.as<float>()[v] = 1 + soup.positions[v][0];  // 1 .. 11
  for (std::size_t f = 0; f < nf; ++f) material.as<std::int32_t>()[f] = 7;
  for (std::size_t c = 0; c < nc; ++c) {
    const Point& p = soup.positions[soup.corners[c]];
    uv.as<float>()[2 * c] = p[0] / 10;
    uv.as<float>()[2 * c + 1] = p[1] / 10;
  }
  Mesh mesh = build(soup).mesh;
  FillHolesOptions options;
  options.max_hole_edges = 30;
  FillHolesReport r = fill_holes(mesh, options);
  ASSERT_VALID(mesh);
  ASSERT_EQ(r.holes_filled, 1u);
  ASSERT_GT(r.vertices_added, 0u);

  Soup out = extract(mesh);
  ASSERT_NO_THROW(out.check());
  const Channel* q = out.find("quality", Domain::vertex);
  const Channel* m = out.find("material", Domain::face);
  const Channel* t = out.find("uv", Domain::corner);
  ASSERT_TRUE(q && m && t);
  for (std::size_t v = nv; v < out.n_vertices(); ++v) {
    // Interpolated quality follows the linear field it was made from.
    EXPECT_NEAR(q->as<float>()[v], 1 + out.positions[v][0], 0.5f) << v;
  }
  for (std::size_t f = 0; f < out.n_faces(); ++f) EXPECT_EQ(m->as<std::int32_t>()[f], 7) << f;
  // Corner UVs, old corners included, match the planar parameterisation within the patch.
  for (std::size_t c = 0; c < out.n_corners(); ++c) {
    const Point& p = out.positions[out.corners[c]];
    EXPECT_NEAR(t->as<float>()[2 * c], p[0] / 10, 0.05f) << c;
    EXPECT_NEAR(t->as<float>()[2 * c + 1], p[1] / 10, 0.05f) << c;
  }
}

TEST(FillHoles, ProvenanceOfNewElementsStaysDefault) {
  // A bow-tie vertex makes build() store provenance; new elements must not claim a source,
  // and extract() must still weld the old copies back.
  Soup soup = grid_with_hole(8, 2);
  const std::uint32_t base = std::uint32_t(soup.positions.size());
  soup.positions.push_back(Point{{-1, -1, 0}});
  soup.positions.push_back(Point{{0, -1, 0}});
  soup.add_face({base, base + 1, 0});  // touches the grid at its corner vertex 0 only
  BuildResult built = build(soup);
  ASSERT_EQ(built.report.non_manifold_vertices, 1u);
  Mesh mesh = std::move(built.mesh);
  FillHolesOptions options;
  options.max_hole_edges = 20;
  FillHolesReport r = fill_holes(mesh, options);
  ASSERT_VALID(mesh);
  ASSERT_EQ(r.holes_filled, 1u);
  auto source = mesh.get_vertex_property<std::uint32_t>(provenance::kVertexSource);
  ASSERT_TRUE(source);
  for (Vertex v : mesh.vertices())
    if (v.idx() >= built.maps.vertex_source.size()) {
      EXPECT_EQ(source[v], kInvalidIndex);
    }
  Soup out = extract(mesh);
  EXPECT_EQ(out.n_vertices(), soup.n_vertices() + r.vertices_added);  // the copy welded back
  EXPECT_EQ(out.n_faces(), soup.n_faces() + r.triangles_added);
}

TEST(FillHoles, QuadMeshHole) {
  // Quads around the hole: the patch is triangles, cotangent fairing falls back to uniform.
  Soup soup;
  const int n = 12;
  for (int y = 0; y <= n; ++y)
    for (int x = 0; x <= n; ++x)
      soup.positions.push_back(Point{{float(x), float(y), float((x - 6) * (x - 6) + (y - 6) * (y - 6)) / 20}});
  for (std::uint32_t y = 0; y < n; ++y)
    for (std::uint32_t x = 0; x < n; ++x) {
      if (x >= 4 && x < 8 && y >= 4 && y < 8) continue;
      soup.add_face({y * (n + 1) + x, y * (n + 1) + x + 1, (y + 1) * (n + 1) + x + 1, (y + 1) * (n + 1) + x});
    }
  Mesh mesh = build(soup).mesh;
  FillHolesOptions options;
  options.max_hole_edges = 16;
  options.weights = FairingWeights::cotangent;
  FillHolesReport r = fill_holes(mesh, options);
  ASSERT_VALID(mesh);
  EXPECT_EQ(r.holes_filled, 1u);
  EXPECT_EQ(r.fairing_failures, 0u);
  EXPECT_EQ(loop_lengths(mesh).size(), 1u);
  // The paraboloid's hole is filled near the paraboloid (z = r^2 / 20 <= 0.4 there); the
  // uniform operator, all quads allow, is the less accurate one.
  for (Vertex v : mesh.vertices())
    if (v.idx() >= soup.n_vertices()) {
      const Point& p = mesh.position(v);
      EXPECT_NEAR(p[2], ((p[0] - 6) * (p[0] - 6) + (p[1] - 6) * (p[1] - 6)) / 20, 0.1) << v.idx();
    }
}

TEST(FillHoles, PatchTurnsWithFlippedNeighbours) {
  // The host's faces left of x = 4 are listed backwards; build() flips them, extract()
  // turns them back. The patch must come out turned like the faces it borders.
  Soup soup = grid_with_hole(12, 3);
  const auto offset = soup.face_offsets();
  const std::size_t original_faces = soup.n_faces();
  for (std::size_t f = 0; f < original_faces; ++f)
    if (soup.positions[soup.corners[offset[f]]][0] < 4)
      std::reverse(soup.corners.begin() + std::ptrdiff_t(offset[f]),
                   soup.corners.begin() + std::ptrdiff_t(offset[f + 1]));
  BuildResult built = build(soup);
  ASSERT_GT(built.report.flipped_faces, 0u);
  FillHolesOptions options;
  options.max_hole_edges = 30;
  Mesh mesh = std::move(built.mesh);
  ASSERT_EQ(fill_holes(mesh, options).holes_filled, 1u);
  ASSERT_VALID(mesh);
  Soup out = extract(mesh);
  // Directed edges of the old faces; a patch face sharing an edge must run it backwards.
  std::map<std::pair<std::uint32_t, std::uint32_t>, std::size_t> directed;
  const auto out_offset = out.face_offsets();
  auto for_edges = [&](std::size_t f, auto fn) {
    const std::size_t n = out.face_sizes[f];
    for (std::size_t i = 0; i < n; ++i) fn(out.corners[out_offset[f] + i], out.corners[out_offset[f] + (i + 1) % n]);
  };
  for (std::size_t f = 0; f < original_faces; ++f)
    for_edges(f, [&](std::uint32_t a, std::uint32_t b) { directed[{a, b}] = f; });
  // Where the border passes from turned to unturned faces, a patch triangle touching both
  // kinds cannot agree with both: it must agree with one.
  std::size_t shared = 0, conflicts = 0;
  for (std::size_t f = original_faces; f < out.n_faces(); ++f) {
    std::size_t agree = 0, disagree = 0;
    for_edges(f, [&](std::uint32_t a, std::uint32_t b) {
      disagree += directed.count({a, b});
      agree += directed.count({b, a});
    });
    shared += agree;
    conflicts += disagree;
    if (disagree) {
      EXPECT_GT(agree, 0u) << "patch face " << f << " is turned against all its neighbours";
    }
  }
  EXPECT_LE(conflicts, 4u);
  EXPECT_GT(shared, 10u);
}

TEST(FillHoles, ExistingDiagonalIsNotDoubled) {
  // Two triangles (a,b,c), (a,c,d): the hole on the other side must use b-d, not a-c.
  Soup soup;
  soup.positions = {Point{{0, 0, 0}}, Point{{1, 0, 0}}, Point{{1, 1, 0.2f}}, Point{{0, 1, 0}}};
  soup.add_face({0, 1, 2});
  soup.add_face({0, 2, 3});
  Mesh mesh = build(soup).mesh;
  FillHolesOptions options;
  options.refine = false;
  options.fair = false;
  FillHolesReport r = fill_holes(mesh, options);
  ASSERT_VALID(mesh);
  EXPECT_EQ(r.holes_filled, 1u);
  EXPECT_TRUE(watertight(mesh));
  EXPECT_EQ(multi_edges(mesh), 0u);
  EXPECT_TRUE(mesh.find_edge(Vertex(1), Vertex(3)).is_valid());
}

TEST(FillHoles, LoneTriangleIsNotDoubled) {
  Soup soup;
  soup.positions = {Point{{0, 0, 0}}, Point{{1, 0, 0}}, Point{{0, 1, 0}}};
  soup.add_face({0, 1, 2});
  Mesh mesh = build(soup).mesh;
  FillHolesReport r = fill_holes(mesh);
  ASSERT_VALID(mesh);
  EXPECT_EQ(r.holes_found, 1u);
  EXPECT_EQ(r.holes_filled, 0u);
  EXPECT_EQ(r.holes_skipped, 1u);
  EXPECT_EQ(r.lone_faces, 1u);
  EXPECT_EQ(mesh.n_faces(), 1u);
}

TEST(FillHoles, BorderVertexWithoutEdgeLengthGetsNoFan) {
  // Found by fuzz_euler: border vertices all of whose edges have zero length asked for
  // triangles of no size, so refinement fanned hundreds of slivers into them and the fan
  // made the fairing system dense (seconds of solving for a hole of six edges). The mesh
  // as the fuzzer left it: six vertices at two points, a pentagon and a triangle.
  const Point p{{-3, -2, -2}}, q{{1, -2, -1}};
  Soup soup;
  soup.positions = {p, q, p, p, p, q};
  soup.add_face({0, 2, 1, 4, 3});
  soup.add_face({1, 5, 4});
  Mesh mesh = build(soup).mesh;
  FillHolesReport r = fill_holes(mesh);
  ASSERT_VALID(mesh);
  EXPECT_EQ(r.holes_filled, 1u);
  EXPECT_TRUE(watertight(mesh));
  EXPECT_LT(r.vertices_added, 60u);
  std::size_t max_valence = 0;
  for (Vertex v : mesh.vertices()) max_valence = std::max(max_valence, mesh.valence(v));
  EXPECT_LE(max_valence, 24u);
}

TEST(FillHoles, CancelLeavesTheMeshAsItWas) {
  Mesh mesh = build(sphere_with_hole(32, 50)).mesh;
  const std::size_t faces = mesh.n_faces(), vertices = mesh.n_vertices();
  int calls = 0;
  Progress stop([&](double, const std::string&) { return ++calls < 3; });
  EXPECT_THROW(fill_holes(mesh, {}, stop), Cancelled);
  EXPECT_EQ(mesh.n_faces(), faces);
  EXPECT_EQ(mesh.n_vertices(), vertices);
  EXPECT_EQ(loop_lengths(mesh).size(), 1u);
  ASSERT_VALID(mesh);
}

TEST(FillHoles, TenThousandEdgeHoleFinishes) {
  // A cylinder of 10,000 segments open at both ends: two holes of 10,000 edges.
  const int n = 10000;
  Soup soup;
  const double edge = 2 * std::numbers::pi / n;
  for (int k = 0; k < 3; ++k)
    for (int j = 0; j < n; ++j) {
      double phi = j * edge;
      soup.positions.push_back(Point{{float(std::cos(phi)), float(std::sin(phi)), float(k * edge)}});
    }
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < n; ++j) {
      std::uint32_t a = k * n + j, b = k * n + (j + 1) % n, c = (k + 1) * n + (j + 1) % n, d = (k + 1) * n + j;
      soup.add_face({a, b, c});
      soup.add_face({a, c, d});
    }
  Mesh mesh = build(soup).mesh;
  auto t0 = std::chrono::steady_clock::now();
  FillHolesReport r = fill_holes(mesh);
  const double seconds = seconds_since(t0);
  ASSERT_VALID(mesh);
  EXPECT_EQ(r.holes_filled, 2u);
  EXPECT_TRUE(watertight(mesh));
  EXPECT_EQ(multi_edges(mesh), 0u);
  EXPECT_LE(r.vertices_added, 2 * FillHolesOptions{}.max_new_vertices_per_hole);
  MeshStatistics s = mesh_statistics(mesh);
  std::printf(
      "[ fill_holes ] two holes of %d edges: %.2f s, %zu vertices and %zu triangles added, min angle %.1f, "
      "mean quality %.3f\n",
      n, seconds, r.vertices_added, r.triangles_added, s.min_angle_degrees, s.quality_mean);
}

TEST(FillHoles, DragonRes4EveryHoleClosed) {
  if (!have("dragon_res4.ply")) GTEST_SKIP() << "dragon_res4.ply not fetched";
  Mesh mesh = load("dragon_res4.ply");
  const std::size_t loops = loop_lengths(mesh).size();
  auto t0 = std::chrono::steady_clock::now();
  FillHolesReport r = fill_holes(mesh);
  const double seconds = seconds_since(t0);
  ASSERT_VALID(mesh);
  // Every edge of dragon_res4 has an even number of faces: its boundary loops are all seams
  // of split non-manifold edges, and none is a hole.
  EXPECT_EQ(r.split_seams, loops);
  EXPECT_EQ(r.holes_found, 0u);
  EXPECT_EQ(loop_lengths(mesh).size(), loops);
  EXPECT_EQ(r.triangles_added, 0u);
  std::printf("[ fill_holes ] dragon_res4: %zu seams of non-manifold edges, %zu holes, %.2f s\n", r.split_seams,
              r.holes_found, seconds);
}

TEST(FillHoles, SeamsOfSplitNonManifoldEdgesAreNoHoles) {
  // Two closed tetrahedra glued along edge 0-1 (four faces on it): building splits the edge,
  // which leaves boundary loops where the input has none.
  Soup soup;
  soup.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {0, -1, 0}, {0, 0, -1}};
  for (std::uint32_t c : {0, 2, 1, 0, 1, 3, 1, 2, 3, 2, 0, 3, 0, 4, 1, 0, 1, 5, 1, 4, 5, 4, 0, 5})
    soup.corners.push_back(c);
  soup.face_sizes.assign(8, 3);
  Mesh mesh = build(soup).mesh;
  ASSERT_FALSE(loop_lengths(mesh).empty());
  FillHolesReport r = fill_holes(mesh);
  EXPECT_EQ(r.split_seams, loop_lengths(mesh).size());
  EXPECT_EQ(r.holes_found, 0u);
  EXPECT_EQ(r.triangles_added, 0u);
  EXPECT_EQ(extract(mesh).corners, soup.corners);

  // A real hole beside the glued edge is still filled: drop face (1, 4, 5). Its loop runs on
  // along the split edge through a copy of vertex 1; the hole is the stretch 1, 4, 5 that
  // comes back to vertex 1, and the patch is the triangle the input lacks.
  soup.corners.erase(soup.corners.begin() + 18, soup.corners.begin() + 21);
  soup.face_sizes.pop_back();
  soup.add_channel("uv", Domain::corner, ScalarType::f32, 2);  // a UV per vertex: (x + 2, y + 2)
  for (std::size_t c = 0; c < soup.n_corners(); ++c)
    for (int k = 0; k < 2; ++k)
      soup.find("uv", Domain::corner)->as<float>()[2 * c + k] = soup.positions[soup.corners[c]][k] + 2;
  mesh = build(soup).mesh;
  r = fill_holes(mesh);
  EXPECT_EQ(r.holes_found, 1u);
  EXPECT_EQ(r.holes_filled, 1u);
  EXPECT_EQ(r.holes_on_seams, 0u);
  EXPECT_EQ(r.triangles_added, 1u);
  ASSERT_VALID(mesh);
  const Soup out = extract(mesh);
  ASSERT_EQ(out.n_faces(), soup.n_faces() + 1);
  EXPECT_TRUE(std::equal(soup.corners.begin(), soup.corners.end(), out.corners.begin()));
  std::vector<std::uint32_t> patch(out.corners.end() - 3, out.corners.end());
  std::sort(patch.begin(), patch.end());
  EXPECT_EQ(patch, (std::vector<std::uint32_t>{1, 4, 5}));
  const Channel* uv = out.find("uv", Domain::corner);
  ASSERT_TRUE(uv);
  for (std::size_t c = 0; c < out.n_corners(); ++c)
    for (int k = 0; k < 2; ++k) EXPECT_EQ(uv->as<float>()[2 * c + k], out.positions[out.corners[c]][k] + 2) << c;
  EXPECT_EQ(test::count_defects(out).non_manifold_edges, test::count_defects(soup).non_manifold_edges);
}

TEST(FillHoles, HoleAlongANonManifoldEdgeStaysOpen) {
  // The glued tetrahedra without face (0, 4, 1): the hole's border is 0-4, 4-1 and the glued
  // edge itself, which keeps three faces. A patch would give it a fourth.
  Soup soup;
  soup.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {0, -1, 0}, {0, 0, -1}};
  for (std::uint32_t c : {0, 2, 1, 0, 1, 3, 1, 2, 3, 2, 0, 3, 0, 1, 5, 1, 4, 5, 4, 0, 5}) soup.corners.push_back(c);
  soup.face_sizes.assign(7, 3);
  Mesh mesh = build(soup).mesh;
  FillHolesReport r = fill_holes(mesh);
  EXPECT_EQ(r.holes_found, 1u);
  EXPECT_EQ(r.holes_on_seams, 1u);
  EXPECT_EQ(r.holes_skipped, 1u);
  EXPECT_EQ(r.holes_filled, 0u);
  EXPECT_EQ(r.triangles_added, 0u);
  ASSERT_EQ(r.messages.size(), 1u);
  EXPECT_NE(r.messages[0].find("non-manifold"), std::string::npos) << r.messages[0];
  EXPECT_EQ(extract(mesh).corners, soup.corners);
}

TEST(FillHoles, DragonRes4AfterRepairOnlyLoneFacesStayOpen) {
  if (!have("dragon_res4.ply")) GTEST_SKIP() << "dragon_res4.ply not fetched";
  // repair removes the pinches that leave two-edge slits; filling then closes every hole
  // except the borders of lone triangles (the fins of the non-manifold edges).
  Mesh mesh = load("dragon_res4.ply");
  repair(mesh);
  FillHolesReport r = fill_holes(mesh);
  ASSERT_VALID(mesh);
  for (std::size_t n : loop_lengths(mesh)) EXPECT_EQ(n, 3u);
  std::size_t lone = 0;
  for (Face f : mesh.faces()) {
    bool alone = true;
    for (Face g : mesh.faces(f)) alone = alone && !g.is_valid();
    lone += alone ? 1 : 0;
  }
  EXPECT_EQ(loop_lengths(mesh).size(), lone);
  EXPECT_EQ(r.holes_skipped, lone);
  std::printf("[ fill_holes ] dragon_res4 after repair: %zu holes, %zu filled, %zu lone triangles left\n",
              r.holes_found, r.holes_filled, r.holes_skipped);
}

TEST(FillHoles, DragonEveryHoleClosed) {
  if (!have("dragon.ply")) GTEST_SKIP() << "dragon.ply not fetched";
  Mesh mesh = load("dragon.ply");
  const MeshStatistics before = mesh_statistics(mesh);
  auto t0 = std::chrono::steady_clock::now();
  FillHolesReport r = fill_holes(mesh);
  const double seconds = seconds_since(t0);
  ASSERT_VALID(mesh);
  EXPECT_EQ(r.holes_found, before.topology.boundary_loops);
  EXPECT_EQ(r.holes_filled + r.holes_skipped, r.holes_found);
  // The dragon has single triangles floating free: their borders stay, nothing else does.
  const std::vector<std::size_t> left = loop_lengths(mesh);
  EXPECT_EQ(left.size(), r.holes_skipped);
  for (std::size_t n : left) EXPECT_EQ(n, 3u);
  const MeshStatistics after = mesh_statistics(mesh);
  EXPECT_EQ(after.multi_edges, 0u);
  EXPECT_EQ(after.topology.components, before.topology.components);
  std::printf(
      "[ fill_holes ] dragon: %zu holes filled (%zu lone triangles left) in %.2f s, +%zu vertices +%zu "
      "triangles\n",
      r.holes_filled, r.holes_skipped, seconds, r.vertices_added, r.triangles_added);
}

TEST(FillHoles, OperationRunsFromTheCatalogue) {
  const Operation& op = find_operation("fill_holes");
  EXPECT_EQ(op.category, Category::cleaning);
  RunResult run =
      run_operation(op, grid_with_hole(10, 2.5),
                    resolve_params(op, std::map<std::string, std::string>{{"max_hole_edges", "30"}}), Progress::none());
  ASSERT_TRUE(run.report.find("holes_filled"));
  EXPECT_EQ(std::get<std::int64_t>(*run.report.find("holes_found")), 2);
  EXPECT_EQ(std::get<std::int64_t>(*run.report.find("holes_filled")), 1);
  EXPECT_EQ(std::get<std::int64_t>(*run.report.find("holes_skipped")), 1);
  EXPECT_EQ(std::get<std::int64_t>(*run.report.find("holes_too_large")), 1);
  BuildResult again = build(run.soup);
  EXPECT_FALSE(again.report.repaired());
  EXPECT_EQ(loop_lengths(again.mesh).size(), 1u);
}

}  // namespace
}  // namespace hedge
