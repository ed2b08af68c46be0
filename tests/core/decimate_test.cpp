// Tests of decimate (decimate.h): exact face counts, valid manifold output, no flipped
// triangles, boundaries and UV seams kept, Hausdorff distance to the input, determinism,
// parameter checks and an untouched input on failure. Prints timings, never asserts them.
#include "hedge/decimate.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <map>
#include <numbers>
#include <set>
#include <string>
#include <tuple>
#include <vector>

#include "hedge/build.h"
#include "hedge/catalogue.h"
#include "hedge/distance.h"
#include "hedge/error.h"
#include "hedge/io.h"
#include "hedge/normals.h"
#include "hedge/report.h"
#include "hedge/topology.h"
#include "hedge/validate.h"
#include "test_meshes.h"

namespace hedge {
namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

// A real mesh, or nothing when it has not been fetched (the caller skips).
bool load(const std::string& name, Mesh& mesh) {
  const std::string path = std::string(HEDGE_MESH_DIR) + "/" + name;
  if (!std::filesystem::exists(path)) return false;
  mesh = build(read_mesh(path)).mesh;
  return true;
}

// An icosahedron subdivided `levels` times (each triangle into four), on the unit sphere.
Soup icosphere(int levels) {
  const double t = (1 + std::sqrt(5.0)) / 2;
  std::vector<Vec3d> p = {{{-1, t, 0}},  {{1, t, 0}},  {{-1, -t, 0}}, {{1, -t, 0}}, {{0, -1, t}},  {{0, 1, t}},
                          {{0, -1, -t}}, {{0, 1, -t}}, {{t, 0, -1}},  {{t, 0, 1}},  {{-t, 0, -1}}, {{-t, 0, 1}}};
  std::vector<std::array<std::uint32_t, 3>> f = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                                                 {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                                                 {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                                                 {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  for (auto& x : p) x = normalize(x);
  for (int l = 0; l < levels; ++l) {
    std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> mid;
    auto midpoint = [&](std::uint32_t a, std::uint32_t b) {
      auto key = std::minmax(a, b);
      auto it = mid.find(key);
      if (it != mid.end()) return it->second;
      p.push_back(normalize((p[a] + p[b]) * 0.5));
      return mid[key] = std::uint32_t(p.size() - 1);
    };
    std::vector<std::array<std::uint32_t, 3>> g;
    for (auto [a, b, c] : f) {
      std::uint32_t ab = midpoint(a, b), bc = midpoint(b, c), ca = midpoint(c, a);
      g.push_back({a, ab, ca});
      g.push_back({b, bc, ab});
      g.push_back({c, ca, bc});
      g.push_back({ab, bc, ca});
    }
    f = std::move(g);
  }
  Soup s;
  for (auto& x : p) s.positions.push_back(to_float(x));
  for (auto [a, b, c] : f) s.add_face({a, b, c});
  return s;
}

// An open cylinder (radius 1, height 2, wavy so that there is something to simplify) cut
// open along the seam x > 0, y = 0: corner UVs run u 0..1 around and v 0..1 up, so the
// corners on the seam carry u = 0 on one side and u = 1 on the other.
constexpr int kSegments = 64, kRings = 40;
Soup uv_cylinder() {
  Soup s;
  for (int i = 0; i <= kRings; ++i)
    for (int j = 0; j < kSegments; ++j) {
      const double phi = 2 * std::numbers::pi * j / kSegments, z = 2.0 * i / kRings;
      const double r = 1 + 0.05 * std::sin(3 * phi) * std::cos(2 * z);
      s.positions.push_back(Point{{float(r * std::cos(phi)), float(r * std::sin(phi)), float(z)}});
    }
  auto id = [](int i, int j) { return std::uint32_t(i * kSegments + (j % kSegments)); };
  std::vector<float> uv;
  auto corner = [&](int i, int j) {
    uv.push_back(float(j) / kSegments);
    uv.push_back(float(i) / kRings);
  };
  for (int i = 0; i < kRings; ++i)
    for (int j = 0; j < kSegments; ++j) {
      s.add_face({id(i, j), id(i, j + 1), id(i + 1, j + 1)});
      corner(i, j), corner(i, j + 1), corner(i + 1, j + 1);
      s.add_face({id(i, j), id(i + 1, j + 1), id(i + 1, j)});
      corner(i, j), corner(i + 1, j + 1), corner(i + 1, j);
    }
  Channel& c = s.add_channel("uv", Domain::corner, ScalarType::f32, 2);
  std::memcpy(c.data.data(), uv.data(), uv.size() * sizeof(float));
  return s;
}

// A bumpy open square (height field): one boundary loop.
Soup bumpy_grid(int n) {
  return test::height_field(n, 1.0, [](double x, double y) { return 0.1 * std::sin(6 * x) * std::cos(5 * y); });
}

double bbox_diagonal(const Mesh& mesh) { return mesh_statistics(mesh).bbox_diagonal; }

// Valid, manifold (validate() checks every fan), triangles only, compacted, and no edge
// doubled that was not doubled before (build() keeps some where it splits non-manifold input).
void expect_clean(const Mesh& mesh, std::size_t multi_edges_before = 0) {
  const Validation v = validate(mesh);
  EXPECT_TRUE(v.ok) << v.message;
  EXPECT_TRUE(mesh.is_triangle_mesh());
  EXPECT_FALSE(mesh.has_garbage());
  EXPECT_LE(mesh_statistics(mesh).multi_edges, multi_edges_before);
}
std::size_t multi_edges(const Mesh& mesh) { return mesh_statistics(mesh).multi_edges; }

// Output triangles whose normal points against the input surface nearest to them: judged at
// four points of the triangle (its centroid and one towards each corner), flipped when most
// of them disagree, so a triangle spanning a crease is not taken for a fold.
// With interior_only, triangles touching the boundary are skipped: around the scans' holes
// build() leaves sheets lying on each other, where "the nearest input triangle" is a toss-up.
std::size_t flipped_faces(const Mesh& input, const Mesh& output, bool interior_only = false) {
  const TriangleTree tree(input);
  std::size_t flipped = 0;
  for (Face f : output.faces()) {
    if (interior_only && output.is_boundary(f)) continue;
    bool touches_boundary = false;
    for (Vertex v : output.vertices(f)) touches_boundary = touches_boundary || output.is_boundary(v);
    if (interior_only && touches_boundary) continue;
    std::array<Vec3d, 3> p;
    int k = 0;
    for (Vertex v : output.vertices(f)) p[k++] = to_double(output.position(v));
    const Vec3f n_out = face_normal(output, f);
    int against = 0;
    for (const Vec3d& w : {Vec3d{{1.0 / 3, 1.0 / 3, 1.0 / 3}}, Vec3d{{2.0 / 3, 1.0 / 6, 1.0 / 6}},
                           Vec3d{{1.0 / 6, 2.0 / 3, 1.0 / 6}}, Vec3d{{1.0 / 6, 1.0 / 6, 2.0 / 3}}}) {
      const ClosestPoint cp = tree.closest_point(p[0] * w[0] + p[1] * w[1] + p[2] * w[2]);
      if (cp.found() && dot(face_normal(input, tree.face(cp.triangle)), n_out) < 0) ++against;
    }
    if (against >= 3) ++flipped;
  }
  return flipped;
}

struct Outcome {
  DecimateReport report;
  double seconds = 0;      // wall clock
  double cpu_seconds = 0;  // of this process: decimate() runs on one thread
};
Outcome run(Mesh& mesh, const DecimateOptions& o) {
  const auto t = Clock::now();
  const std::clock_t c = std::clock();
  Outcome out;
  out.report = decimate(mesh, o);
  out.cpu_seconds = double(std::clock() - c) / CLOCKS_PER_SEC;
  out.seconds = seconds_since(t);
  return out;
}

// ---- face counts -----------------------------------------------------------------------

// The low-resolution dragons are full of slits and tiny pieces where build() split their
// non-manifold edges (dragon_res4: 485 boundary loops, 208 components of which 198 have at
// most 6 faces): no topology-preserving collapse gets them below about 19% (res4) and 12%
// (res3), so their exact targets are 25%.
TEST(Decimate, HitsTheTargetExactlyOnClosedAndOpenMeshes) {
  struct Case {
    std::string name;
    std::size_t target;
  };
  for (const Case& k :
       {Case{"bunny.off", 368}, Case{"bunny.off", 1000}, Case{"dragon_res4.ply", 2775}, Case{"dragon_res4.ply", 2776},
        Case{"dragon_res3.ply", 11948}, Case{"dragon_res3.ply", 11949}}) {
    Mesh mesh;
    if (!load(k.name, mesh)) {
      std::printf("  %s not present, skipped\n", k.name.c_str());
      continue;
    }
    const std::size_t m0 = multi_edges(mesh);
    DecimateOptions o;
    o.target_faces = k.target;
    const Outcome r = run(mesh, o);
    EXPECT_EQ(mesh.n_faces(), k.target) << k.name << ": " << r.report.stopped_by;
    EXPECT_EQ(r.report.faces_after, mesh.n_faces());
    expect_clean(mesh, m0);
    std::printf("  %s -> %zu faces in %.3f s (%s)\n", k.name.c_str(), mesh.n_faces(), r.seconds,
                r.report.stopped_by.c_str());
  }
}

TEST(Decimate, SphereEvenTargetExactOddTargetOneAbove) {
  for (std::size_t target : {1000u, 1001u, 100u, 20u}) {
    Mesh mesh = build(icosphere(4)).mesh;  // 5120 triangles
    DecimateOptions o;
    o.target_faces = target;
    const DecimateReport r = decimate(mesh, o);
    expect_clean(mesh);
    const std::size_t expected = target % 2 ? target + 1 : target;  // closed: collapses remove two
    EXPECT_EQ(mesh.n_faces(), expected) << r.stopped_by;
    EXPECT_EQ(topology_stats(mesh).genus, 0);
    EXPECT_EQ(topology_stats(mesh).components, 1u);
    // Still round: every vertex stays near the unit sphere.
    if (target >= 100) {
      for (Vertex v : mesh.vertices()) EXPECT_NEAR(norm(to_double(mesh.position(v))), 1.0, 0.05);
    }
  }
}

TEST(Decimate, RatioAndPolygons) {
  // Quads are triangulated first; the ratio applies to the triangles. Their corner UVs (a
  // linear map of the plane) follow the corners through triangulation and collapses.
  Soup s;
  const int n = 20;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i)
      s.positions.push_back(Point{{float(i), float(j), float(0.3 * std::sin(i * 0.5) * std::cos(j * 0.4))}});
  std::vector<float> uv;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      std::uint32_t a = j * (n + 1) + i;
      s.add_face({a, a + 1, a + n + 2, a + n + 1});
      for (auto [di, dj] : {std::pair{0, 0}, {1, 0}, {1, 1}, {0, 1}}) {
        uv.push_back(float(i + di) / n);
        uv.push_back(float(j + dj) / n);
      }
    }
  Channel& c = s.add_channel("uv", Domain::corner, ScalarType::f32, 2);
  std::memcpy(c.data.data(), uv.data(), uv.size() * sizeof(float));
  Mesh mesh = build(s).mesh;
  DecimateOptions o;
  o.target_ratio = 0.25;
  const DecimateReport r = decimate(mesh, o);
  EXPECT_EQ(r.triangulated_faces, 400u);
  EXPECT_EQ(r.faces_before, 400u);
  EXPECT_EQ(r.target_faces, 200u);
  EXPECT_EQ(mesh.n_faces(), 200u);
  expect_clean(mesh);
  // Each corner's UV against the UV of the input surface point nearest to its vertex.
  const Mesh input = build(s).mesh;
  const TriangleTree tree(input);
  const ChannelArray& uv_in = *input.halfedge_properties().get_channel("uv");
  const ChannelArray& ch = *mesh.halfedge_properties().get_channel("uv");
  double worst = 0;
  for (Face f : mesh.faces())
    for (Halfedge h : mesh.halfedges(f)) {
      Vec2f t;
      std::memcpy(&t, ch.element(h.idx()), sizeof t);
      const ClosestPoint cp = tree.closest_point(to_double(mesh.position(mesh.to_vertex(h))));
      // The input is a fan-triangulated quad grid: its faces map to tree triangles in order.
      const Face g = tree.face(cp.triangle);
      const auto corners = tree.corners(cp.triangle);
      Vec2f truth{};
      for (Halfedge k : input.halfedges(g)) {
        Vec2f c;
        std::memcpy(&c, uv_in.element(k.idx()), sizeof c);
        const Vec3d q = to_double(input.position(input.to_vertex(k)));
        for (int i = 0; i < 3; ++i)
          if (q == corners[i]) truth += c * float(cp.barycentric[i]);
      }
      worst = std::max({worst, double(std::abs(t[0] - truth[0])), double(std::abs(t[1] - truth[1]))});
    }
  std::printf("  quads with corner UVs: worst |uv - position / n| %.4f\n", worst);
  EXPECT_LT(worst, 0.01);
}

TEST(Decimate, NothingToDo) {
  Mesh mesh = build(icosphere(1)).mesh;
  const Soup before = extract(mesh);
  DecimateOptions o;
  o.target_ratio = 1;
  const DecimateReport r = decimate(mesh, o);
  EXPECT_EQ(r.collapses, 0u);
  EXPECT_EQ(extract(mesh), before);
  o.target_faces = 1000;  // more than there are
  decimate(mesh, o);
  EXPECT_EQ(extract(mesh), before);
}

// ---- shape -----------------------------------------------------------------------------

// Reference figures, measured with the same sampler: CGAL 5.5 Garland-Heckbert (plane
// policies) gives 0.0138 diag on the bunny at 10%, 0.0070 at 25%, and 0.0053 on dragon_res3
// at 25%. (At 10% the bunny keeps 368 triangles: 0.005 diag is out of anyone's reach.)
TEST(Decimate, NoFlippedTrianglesAndSmallHausdorff) {
  struct Case {
    std::string name;
    double ratio, bound;
  };
  for (const Case& k :
       {Case{"bunny.off", 0.1, 0.015}, Case{"bunny.off", 0.25, 0.0075}, Case{"dragon_res3.ply", 0.25, 0.006}}) {
    Mesh input;
    if (!load(k.name, input)) {
      std::printf("  %s not present, skipped\n", k.name.c_str());
      continue;
    }
    Mesh mesh = input;
    DecimateOptions o;
    o.target_ratio = k.ratio;
    const Outcome r = run(mesh, o);
    expect_clean(mesh, multi_edges(input));
    const double diag = bbox_diagonal(input);
    const HausdorffResult h = hausdorff(input, mesh);
    const MeshStatistics st = mesh_statistics(mesh);
    std::printf(
        "  %s %g%%: %zu -> %zu faces in %.3f s; Hausdorff %.3g diag (in->out %.3g, out->in %.3g, mean %.3g); "
        "quality min %.3f mean %.3f; min angle %.2f deg\n",
        k.name.c_str(), 100 * k.ratio, input.n_faces(), mesh.n_faces(), r.seconds, h.max / diag, h.a_to_b.max / diag,
        h.b_to_a.max / diag, h.a_to_b.mean / diag, st.quality_min, st.quality_mean, st.min_angle_degrees);
    EXPECT_LT(h.max, k.bound * diag) << k.name;
    EXPECT_EQ(topology_stats(mesh).genus, topology_stats(input).genus) << k.name;
    EXPECT_EQ(topology_stats(mesh).components, topology_stats(input).components) << k.name;
    EXPECT_EQ(topology_stats(mesh).boundary_loops, topology_stats(input).boundary_loops) << k.name;
    // Flips are judged against the nearest input triangle, which is ambiguous where build()
    // left sheets lying on each other (dragon_res3 alone has 1123 "flips" against itself).
    if (flipped_faces(input, input) == 0) {
      EXPECT_EQ(flipped_faces(input, mesh), 0u) << k.name;
    }
  }
}

TEST(Decimate, NoFlipsOnASphere) {
  const Mesh input = build(icosphere(5)).mesh;  // 20480 triangles
  for (double ratio : {0.1, 0.01}) {
    Mesh mesh = input;
    DecimateOptions o;
    o.target_ratio = ratio;
    decimate(mesh, o);
    expect_clean(mesh);
    EXPECT_EQ(flipped_faces(input, mesh), 0u) << ratio;
  }
}

TEST(Decimate, MinQualityRaisesTheWorstTriangle) {
  Mesh input;
  if (!load("bunny.off", input)) GTEST_SKIP() << "bunny.off not present";
  Mesh plain = input, careful = input;
  DecimateOptions o;
  o.target_ratio = 0.25;
  decimate(plain, o);
  o.min_quality = 0.3;
  decimate(careful, o);
  expect_clean(careful);
  EXPECT_EQ(careful.n_faces(), plain.n_faces());
  const MeshStatistics a = mesh_statistics(plain), b = mesh_statistics(careful);
  std::printf("  min_quality 0.3: quality min %.3f -> %.3f, mean %.3f -> %.3f\n", a.quality_min, b.quality_min,
              a.quality_mean, b.quality_mean);
  EXPECT_GT(b.quality_min, a.quality_min);
  EXPECT_GT(b.quality_mean, a.quality_mean);
}

TEST(Decimate, MaxErrorStopsEarly) {
  Mesh input;
  if (!load("dragon_res3.ply", input)) GTEST_SKIP() << "dragon_res3.ply not present";
  Mesh mesh = input;
  DecimateOptions o;
  o.target_ratio = 0.01;
  o.max_error = 2e-4;
  const DecimateReport r = decimate(mesh, o);
  expect_clean(mesh, multi_edges(input));
  EXPECT_GT(mesh.n_faces(), r.target_faces);
  EXPECT_EQ(r.stopped_by, "max_error reached");
  EXPECT_LE(r.max_error, o.max_error);
  const double diag = bbox_diagonal(input);
  const HausdorffResult h = hausdorff(input, mesh);
  std::printf("  max_error %.1e: %zu -> %zu faces, largest collapse error %.3g, Hausdorff %.3g diag\n", o.max_error,
              input.n_faces(), mesh.n_faces(), r.max_error, h.max / diag);
  // The error is an RMS distance to the merged planes, not a bound on the Hausdorff distance;
  // it still keeps the surface close.
  EXPECT_LT(h.max, 20 * o.max_error * diag);

  // A looser bound goes further.
  Mesh looser = input;
  o.max_error = 1e-3;
  decimate(looser, o);
  EXPECT_LT(looser.n_faces(), mesh.n_faces());
}

// ---- boundaries --------------------------------------------------------------------------

std::set<std::tuple<float, float, float>> boundary_positions(const Mesh& mesh) {
  std::set<std::tuple<float, float, float>> out;
  for (Vertex v : mesh.vertices())
    if (mesh.is_boundary(v)) {
      const Point& p = mesh.position(v);
      out.insert({p[0], p[1], p[2]});
    }
  return out;
}

TEST(Decimate, PreservesBoundaries) {
  std::vector<std::pair<std::string, Mesh>> inputs;
  inputs.emplace_back("bumpy grid", build(bumpy_grid(40)).mesh);
  Mesh real;
  if (load("dragon_res4.ply", real)) inputs.emplace_back("dragon_res4", std::move(real));
  for (auto& [name, input] : inputs) {
    const auto before = boundary_positions(input);
    const TopologyStats t0 = topology_stats(input);
    ASSERT_GT(t0.boundary_loops, 0u) << name;
    for (std::size_t target : {input.n_faces() / 5, input.n_faces() / 5 + 1}) {
      Mesh mesh = input;
      DecimateOptions o;
      o.target_faces = target;
      const DecimateReport r = decimate(mesh, o);
      expect_clean(mesh, multi_edges(input));
      EXPECT_EQ(mesh.n_faces(), target) << name << ": " << r.stopped_by;
      const TopologyStats t1 = topology_stats(mesh);
      EXPECT_EQ(t1.boundary_loops, t0.boundary_loops) << name;
      EXPECT_EQ(t1.components, t0.components) << name;
      std::size_t moved = 0;
      for (const auto& p : boundary_positions(mesh)) moved += !before.count(p);
      EXPECT_EQ(moved, 0u) << name << ": boundary vertices moved";
    }
    // Without the constraint the boundary may move, and the count is still exact.
    Mesh mesh = input;
    DecimateOptions o;
    o.target_faces = input.n_faces() / 5;
    o.preserve_boundary = false;
    decimate(mesh, o);
    expect_clean(mesh, multi_edges(input));
    EXPECT_EQ(mesh.n_faces(), input.n_faces() / 5) << name;
    EXPECT_EQ(topology_stats(mesh).boundary_loops, t0.boundary_loops) << name;
  }
}

// ---- attributes --------------------------------------------------------------------------

// Corner UVs of a face, indexed like its corners.
std::array<Vec2f, 3> face_uvs(const Mesh& mesh, const ChannelArray& uv, Face f) {
  std::array<Vec2f, 3> out;
  int k = 0;
  for (Halfedge h : mesh.halfedges(f)) std::memcpy(&out[k++], uv.element(h.idx()), sizeof(Vec2f));
  return out;
}

bool on_seam(const Point& p) { return p[0] > 0 && std::abs(p[1]) < 1e-6f; }

TEST(Decimate, KeepsUvSeamsAndInterpolatesUvs) {
  const Soup soup = uv_cylinder();
  for (bool preserve_boundary : {true, false}) {
    Mesh mesh = build(soup).mesh;
    ASSERT_NE(mesh.halfedge_properties().get_channel("uv"), nullptr);
    DecimateOptions o;
    o.target_ratio = 0.1;
    o.preserve_boundary = preserve_boundary;
    const DecimateReport r = decimate(mesh, o);
    expect_clean(mesh);
    EXPECT_EQ(mesh.n_faces(), r.target_faces) << r.stopped_by;
    const ChannelArray& uv = *mesh.halfedge_properties().get_channel("uv");

    std::size_t seam_edges = 0, seam_edges_off_the_seam = 0;
    double worst_u = 0, worst_v = 0;
    for (Edge e : mesh.edges()) {
      if (mesh.is_boundary(e)) continue;
      const Halfedge h = Mesh::halfedge(e, 0), o2 = Mesh::opposite(h);
      const bool differ = std::memcmp(uv.element(h.idx()), uv.element(mesh.prev(o2).idx()), 8) != 0 ||
                          std::memcmp(uv.element(mesh.prev(h).idx()), uv.element(o2.idx()), 8) != 0;
      if (!differ) continue;
      ++seam_edges;
      if (!on_seam(mesh.position(mesh.vertex(e, 0))) || !on_seam(mesh.position(mesh.vertex(e, 1))))
        ++seam_edges_off_the_seam;
    }
    // Every UV is in the input's range and matches where its corner is on the cylinder.
    for (Face f : mesh.faces()) {
      const auto uvs = face_uvs(mesh, uv, f);
      int k = 0;
      Vec3d centroid{};
      for (Vertex v : mesh.vertices(f)) centroid += to_double(mesh.position(v));
      const double centre_angle = std::atan2(centroid[1], centroid[0]);
      for (Vertex v : mesh.vertices(f)) {
        const Point& p = mesh.position(v);
        const Vec2f t = uvs[k++];
        ASSERT_TRUE(t[0] >= 0 && t[0] <= 1 && t[1] >= 0 && t[1] <= 1) << t[0] << " " << t[1];
        double angle = std::atan2(double(p[1]), double(p[0]));
        // The seam's corners take the side of their face.
        if (on_seam(p)) angle = centre_angle < 0 ? 2 * std::numbers::pi : 0;
        if (angle < 0) angle += 2 * std::numbers::pi;
        worst_u = std::max(worst_u, std::abs(t[0] - angle / (2 * std::numbers::pi)));
        worst_v = std::max(worst_v, std::abs(t[1] - p[2] / 2.0));
      }
    }
    std::printf(
        "  uv cylinder (preserve_boundary %d): %zu faces, %zu seam edges, %zu off the seam; "
        "worst |u - angle| %.4f, |v - height| %.4f\n",
        int(preserve_boundary), mesh.n_faces(), seam_edges, seam_edges_off_the_seam, worst_u, worst_v);
    EXPECT_GT(seam_edges, 0u);
    EXPECT_EQ(seam_edges_off_the_seam, 0u);
    EXPECT_LT(worst_u, 0.02);
    EXPECT_LT(worst_v, 0.02);
  }
}

TEST(Decimate, VertexAttributesAreInterpolated) {
  // A vertex channel equal to a linear function of the position stays (nearly) equal to it.
  Soup s = bumpy_grid(30);
  Channel& c = s.add_channel("quality", Domain::vertex, ScalarType::f32, 1);
  for (std::size_t i = 0; i < s.n_vertices(); ++i) c.as<float>()[i] = s.positions[i][0] + 2 * s.positions[i][1];
  Mesh mesh = build(s).mesh;
  DecimateOptions o;
  o.target_ratio = 0.2;
  decimate(mesh, o);
  expect_clean(mesh);
  const ChannelArray& q = *mesh.vertex_properties().get_channel("quality");
  double worst = 0;
  for (Vertex v : mesh.vertices()) {
    float value;
    std::memcpy(&value, q.element(v.idx()), 4);
    const Point& p = mesh.position(v);
    worst = std::max(worst, std::abs(double(value) - (p[0] + 2 * p[1])));
  }
  // Exact for a linear function along the edge; the optimal point may sit off the edge.
  EXPECT_LT(worst, 0.05);  // of a range of 3
}

TEST(Decimate, IdsNameOneOfTheMergedVertices) {
  // An integer vertex channel does not blend: each collapse keeps one of its two ends' values,
  // so on a manifold mesh (no copies of split vertices sharing an id) the ids stay distinct; a
  // neighbour's id would name a vertex twice.
  const std::string path = std::string(HEDGE_MESH_DIR) + "/bunny.off";
  if (!std::filesystem::exists(path)) GTEST_SKIP() << "bunny.off not present";
  Soup s = read_mesh(path);
  auto* id = s.add_channel("id", Domain::vertex, ScalarType::i32, 1).as<std::int32_t>();
  for (std::size_t i = 0; i < s.n_vertices(); ++i) id[i] = static_cast<std::int32_t>(i);
  Mesh mesh = build(s).mesh;
  DecimateOptions o;
  o.target_ratio = 0.1;
  decimate(mesh, o);
  const ChannelArray& ids = *mesh.vertex_properties().get_channel("id");
  std::set<std::int32_t> seen;
  for (Vertex v : mesh.vertices()) {
    std::int32_t value;
    std::memcpy(&value, ids.element(v.idx()), sizeof value);
    ASSERT_GE(value, 0);
    ASSERT_LT(std::size_t(value), s.n_vertices());
    EXPECT_TRUE(seen.insert(value).second) << "id " << value << " names two vertices";
  }
  EXPECT_EQ(seen.size(), mesh.n_vertices());
}

// ---- weights and locks ------------------------------------------------------------------------

// An icosphere with a vertex channel: `value(position)` at each vertex.
template <class T, class F>
Soup sphere_with(const std::string& name, ScalarType scalar, F value) {
  Soup s = icosphere(5);
  T* c = s.add_channel(name, Domain::vertex, scalar, 1).as<T>();
  for (std::size_t i = 0; i < s.n_vertices(); ++i) c[i] = static_cast<T>(value(s.positions[i]));
  return s;
}

std::size_t faces_with_positive_x(const Mesh& mesh) {
  std::size_t n = 0;
  for (Face f : mesh.faces()) {
    double x = 0;
    for (Vertex v : mesh.vertices(f)) x += mesh.position(v)[0];
    n += x > 0;
  }
  return n;
}

TEST(Decimate, LockedVerticesNeitherMoveNorGo) {
  // A cap of the sphere and every 20th vertex elsewhere locked: each is in the result, where
  // it was, and the rest still goes down to the target.
  auto is_locked = [](const Point& p) { return p[2] > 0.9 || std::fmod(std::abs(p[0]) * 1e4, 20) < 1; };
  const Soup s = sphere_with<std::uint8_t>("lock", ScalarType::u8, is_locked);
  std::set<std::array<double, 3>> locked;
  for (const Point& p : s.positions)
    if (is_locked(p)) locked.insert({p[0], p[1], p[2]});
  ASSERT_GT(locked.size(), 100u);
  Mesh mesh = build(s).mesh;
  DecimateOptions o;
  o.target_ratio = 0.2;
  o.lock_attribute = "lock";
  const DecimateReport r = decimate(mesh, o);
  expect_clean(mesh);
  EXPECT_EQ(r.locked_vertices, locked.size());
  std::printf("%zu of %zu vertices locked: %zu faces left\n", locked.size(), s.n_vertices(), mesh.n_faces());
  std::size_t found = 0;
  for (Vertex v : mesh.vertices()) {
    const Point& p = mesh.position(v);
    found += locked.count({p[0], p[1], p[2]});
  }
  EXPECT_EQ(found, locked.size());
  EXPECT_EQ(r.stopped_by, "target reached");
}

TEST(Decimate, WeightsKeepMoreTrianglesWhereTheyAreHigh) {
  // Weight 1 on the half x > 0: that half keeps far more of the triangles than the other.
  const Soup s = sphere_with<float>("density", ScalarType::f32, [](const Point& p) { return p[0] > 0 ? 1.0 : 0.0; });
  Mesh plain = build(s).mesh, weighted = plain;
  DecimateOptions o;
  o.target_ratio = 0.1;
  decimate(plain, o);
  o.weight_attribute = "density";
  const DecimateReport r = decimate(weighted, o);
  expect_clean(weighted);
  EXPECT_EQ(weighted.n_faces(), plain.n_faces());
  EXPECT_TRUE(r.messages.empty());
  const double share_plain = double(faces_with_positive_x(plain)) / double(plain.n_faces());
  const double share_weighted = double(faces_with_positive_x(weighted)) / double(weighted.n_faces());
  std::printf("faces on the weighted half: %.2f of all (unweighted run: %.2f)\n", share_weighted, share_plain);
  EXPECT_NEAR(share_plain, 0.5, 0.1);
  // Quadric costs grow about as the sixth power of the edge length here, so 11 times the cost
  // buys about 1.5 times shorter edges.
  EXPECT_GT(share_weighted, 0.62);
  Mesh strong = build(s).mesh;
  o.weight_strength = 1000;
  decimate(strong, o);
  const double share_strong = double(faces_with_positive_x(strong)) / double(strong.n_faces());
  std::printf("with strength 1000: %.2f\n", share_strong);
  EXPECT_GT(share_strong, 0.8);
  // No strength, no effect.
  Mesh none = build(s).mesh;
  o.weight_strength = 0;
  decimate(none, o);
  EXPECT_EQ(extract(none).positions, extract(plain).positions);
}

TEST(Decimate, WeightsOutsideZeroToOneAreRescaled) {
  // MeshLab's quality runs over any range: 100 x the weights of above gives the same result.
  const auto half = [](const Point& p) { return p[0] > 0 ? 1.0 : 0.0; };
  Mesh unit = build(sphere_with<float>("quality", ScalarType::f32, half)).mesh;
  Mesh hundred =
      build(sphere_with<float>("quality", ScalarType::f32, [&](const Point& p) { return 100 * half(p); })).mesh;
  DecimateOptions o;
  o.target_ratio = 0.1;
  o.weight_attribute = "quality";
  decimate(unit, o);
  const DecimateReport r = decimate(hundred, o);
  ASSERT_EQ(r.messages.size(), 1u);
  EXPECT_NE(r.messages[0].find("rescaled"), std::string::npos) << r.messages[0];
  EXPECT_EQ(extract(unit).positions, extract(hundred).positions);
}

TEST(Decimate, WeightAndLockNamesTheMeshLacksAreRefused) {
  Soup s = sphere_with<float>("density", ScalarType::f32, [](const Point&) { return 0.5; });
  s.add_channel("colour", Domain::vertex, ScalarType::f32, 3);
  Mesh mesh = build(s).mesh;
  const Soup before = extract(mesh);
  for (auto [weight, lock, says] : std::vector<std::tuple<std::string, std::string, std::string>>{
           {"nope", "", "weight_attribute: the mesh has no vertex attribute 'nope'; its vertex attributes are: "},
           {"", "nope", "lock_attribute: the mesh has no vertex attribute 'nope'"},
           {"colour", "", "'colour' holds 3 numbers per vertex; one is needed"}}) {
    DecimateOptions o;
    o.target_ratio = 0.1;
    o.weight_attribute = weight;
    o.lock_attribute = lock;
    try {
      decimate(mesh, o);
      ADD_FAILURE() << "accepted " << weight << lock;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(says), std::string::npos) << e.what();
      if (weight == "nope") {
        EXPECT_NE(std::string(e.what()).find("density"), std::string::npos) << e.what();
      }
    }
    EXPECT_EQ(extract(mesh), before);
  }
}

TEST(Decimate, WeightsAndLocksThroughTheCatalogue) {
  // As the CLI and the hosts pass them: names as text.
  Soup s = sphere_with<float>("density", ScalarType::f32, [](const Point& p) { return p[0] > 0 ? 1.0 : 0.0; });
  std::uint8_t* lock = s.add_channel("pin", Domain::vertex, ScalarType::u8, 1).as<std::uint8_t>();
  lock[0] = 1;
  const Operation& op = find_operation("decimate");
  const RunResult r =
      run_operation(op, s,
                    resolve_params(op, std::map<std::string, std::string>{{"target_ratio", "0.1"},
                                                                          {"weight_attribute", "density"},
                                                                          {"lock_attribute", "pin"}}),
                    Progress::none());
  ASSERT_NE(r.report.find("locked_vertices"), nullptr);
  EXPECT_EQ(std::get<std::int64_t>(*r.report.find("locked_vertices")), 1);
  EXPECT_NE(std::find(r.soup.positions.begin(), r.soup.positions.end(), s.positions[0]), r.soup.positions.end());
  // Without a lock attribute the report does not mention locks.
  const RunResult plain =
      run_operation(op, s, resolve_params(op, std::map<std::string, std::string>{}), Progress::none());
  EXPECT_EQ(plain.report.find("locked_vertices"), nullptr);
}

// ---- shapes ---------------------------------------------------------------------------------

// The mesh as it looks in the shape of channel `name` (positions plus offsets).
Mesh in_shape(const Mesh& mesh, const std::string& name) {
  Soup s = extract(mesh);
  const Channel* offsets = s.find(name, Domain::vertex);
  for (std::size_t i = 0; i < s.n_vertices(); ++i)
    for (int j = 0; j < 3; ++j) s.positions[i][j] += offsets->as<float>()[3 * i + j];
  return build(s).mesh;
}

TEST(Decimate, ShapesWeighInTheError) {
  // A sphere with a shape that dents it deeply where the sphere itself is smooth: the dent
  // only survives decimation when collapses are measured in that shape too. The same offsets
  // in a channel without the "shape:" prefix are only interpolated, not measured.
  auto dented_sphere = [](const std::string& name) {
    Soup s = icosphere(5);
    float* o = s.add_channel(name, Domain::vertex, ScalarType::f32, 3).as<float>();
    for (std::size_t i = 0; i < s.n_vertices(); ++i) {
      const Vec3d p = to_double(s.positions[i]);
      const double depth = 0.4 * std::exp(-sqrnorm(p - Vec3d{{1, 0, 0}}) / 0.08);
      for (int j = 0; j < 3; ++j) o[3 * i + j] = static_cast<float>(-depth * p[j]);
    }
    return build(s).mesh;
  };
  DecimateOptions o;
  o.target_ratio = 0.05;
  std::map<std::string, std::pair<double, double>> error;  // basis, dented shape
  for (const std::string name : {"shape:dent", "offsets"}) {
    const Mesh input = dented_sphere(name);
    Mesh mesh = input;
    const DecimateReport r = decimate(mesh, o);
    expect_clean(mesh);
    EXPECT_EQ(r.stopped_by, "target reached");
    error[name] = {hausdorff(input, mesh).max, hausdorff(in_shape(input, name), in_shape(mesh, name)).max};
  }
  const auto [basis, weighed] = error["shape:dent"];
  const auto [basis_carried, carried] = error["offsets"];
  std::printf("to 5 %%, Hausdorff: basis %.4f, dented shape %.4f; offsets only carried: basis %.4f, dented %.4f\n",
              basis, weighed, basis_carried, carried);
  EXPECT_LT(weighed, 0.4 * carried);
  EXPECT_LT(weighed, 2.5 * basis);
  EXPECT_LT(basis, 1.5 * basis_carried);  // the shape costs the basis little
}

TEST(Decimate, AShapeLikeTheMeshChangesNothing) {
  // A key that moves nothing (Blender's fresh "Key 1") leaves the collapses as they were.
  Soup s = icosphere(4);
  Mesh plain = build(s).mesh;
  s.add_channel("shape:Key 1", Domain::vertex, ScalarType::f32, 3);
  Mesh keyed = build(s).mesh;
  DecimateOptions o;
  o.target_ratio = 0.2;
  decimate(plain, o);
  decimate(keyed, o);
  EXPECT_EQ(extract(plain).positions, extract(keyed).positions);
}

// ---- contracts -----------------------------------------------------------------------------

TEST(Decimate, Deterministic) {
  Mesh input;
  if (!load("dragon_res4.ply", input)) input = build(icosphere(4)).mesh;
  Mesh a = input, b = input;
  DecimateOptions o;
  o.target_ratio = 0.15;
  decimate(a, o);
  decimate(b, o);
  const Soup sa = extract(a), sb = extract(b);
  EXPECT_EQ(sa.positions.size(), sb.positions.size());
  EXPECT_EQ(std::memcmp(sa.positions.data(), sb.positions.data(), sa.positions.size() * sizeof(Point)), 0);
  EXPECT_EQ(sa.corners, sb.corners);
  EXPECT_EQ(sa, sb);
}

TEST(Decimate, SameResultOnOneThreadAndTwo) {
  // 7 levels: 327,680 triangles, enough edges for the measuring pass to split.
  const Mesh input = build(icosphere(7)).mesh;
  Mesh a = input, b = input;
  DecimateOptions o;
  o.target_ratio = 0.1;
  o.threads = 1;
  decimate(a, o);
  o.threads = 2;
  decimate(b, o);
  EXPECT_EQ(extract(a), extract(b));
}

// Large meshes collapse in regions on all threads (decimate.cpp): the same result on any
// number of threads, with seams, vertex attributes and a shape along.
TEST(Decimate, SameResultOnOneThreadAndTwoWithAttributes) {
  Mesh loaded;
  Soup soup = load("dragon_res2.ply", loaded) ? extract(loaded) : icosphere(7);
  ASSERT_GT(soup.n_faces(), 100000u);
  std::vector<float> uv, temperature, bend;
  const std::vector<std::size_t> offsets = soup.face_offsets();
  for (std::size_t f = 0; f < soup.n_faces(); ++f) {
    // A seam where the faces' first corners cross x = 0.
    const float chart = soup.positions[soup.corners[offsets[f]]][0] > 0 ? 1.0f : 0.0f;
    for (std::size_t c = offsets[f]; c < offsets[f + 1]; ++c) {
      const Point& p = soup.positions[soup.corners[c]];
      uv.insert(uv.end(), {p[0] + chart, p[1]});
    }
  }
  for (const Point& p : soup.positions) {
    temperature.push_back(p[2]);
    bend.insert(bend.end(), {0.0f, 0.0f, 0.1f * p[0] * p[0]});
  }
  std::memcpy(soup.add_channel("uv", Domain::corner, ScalarType::f32, 2).data.data(), uv.data(), uv.size() * 4);
  std::memcpy(soup.add_channel("temperature", Domain::vertex, ScalarType::f32, 1).data.data(), temperature.data(),
              temperature.size() * 4);
  std::memcpy(soup.add_channel(std::string(kShapePrefix) + "bend", Domain::vertex, ScalarType::f32, 3).data.data(),
              bend.data(), bend.size() * 4);
  const Mesh input = build(soup).mesh;
  Mesh a = input, b = input;
  DecimateOptions o;
  o.target_ratio = 0.1;
  o.threads = 1;
  const DecimateReport ra = decimate(a, o);
  o.threads = 2;
  const DecimateReport rb = decimate(b, o);
  EXPECT_EQ(a.n_faces(), ra.target_faces) << ra.stopped_by;
  EXPECT_EQ(ra.collapses, rb.collapses);
  EXPECT_EQ(extract(a), extract(b));
  expect_clean(a, multi_edges(input));
}

TEST(Decimate, RefusesParametersOutOfRange) {
  const Operation& op = find_operation("decimate");
  EXPECT_NO_THROW(resolve_params(op, std::map<std::string, std::string>{}));
  for (auto [id, value] : std::vector<std::pair<std::string, std::string>>{{"target_ratio", "1.5"},
                                                                           {"target_ratio", "-0.1"},
                                                                           {"max_error", "2"},
                                                                           {"max_error", "-1"},
                                                                           {"min_quality", "1.1"},
                                                                           {"target_faces", "-1"},
                                                                           {"target_faces", "2147483648"},
                                                                           {"prevent_flips", "maybe"},
                                                                           {"target_face", "10"}}) {
    try {
      resolve_params(op, std::map<std::string, std::string>{{id, value}});
      ADD_FAILURE() << id << "=" << value << " accepted";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(id), std::string::npos) << e.what();
    }
  }
  // Defaults as documented.
  const ParamValues v = resolve_params(op, std::map<std::string, std::string>{});
  EXPECT_EQ(v.get_int("target_faces"), 0);
  EXPECT_EQ(v.get_real("target_ratio"), 0.5);
  EXPECT_EQ(v.get_real("max_error"), 0.0);
  EXPECT_TRUE(v.get_bool("preserve_boundary"));
  EXPECT_TRUE(v.get_bool("preserve_uv_seams"));
  EXPECT_TRUE(v.get_bool("prevent_flips"));
}

