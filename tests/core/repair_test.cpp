// Tests of the repair operation (repair.h): build()'s repairs kept, degenerate and duplicate
// faces, welding, pinches and isolated vertices removed, and an output that builds clean.
#include "hedge/repair.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <map>

#include "hedge/build.h"
#include "hedge/catalogue.h"
#include "hedge/io.h"
#include "hedge/report.h"
#include "hedge/validate.h"
#include "defect_counts.h"
#include "test_meshes.h"

namespace hedge {
namespace {

// Adds points shifted by x0 along x and returns the index of the first.
std::uint32_t add_points(Soup& s, float x0, std::initializer_list<std::array<float, 3>> points) {
  const auto first = std::uint32_t(s.positions.size());
  for (const auto& p : points) s.positions.push_back(Point{{p[0] + x0, p[1], p[2]}});
  return first;
}

// Three triangles on one edge: a non-manifold edge (and its two end vertices).
void add_book(Soup& s, float x0) {
  auto a = add_points(s, x0, {{0, 0, 0}, {1, 0, 0}, {0.5f, 1, 0}, {0.5f, -1, 0}, {0.5f, 0, 1}});
  s.add_face({a, a + 1, a + 2});
  s.add_face({a + 1, a, a + 3});
  s.add_face({a, a + 1, a + 4});
}

// Two triangles sharing only a vertex: a non-manifold vertex.
void add_bowtie(Soup& s, float x0) {
  auto b = add_points(s, x0, {{0, 0, 0}, {1, -0.5f, 0}, {1, 0.5f, 0}, {-1, 0.5f, 0}, {-1, -0.5f, 0}});
  s.add_face({b, b + 1, b + 2});
  s.add_face({b, b + 3, b + 4});
}

// A strip of four triangles, the last one listed backwards: one flip.
void add_flipped_strip(Soup& s, float x0) {
  auto c = add_points(s, x0, {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {2, 0, 0}, {2, 1, 0}});
  s.add_face({c, c + 1, c + 2});
  s.add_face({c, c + 2, c + 3});
  s.add_face({c + 1, c + 4, c + 5});
  s.add_face({c + 1, c + 2, c + 5});  // should be (c1, c5, c2)
}

// A square whose bottom edge is split at its middle, with a zero-area triangle along it.
void add_degenerate(Soup& s, float x0) {
  auto d = add_points(s, x0, {{0, 0, 0}, {2, 0, 0}, {2, 2, 0}, {0, 2, 0}, {1, 0, 0}});
  s.add_face({d, d + 4, d + 3});
  s.add_face({d + 4, d + 1, d + 2});
  s.add_face({d + 4, d + 2, d + 3});
  s.add_face({d + 4, d, d + 1});  // collinear
}

// Two triangles of a square, the second one listed twice.
void add_duplicate(Soup& s, float x0) {
  auto e = add_points(s, x0, {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}});
  s.add_face({e, e + 1, e + 2});
  s.add_face({e, e + 2, e + 3});
  s.add_face({e, e + 2, e + 3});
}

// Two triangles of a square that do not share their diagonal's vertices: copies 1e-6 apart.
void add_near_duplicates(Soup& s, float x0) {
  auto f = add_points(s, x0, {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {1e-6f, 0, 0}, {1, 1 + 1e-6f, 0}});
  s.add_face({f, f + 1, f + 2});
  s.add_face({f + 4, f + 5, f + 3});
}

std::int64_t entry(const OperationReport& r, const std::string& key) {
  const Value* v = r.find(key);
  EXPECT_NE(v, nullptr) << key;
  return v ? std::get<std::int64_t>(*v) : -1;
}

RunResult run_repair(const Soup& soup, std::map<std::string, std::string> params = {}) {
  const Operation& op = find_operation("repair");
  return run_operation(op, soup, resolve_params(op, params), Progress::none());
}

bool have(const std::string& name) { return std::filesystem::exists(std::string(HEDGE_MESH_DIR) + "/" + name); }

TEST(Repair, EveryDefectRepairedAndTheResultBuildsClean) {
  Soup soup;
  add_book(soup, 0);
  add_bowtie(soup, 10);
  add_flipped_strip(soup, 20);
  add_degenerate(soup, 30);
  add_duplicate(soup, 40);
  add_near_duplicates(soup, 50);
  add_points(soup, 60, {{0, 0, 0}});  // isolated
  // Attributes that identify their element, to see them follow.
  Channel& id = soup.add_channel("id", Domain::vertex, ScalarType::i32, 1);
  for (std::size_t v = 0; v < soup.n_vertices(); ++v) id.as<std::int32_t>()[v] = std::int32_t(v);
  Channel& material = soup.add_channel("material", Domain::face, ScalarType::i32, 1);
  for (std::size_t f = 0; f < soup.n_faces(); ++f) material.as<std::int32_t>()[f] = std::int32_t(f);
  Channel& corner = soup.add_channel("corner", Domain::corner, ScalarType::i32, 1);
  for (std::size_t c = 0; c < soup.n_corners(); ++c) corner.as<std::int32_t>()[c] = std::int32_t(soup.corners[c]);
  ASSERT_TRUE(build(soup).report.repaired());

  RunResult run = run_repair(soup, {{"weld_distance", "1e-4"}});
  EXPECT_EQ(entry(run.report, "non_manifold_edges_split"), 1);
  EXPECT_EQ(entry(run.report, "non_manifold_vertices_split"), 3);
  EXPECT_EQ(entry(run.report, "faces_flipped"), 1);
  EXPECT_EQ(entry(run.report, "degenerate_faces_removed"), 1);
  EXPECT_EQ(entry(run.report, "duplicate_faces_removed"), 1);
  EXPECT_EQ(entry(run.report, "vertices_welded"), 2);
  EXPECT_EQ(entry(run.report, "isolated_vertices_removed"), 1);
  EXPECT_EQ(entry(run.report, "pinched_faces_removed"), 0);

  ASSERT_NO_THROW(run.soup.check());
  // Every vertex keeps its own id (copies their source's), and every corner its vertex's.
  const Channel* out_id = run.soup.find("id", Domain::vertex);
  const Channel* out_corner = run.soup.find("corner", Domain::corner);
  ASSERT_TRUE(out_id && out_corner && run.soup.find("material", Domain::face));
  for (std::size_t v = 0; v < run.soup.n_vertices(); ++v) {
    const auto source = std::size_t(out_id->as<std::int32_t>()[v]);
    ASSERT_LT(source, soup.n_vertices());
    EXPECT_EQ(run.soup.positions[v], soup.positions[source]) << v;
  }
  for (std::size_t c = 0; c < run.soup.n_corners(); ++c) {
    const std::int32_t vertex_id = out_id->as<std::int32_t>()[run.soup.corners[c]];
    const std::int32_t corner_id = out_corner->as<std::int32_t>()[c];
    // A welded corner names the vertex it was welded away from; they are 1e-6 apart. The
    // collapse of the degenerate face (x in 30..32) moves a vertex: its corners keep their
    // values, as every collapse does.
    const Point& a = soup.positions[std::size_t(vertex_id)];
    const Point& b = soup.positions[std::size_t(corner_id)];
    if (a[0] >= 30 && a[0] <= 32) continue;
    EXPECT_NEAR(a[0], b[0], 1e-5f);
    EXPECT_NEAR(a[1], b[1], 1e-5f);
  }

  BuildResult again = build(run.soup);
  EXPECT_FALSE(again.report.repaired()) << again.report.messages.front();
  EXPECT_EQ(again.report.isolated_vertices, 0u);
  ASSERT_VALID(again.mesh);
  const MeshStatistics s = mesh_statistics(again.mesh);
  EXPECT_EQ(s.degenerate_faces, 0u);
  EXPECT_EQ(s.multi_edges, 0u);
  // Faces: 3 book + 2 bow-tie + 4 strip + 2 (degenerate square after the collapse)
  // + 2 (duplicate square) + 2 (welded square).
  EXPECT_EQ(run.soup.n_faces(), 15u);
  // Vertices: the book and the bow-tie keep their copies (+2, +1), the collapse and the
  // weld take some away (-1, -2).
  EXPECT_EQ(run.soup.n_vertices(), (5u + 2u) + (5u + 1u) + 6u + (5u - 1u) + 4u + (6u - 2u));
}

// Collapsing the zero-area faces of this soup (found by fuzzing) glues two quads into a
// pillow: one vertex set twice. The later one goes, and the result has no defect at all.
TEST(Repair, CollapsesLeaveNoDuplicateFace) {
  const Soup soup = read_mesh(std::string(HEDGE_TEST_DATA) + "/repair_pinch_quad_pillow.off");
  ASSERT_EQ(test::count_defects(soup).duplicate_faces, 0u);
  const RunResult result = run_repair(soup);
  const test::DefectCounts after = test::count_defects(result.soup);
  EXPECT_EQ(after.duplicate_faces, 0u);
  EXPECT_EQ(after.non_manifold_edges + after.non_manifold_vertices + after.repeating_faces, 0u) << after;
  EXPECT_GE(entry(result.report, "duplicate_faces_removed"), 1);
}

TEST(Repair, CountsMatchWhatBuildReported) {
  // No welding and no duplicates: the counts come from build()'s provenance alone.
  Soup soup;
  add_book(soup, 0);
  add_bowtie(soup, 10);
  add_flipped_strip(soup, 20);
  add_book(soup, 30);
  soup.add_face({0, 0, 1});  // fewer than 3 distinct vertices: build() skips it
  add_bowtie(soup, 40);      // so that the skipped face is not the last one
  const BuildReport input = build(soup).report;
  ASSERT_EQ(input.skipped_faces, 1u);
  RunResult run = run_repair(soup);
  EXPECT_EQ(entry(run.report, "non_manifold_edges_split"), std::int64_t(input.non_manifold_edges));
  EXPECT_EQ(entry(run.report, "non_manifold_vertices_split"), std::int64_t(input.non_manifold_vertices));
  EXPECT_EQ(entry(run.report, "vertex_copies_added"), std::int64_t(input.vertex_copies));
  EXPECT_EQ(entry(run.report, "faces_flipped"), std::int64_t(input.flipped_faces));
  EXPECT_EQ(entry(run.report, "degenerate_faces_removed"), std::int64_t(input.skipped_faces));
  EXPECT_EQ(input.non_manifold_edges, 2u);
  EXPECT_EQ(run.soup.n_vertices(), soup.n_vertices() + input.vertex_copies);
  EXPECT_EQ(run.soup.n_faces(), soup.n_faces() - 1);
  EXPECT_FALSE(build(run.soup).report.repaired());
}

TEST(Repair, CleanMeshIsUnchanged) {
  Soup soup;
  for (int y = 0; y <= 4; ++y)
    for (int x = 0; x <= 4; ++x) soup.positions.push_back(Point{{float(x), float(y), float(x * y) / 10}});
  for (std::uint32_t y = 0; y < 4; ++y)
    for (std::uint32_t x = 0; x < 4; ++x)
      soup.add_face({y * 5 + x, y * 5 + x + 1, (y + 1) * 5 + x + 1, (y + 1) * 5 + x});
  Channel& quality = soup.add_channel("quality", Domain::vertex, ScalarType::f32, 1);
  for (std::size_t v = 0; v < soup.n_vertices(); ++v) quality.as<float>()[v] = float(v) * 0.5f;
  Channel& material = soup.add_channel("material", Domain::face, ScalarType::i32, 1);
  for (std::size_t f = 0; f < soup.n_faces(); ++f) material.as<std::int32_t>()[f] = std::int32_t(f % 3);
  Channel& uv = soup.add_channel("uv", Domain::corner, ScalarType::f32, 2);
  for (std::size_t c = 0; c < 2 * soup.n_corners(); ++c) uv.as<float>()[c] = float(c) / 7;
  RunResult run = run_repair(soup, {{"weld_distance", "0.01"}});
  EXPECT_TRUE(run.soup == soup);
  for (const char* key :
       {"non_manifold_edges_split", "non_manifold_vertices_split", "faces_flipped", "degenerate_faces_removed",
        "duplicate_faces_removed", "vertices_welded", "isolated_vertices_removed", "pinched_faces_removed"})
    EXPECT_EQ(entry(run.report, key), 0) << key;
}

TEST(Repair, DegenerateFaceCollapses) {
  Soup soup;
  add_degenerate(soup, 0);
  Mesh mesh = build(soup).mesh;
  RepairReport r = repair(mesh);
  ASSERT_VALID(mesh);
  EXPECT_EQ(r.degenerate_faces_removed, 1u);
  EXPECT_EQ(r.degenerate_faces_deleted, 0u);
  EXPECT_EQ(mesh.n_faces(), 2u);
  EXPECT_EQ(mesh.n_vertices(), 4u);
  EXPECT_EQ(mesh_statistics(mesh).degenerate_faces, 0u);
}

TEST(Repair, IsolatedVerticesKeptOnRequest) {
  Soup soup;
  add_bowtie(soup, 0);
  add_points(soup, 5, {{0, 0, 0}, {1, 0, 0}});
  Mesh mesh = build(soup).mesh;
  RepairOptions options;
  options.remove_isolated_vertices = false;
  RepairReport r = repair(mesh, options);
  ASSERT_VALID(mesh);
  EXPECT_EQ(r.isolated_vertices_removed, 0u);
  EXPECT_EQ(mesh.n_vertices(), 8u);  // 5 + the copy + 2 isolated
  r = repair(mesh);
  EXPECT_EQ(r.isolated_vertices_removed, 2u);
  EXPECT_EQ(mesh.n_vertices(), 6u);
}

TEST(Repair, WeldJoinsSheetsAlongTheirSeam) {
  // Two 8x8 grids side by side whose seam vertices are 1e-5 apart: welding glues them.
  Soup soup;
  for (int sheet = 0; sheet < 2; ++sheet) {
    const auto base = std::uint32_t(soup.positions.size());
    for (int y = 0; y <= 8; ++y)
      for (int x = 0; x <= 8; ++x) soup.positions.push_back(Point{{float(x + 8 * sheet) + sheet * 1e-5f, float(y), 0}});
    for (std::uint32_t y = 0; y < 8; ++y)
      for (std::uint32_t x = 0; x < 8; ++x)
        soup.add_face({base + y * 9 + x, base + y * 9 + x + 1, base + (y + 1) * 9 + x + 1, base + (y + 1) * 9 + x});
  }
  RunResult run = run_repair(soup, {{"weld_distance", "1e-4"}});
  EXPECT_EQ(entry(run.report, "vertices_welded"), 9);
  BuildResult again = build(run.soup);
  EXPECT_FALSE(again.report.repaired());
  EXPECT_EQ(mesh_statistics(again.mesh).topology.boundary_loops, 1u);
  EXPECT_EQ(mesh_statistics(again.mesh).topology.components, 1u);
  // A distance below the gap welds nothing.
  RunResult none = run_repair(soup, {{"weld_distance", "1e-6"}});
  EXPECT_EQ(entry(none.report, "vertices_welded"), 0);
  // A huge distance welds everything into one point: every face degenerates, nothing hangs.
  RunResult all = run_repair(soup, {{"weld_distance", "1e30"}});
  EXPECT_EQ(entry(all.report, "vertices_welded"), std::int64_t(soup.n_vertices()) - 1);
  EXPECT_EQ(all.soup.n_faces(), 0u);
}

TEST(Repair, BadDistanceAndCancelLeaveTheMeshAlone) {
  Soup soup;
  add_book(soup, 0);
  Mesh mesh = build(soup).mesh;
  const std::size_t vertices = mesh.n_vertices(), faces = mesh.n_faces();
  RepairOptions bad;
  bad.weld_distance = -1;
  EXPECT_THROW(repair(mesh, bad), Error);
  Progress stop([](double fraction, const std::string&) { return fraction < 0.4; });
  EXPECT_THROW(repair(mesh, {}, stop), Cancelled);
  EXPECT_EQ(mesh.n_vertices(), vertices);
  EXPECT_EQ(mesh.n_faces(), faces);
  EXPECT_TRUE(mesh.vertex_properties().exists("hedge:source"));  // provenance still there
}

TEST(Repair, DragonRes4BuildsCleanAfterwards) {
  if (!have("dragon_res4.ply")) GTEST_SKIP() << "dragon_res4.ply not fetched";
  const Soup soup = read_mesh(std::string(HEDGE_MESH_DIR) + "/dragon_res4.ply");
  const BuildReport input = build(soup).report;
  auto t0 = std::chrono::steady_clock::now();
  RunResult run = run_repair(soup);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  // Most of its non-manifold edges come from duplicate faces: removing those instead
  // leaves fewer splits to keep.
  EXPECT_GT(entry(run.report, "duplicate_faces_removed"), 0);
  EXPECT_LE(entry(run.report, "non_manifold_edges_split"), std::int64_t(input.non_manifold_edges));
  BuildResult again = build(run.soup);
  EXPECT_FALSE(again.report.repaired());
  ASSERT_VALID(again.mesh);
  const MeshStatistics s = mesh_statistics(again.mesh);
  EXPECT_EQ(s.multi_edges, 0u);
  EXPECT_EQ(again.report.isolated_vertices, 0u);
  std::printf("[ repair ] dragon_res4 in %.3f s:\n%s", seconds, run.report.to_text().c_str());
}

TEST(Repair, DragonWeldClosesCracks) {
  if (!have("dragon.ply")) GTEST_SKIP() << "dragon.ply not fetched";
  const Soup soup = read_mesh(std::string(HEDGE_MESH_DIR) + "/dragon.ply");
  const MeshStatistics before = mesh_statistics(build(soup).mesh);
  auto t0 = std::chrono::steady_clock::now();
  RunResult run = run_repair(soup, {{"weld_distance", "1e-6"}});
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  BuildResult again = build(run.soup);
  EXPECT_FALSE(again.report.repaired());
  ASSERT_VALID(again.mesh);
  const MeshStatistics after = mesh_statistics(again.mesh);
  EXPECT_EQ(after.degenerate_faces, 0u);
  EXPECT_EQ(after.multi_edges, 0u);
  EXPECT_LT(after.topology.boundary_loops, before.topology.boundary_loops);
  std::printf("[ repair ] dragon, weld 1e-6, in %.2f s: boundary loops %zu -> %zu, degenerate faces %zu -> %zu\n%s",
              seconds, before.topology.boundary_loops, after.topology.boundary_loops, before.degenerate_faces,
              after.degenerate_faces, run.report.to_text().c_str());
}

}  // namespace
}  // namespace hedge