TEST(Decimate, InputUntouchedOnFailureAndCancel) {
  Mesh mesh = build(uv_cylinder()).mesh;
  const Soup before = extract(mesh);
  DecimateOptions bad;
  bad.target_ratio = 2;
  EXPECT_THROW(decimate(mesh, bad), Error);
  bad = {};
  bad.max_error = std::nan("");
  EXPECT_THROW(decimate(mesh, bad), Error);
  EXPECT_EQ(extract(mesh), before);

  // Cancelled half-way: the mesh comes back as it was.
  int calls = 0;
  Progress cancel_later([&](double, const std::string&) { return ++calls < 5; });
  DecimateOptions o;
  o.target_ratio = 0.05;
  EXPECT_THROW(decimate(mesh, o, cancel_later), Cancelled);
  EXPECT_GE(calls, 5);
  EXPECT_TRUE(validate(mesh).ok);
  EXPECT_EQ(extract(mesh), before);
}

TEST(Decimate, ThroughTheCatalogue) {
  const Operation& op = find_operation("decimate");
  EXPECT_EQ(op.title, "Decimate");
  EXPECT_EQ(op.category, Category::remeshing);
  const Soup input = uv_cylinder();
  const ParamValues params = resolve_params(op, std::map<std::string, std::string>{{"target_faces", "500"}});
  const RunResult r = run_operation(op, input, params, Progress::none());
  EXPECT_EQ(r.soup.n_faces(), 500u);
  ASSERT_NE(r.soup.find("uv", Domain::corner), nullptr);
  EXPECT_EQ(r.soup.find("uv", Domain::corner)->count(), r.soup.n_corners());
  EXPECT_NE(r.report.find("max_error"), nullptr);
  EXPECT_EQ(std::get<std::string>(*r.report.find("stopped_by")), "target reached");
}

// ---- timings (printed, not asserted) ---------------------------------------------------------

TEST(Decimate, DragonTiming) {
  for (const std::string name : {"dragon_res2.ply", "dragon.ply"}) {
    Mesh input;
    const auto t0 = Clock::now();
    if (!load(name, input)) {
      std::printf("  %s not present, skipped\n", name.c_str());
      continue;
    }
    const double load_s = seconds_since(t0);
    Mesh mesh = input;
    DecimateOptions o;
    o.target_ratio = 0.1;
    const Outcome r = run(mesh, o);
    expect_clean(mesh, multi_edges(input));
    EXPECT_EQ(mesh.n_faces(), r.report.target_faces) << r.report.stopped_by;
    const auto t1 = Clock::now();
    const double diag = bbox_diagonal(input);
    HausdorffOptions ho;
    ho.sample_density = name == "dragon.ply" ? 1.0 : 4.0;
    const HausdorffResult h = hausdorff(input, mesh, ho);
    const std::size_t flips = flipped_faces(input, mesh, true);
    std::printf(
        "  %s: %zu -> %zu faces in %.3f s (CPU %.3f s; load+build %.2f s); Hausdorff %.3g diag (in->out %.3g, "
        "out->in %.3g, mean %.3g), measured in %.1f s; %zu collapses; %zu interior triangles flipped\n",
        name.c_str(), input.n_faces(), mesh.n_faces(), r.seconds, r.cpu_seconds, load_s, h.max / diag,
        h.a_to_b.max / diag, h.b_to_a.max / diag, h.a_to_b.mean / diag, seconds_since(t1), r.report.collapses, flips);
    EXPECT_LT(h.max, 0.005 * diag);
    if (name == "dragon.ply") {
      EXPECT_LT(h.max, 0.0006 * diag);  // the reference, CGAL's Garland-Heckbert, gives 0.00049-0.00056
      EXPECT_EQ(flips, 0u);
    }
  }
}

}  // namespace
}  // namespace hedge
