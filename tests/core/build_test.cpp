// Tests of build() and extract() (build.h): every pathological soup a host can hold builds
// a valid mesh with the expected repairs and round-trips to the identical soup.
#include "hedge/build.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <limits>
#include <random>
#include <string>
#include <tuple>
#include <vector>

#include "defect_counts.h"
#include "hedge/error.h"
#include "hedge/io.h"
#include "hedge/provenance.h"
#include "hedge/validate.h"
#include "test_meshes.h"

namespace hedge {
namespace {

// Distinct, finite positions for n vertices.
Soup soup_with_vertices(std::size_t n) {
  Soup soup;
  for (std::size_t i = 0; i < n; ++i)
    soup.positions.push_back(Point{{float(i), float((i * 7) % 5) * 0.5f, float((i * 3) % 4) - 1.5f}});
  return soup;
}

Soup make_soup(std::size_t n_vertices, const std::vector<std::vector<std::uint32_t>>& faces) {
  Soup soup = soup_with_vertices(n_vertices);
  for (const auto& f : faces) soup.add_face(f);
  return soup;
}

// The soup build() is expected to give back: the input without the skipped faces.
Soup without_faces(const Soup& soup, const std::vector<std::uint32_t>& skipped) {
  if (skipped.empty()) return soup;
  Soup out;
  out.positions = soup.positions;
  std::vector<bool> skip(soup.n_faces(), false);
  for (auto f : skipped) skip[f] = true;
  const auto offsets = soup.face_offsets();
  std::vector<std::size_t> kept_faces, kept_corners;
  for (std::size_t f = 0; f < soup.n_faces(); ++f) {
    if (skip[f]) continue;
    kept_faces.push_back(f);
    out.face_sizes.push_back(soup.face_sizes[f]);
    for (std::size_t c = offsets[f]; c < offsets[f + 1]; ++c) {
      out.corners.push_back(soup.corners[c]);
      kept_corners.push_back(c);
    }
  }
  for (const Channel& c : soup.channels) {
    Channel k = c;
    const std::vector<std::size_t>* keep = c.domain == Domain::face     ? &kept_faces
                                           : c.domain == Domain::corner ? &kept_corners
                                                                        : nullptr;
    if (keep) {
      k.data.clear();
      for (std::size_t i : *keep)
        k.data.insert(k.data.end(), c.data.begin() + i * c.stride(), c.data.begin() + (i + 1) * c.stride());
    }
    out.channels.push_back(std::move(k));
  }
  return out;
}

struct Counts {
  std::size_t non_manifold_edges = 0, non_manifold_vertices = 0, vertex_copies = 0, flipped_faces = 0,
              unorientable_edges = 0, repeated_vertex_faces = 0, skipped_faces = 0, isolated_vertices = 0;
  bool operator==(const Counts&) const = default;
};

Counts counts(const BuildReport& r) {
  return {r.non_manifold_edges, r.non_manifold_vertices, r.vertex_copies, r.flipped_faces,
          r.unorientable_edges, r.repeated_vertex_faces, r.skipped_faces, r.isolated_vertices};
}

std::ostream& operator<<(std::ostream& out, const Counts& c) {
  return out << "{nm_edges " << c.non_manifold_edges << ", nm_vertices " << c.non_manifold_vertices << ", copies "
             << c.vertex_copies << ", flipped " << c.flipped_faces << ", unorientable " << c.unorientable_edges
             << ", repeated " << c.repeated_vertex_faces << ", skipped " << c.skipped_faces << ", isolated "
             << c.isolated_vertices << "}";
}

std::string messages(const BuildReport& r) {
  std::string out;
  for (const auto& m : r.messages) out += "  " + m + "\n";
  return out;
}

// Everything every build must satisfy: valid mesh, no face lost, maps consistent, round trip.
BuildResult build_and_check(const Soup& soup, const BuildOptions& options = {}) {
  BuildResult r = build(soup, options);
  const Validation v = validate(r.mesh);
  EXPECT_TRUE(v) << v.message;
  EXPECT_EQ(r.mesh.n_faces(), soup.n_faces() - r.report.skipped_faces);
  EXPECT_EQ(r.report.skipped_faces, r.maps.skipped_faces.size());
  EXPECT_EQ(r.mesh.n_vertices(), soup.n_vertices() + r.report.vertex_copies);
  EXPECT_EQ(r.maps.vertex_source.size(), r.mesh.n_vertices());
  EXPECT_EQ(r.maps.face_source.size(), r.mesh.n_faces());
  EXPECT_EQ(r.report.repaired(), r.report.messages.size() > (r.report.isolated_vertices ? 1u : 0u));
  for (std::size_t v = 0; v < r.maps.vertex_source.size(); ++v)
    EXPECT_EQ(r.mesh.position(Vertex(Index(v))), soup.positions[r.maps.vertex_source[v]]);
  EXPECT_EQ(extract(r.mesh), without_faces(soup, r.maps.skipped_faces)) << messages(r.report);
  return r;
}

std::size_t count_boundary_halfedges(const Mesh& m) {
  std::size_t n = 0;
  for (Halfedge h : m.halfedges()) n += m.is_boundary(h);
  return n;
}

// Lengths of the boundary loops, each loop once.
std::vector<std::size_t> boundary_loops(const Mesh& m) {
  std::vector<bool> seen(m.halfedges_size(), false);
  std::vector<std::size_t> loops;
  for (Halfedge h : m.halfedges()) {
    if (!m.is_boundary(h) || seen[h.idx()]) continue;
    std::size_t n = 0;
    for (Halfedge g : m.loop(h)) {
      seen[g.idx()] = true;
      ++n;
    }
    loops.push_back(n);
  }
  return loops;
}

long euler_characteristic(const Mesh& m) { return long(m.n_vertices()) - long(m.n_edges()) + long(m.n_faces()); }

std::size_t n_properties(const Mesh& m) {
  return m.vertex_properties().count() + m.halfedge_properties().count() + m.edge_properties().count() +
         m.face_properties().count();
}

Soup grid(int k, int l) {  // k x l quads, counter-clockwise
  Soup soup;
  for (int y = 0; y <= l; ++y)
    for (int x = 0; x <= k; ++x) soup.positions.push_back(Point{{float(x), float(y), 0}});
  auto id = [&](int x, int y) { return std::uint32_t(y * (k + 1) + x); };
  for (int y = 0; y < l; ++y)
    for (int x = 0; x < k; ++x) soup.add_face({id(x, y), id(x + 1, y), id(x + 1, y + 1), id(x, y + 1)});
  return soup;
}

// ---- clean input -------------------------------------------------------------------------

TEST(Build, EmptySoup) {
  BuildResult r = build_and_check(Soup{});
  EXPECT_TRUE(r.mesh.is_empty());
  EXPECT_EQ(counts(r.report), Counts{});
  EXPECT_TRUE(r.report.messages.empty());
}

TEST(Build, OnlyIsolatedVertices) {
  BuildResult r = build_and_check(soup_with_vertices(4));
  EXPECT_EQ(r.mesh.n_vertices(), 4u);
  EXPECT_EQ(counts(r.report), Counts{.isolated_vertices = 4});
  EXPECT_FALSE(r.report.repaired());
}

TEST(Build, SingleTriangle) {
  BuildResult r = build_and_check(make_soup(3, {{0, 1, 2}}));
  EXPECT_EQ(counts(r.report), Counts{});
  EXPECT_EQ(boundary_loops(r.mesh), std::vector<std::size_t>{3});
  // halfedge(f) points to corner 0; the loop visits the corners in order.
  std::vector<Index> corners;
  for (Vertex v : r.mesh.vertices(Face(0))) corners.push_back(v.idx());
  EXPECT_EQ(corners, (std::vector<Index>{0, 1, 2}));
  for (Vertex v : r.mesh.vertices()) EXPECT_TRUE(r.mesh.is_boundary(r.mesh.halfedge(v)));
  EXPECT_EQ(n_properties(r.mesh), 0u);
}

TEST(Build, IsolatedVerticesAreKept) {
  BuildResult r = build_and_check(make_soup(6, {{1, 3, 4}}));
  EXPECT_EQ(counts(r.report), Counts{.isolated_vertices = 3});
  EXPECT_TRUE(r.mesh.is_isolated(Vertex(0)));
  EXPECT_FALSE(r.mesh.is_isolated(Vertex(1)));
  EXPECT_FALSE(r.report.repaired());
}

TEST(Build, ClosedTetrahedron) {
  BuildResult r = build_and_check(make_soup(4, {{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {2, 0, 3}}));
  EXPECT_EQ(counts(r.report), Counts{});
  EXPECT_EQ(count_boundary_halfedges(r.mesh), 0u);
  EXPECT_EQ(euler_characteristic(r.mesh), 2);
  EXPECT_EQ(r.mesh.n_edges(), 6u);
  EXPECT_EQ(n_properties(r.mesh), 0u);
}

TEST(Build, ClosedCube) {
  BuildResult r = build_and_check(
      make_soup(8, {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4}, {1, 2, 6, 5}, {2, 3, 7, 6}, {3, 0, 4, 7}}));
  EXPECT_EQ(counts(r.report), Counts{});
  EXPECT_EQ(count_boundary_halfedges(r.mesh), 0u);
  EXPECT_EQ(euler_characteristic(r.mesh), 2);
  EXPECT_EQ(r.mesh.n_edges(), 12u);
  for (Vertex v : r.mesh.vertices()) EXPECT_EQ(r.mesh.valence(v), 3u);
}

TEST(Build, OpenGridHasOneBoundaryLoop) {
  BuildResult r = build_and_check(grid(5, 3));
  EXPECT_EQ(counts(r.report), Counts{});
  EXPECT_EQ(boundary_loops(r.mesh), std::vector<std::size_t>{16});
  EXPECT_EQ(euler_characteristic(r.mesh), 1);
  EXPECT_EQ(n_properties(r.mesh), 0u);
  // The boundary loop runs against the faces: each outer half-edge's target is its twin's origin.
  for (Vertex v : r.mesh.vertices()) {
    if (r.mesh.is_boundary(v)) {
      EXPECT_FALSE(r.mesh.face(r.mesh.halfedge(v)).is_valid());
    }
  }
}

TEST(Build, LargeGridTakesTheParallelPaths) {
  Soup soup = grid(300, 250);
  BuildResult r = build_and_check(soup);
  EXPECT_EQ(counts(r.report), Counts{});
  EXPECT_EQ(boundary_loops(r.mesh), std::vector<std::size_t>{2 * (300 + 250)});
  EXPECT_EQ(n_properties(r.mesh), 0u);
  // Memory is exact: no growth slack in any array.
  const std::size_t expected = r.mesh.vertices_size() * (sizeof(Halfedge) + sizeof(Point)) +
                               r.mesh.halfedges_size() * 4 * sizeof(Index) + r.mesh.faces_size() * sizeof(Halfedge);
  EXPECT_EQ(r.mesh.heap_bytes(), expected);
}

TEST(Build, LargeGridWithDefectsTakesTheGeneralPath) {
  // Three reversed quads (each the minority of its neighbourhood) and a fourth quad glued
  // onto an interior edge: the fast path gives up and the general one repairs.
  Soup soup = grid(300, 250);
  for (std::uint32_t f : {1000u, 20000u, 60000u})
    std::reverse(soup.corners.begin() + 4 * f, soup.corners.begin() + 4 * f + 4);
  const std::uint32_t a = soup.corners[4 * 500], b = soup.corners[4 * 500 + 1];
  soup.positions.push_back(Point{{0.5f, 0.5f, 1.0f}});
  soup.add_face({a, b, std::uint32_t(soup.positions.size() - 1)});
  BuildResult r = build_and_check(soup);
  EXPECT_EQ(counts(r.report),
            (Counts{.non_manifold_edges = 1, .non_manifold_vertices = 2, .vertex_copies = 2, .flipped_faces = 3}));
}

TEST(Build, LargeCheckerboardOfPinchedVertices) {
  // Quads on the black squares only: every interior vertex joins two quads at a corner.
  const int k = 300;
  Soup soup;
  for (int y = 0; y <= k; ++y)
    for (int x = 0; x <= k; ++x) soup.positions.push_back(Point{{float(x), float(y), 0}});
  auto id = [&](int x, int y) { return std::uint32_t(y * (k + 1) + x); };
  for (int y = 0; y < k; ++y)
    for (int x = 0; x < k; ++x)
      if ((x + y) % 2 == 0) soup.add_face({id(x, y), id(x + 1, y), id(x + 1, y + 1), id(x, y + 1)});
  BuildResult r = build_and_check(soup);
  const std::size_t pinched = std::size_t(k - 1) * (k - 1);
  EXPECT_EQ(counts(r.report),
            (Counts{.non_manifold_vertices = pinched, .vertex_copies = pinched, .isolated_vertices = 2}));
  EXPECT_EQ(boundary_loops(r.mesh).size(), soup.n_faces());
}

// ---- non-manifold input ------------------------------------------------------------------

TEST(Build, NonManifoldEdgeWithThreeFaces) {
  BuildResult r = build_and_check(make_soup(5, {{0, 1, 2}, {1, 0, 3}, {0, 1, 4}}));
  // Faces 0 and 1 glue; face 2 keeps its own edge and copies of vertices 0 and 1.
  EXPECT_EQ(counts(r.report), (Counts{.non_manifold_edges = 1, .non_manifold_vertices = 2, .vertex_copies = 2}));
  EXPECT_EQ(r.maps.vertex_source, (std::vector<std::uint32_t>{0, 1, 2, 3, 4, 0, 1}));
  EXPECT_TRUE(r.mesh.get_vertex_property<std::uint32_t>(provenance::kVertexSource));
  EXPECT_FALSE(r.mesh.get_face_property<bool>(provenance::kFlipped));
  EXPECT_EQ(r.mesh.n_edges(), 8u);
}

TEST(Build, NonManifoldEdgeBookOfFourPages) {
  BuildResult r = build_and_check(make_soup(6, {{0, 1, 2}, {1, 0, 3}, {0, 1, 4}, {1, 0, 5}}));
  EXPECT_EQ(counts(r.report), (Counts{.non_manifold_edges = 1, .non_manifold_vertices = 2, .vertex_copies = 4}));
}

TEST(Build, TwoTetrahedraSharingAnEdge) {
  // Closed tetrahedra (0,1,2,3) and (0,1,4,5) glued along edge 0-1: four faces on it.
  BuildResult r = build_and_check(
      make_soup(6, {{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {2, 0, 3}, {0, 4, 1}, {0, 1, 5}, {1, 4, 5}, {4, 0, 5}}));
  EXPECT_EQ(counts(r.report), (Counts{.non_manifold_edges = 1, .non_manifold_vertices = 2, .vertex_copies = 2}));
  EXPECT_EQ(r.mesh.n_faces(), 8u);
}

TEST(Build, NonManifoldVertexBowtie) {
  BuildResult r = build_and_check(make_soup(5, {{0, 1, 2}, {0, 3, 4}}));
  EXPECT_EQ(counts(r.report), (Counts{.non_manifold_vertices = 1, .vertex_copies = 1}));
  EXPECT_EQ(boundary_loops(r.mesh), (std::vector<std::size_t>{3, 3}));
  EXPECT_EQ(r.maps.vertex_source.back(), 0u);
}

TEST(Build, ExtractKeepsCopiesApartThatWouldRepeatAVertex) {
  // Vertex 0 of the bow-tie becomes 0 (fan 0 1 2) and copy 5 (fan 0 3 4). A face through
  // both copies, as hole filling or a collapse can make, must not come back as (0, 2, 0, 4).
  Soup soup = make_soup(5, {{0, 1, 2}, {0, 3, 4}});
  soup.add_channel("quality", Domain::vertex, ScalarType::f32, 1);
  BuildResult r = build_and_check(soup);
  ASSERT_EQ(r.mesh.n_vertices(), 6u);
  const Vertex copy(5);
  ASSERT_EQ(r.maps.vertex_source[copy.idx()], 0u);
  const Vertex corners[] = {Vertex(0), Vertex(2), copy, Vertex(4)};
  ASSERT_TRUE(r.mesh.add_face(corners).is_valid());
  ASSERT_VALID(r.mesh);

  ExtractReport report;
  const Soup out = extract(r.mesh, {}, &report);
  EXPECT_EQ(report.copies_kept_apart, 1u);
  ASSERT_EQ(out.positions.size(), 6u);
  EXPECT_EQ(out.positions[5], out.positions[0]);
  EXPECT_EQ(out.corners, (std::vector<std::uint32_t>{0, 1, 2, 5, 3, 4, 0, 2, 5, 4}));
  ASSERT_EQ(out.channels.size(), 1u);
  EXPECT_EQ(out.channels[0].data.size(), 6 * sizeof(float));

  // Without such a face the copy welds back as before.
  BuildResult plain = build_and_check(soup);
  ExtractReport none;
  EXPECT_EQ(extract(plain.mesh, {}, &none).corners, soup.corners);
  EXPECT_EQ(none.copies_kept_apart, 0u);
}

TEST(Build, ExtractCountsDefectsNotOnlyWhereTheyAre) {
  // Edge 2-3 is non-manifold and two triangles on it are doubled; the quad visits 3 twice.
  // build() makes the doubles pillows, and the quad's second 3 is the copy one pillow uses:
  // that pillow's edge to 2 is then a pinch (two mesh edges 2-3'), which no weld undoes.
  // A fan in the quad gives the full weld two new duplicate pairs; keeping the copy apart
  // for them moves the pinch onto a new key pair while the input's edge 2-3 comes back on
  // three faces. Compared by key, each looks allowed, but the output would have two
  // non-manifold edges where the input had one: by count, 2-3 must stay apart too.
  const Soup soup = make_soup(5, {{2, 3, 1, 3}, {3, 2, 3}, {2, 3, 3}, {3, 2, 0}, {3, 2, 4}, {4, 2, 3}, {2, 3, 0}});
  BuildResult r = build_and_check(soup);
  Face quad;
  for (Face f : r.mesh.faces())
    if (r.mesh.valence(f) == 4) quad = f;
  ASSERT_TRUE(quad.is_valid());
  r.mesh.split_face(quad, r.mesh.add_vertex(Point{{0, 0, 1}}));
  ASSERT_VALID(r.mesh);

  ExtractReport report;
  const Soup out = extract(r.mesh, {.input = &soup}, &report);
  const test::DefectCounts before = test::count_defects(soup), after = test::count_defects(out);
  for (int k = 0; k < 4; ++k) EXPECT_LE(after.at(k), before.at(k)) << test::DefectCounts::kNames[k];
  EXPECT_GT(report.copies_kept_apart, 0u);
}

TEST(Build, TwoConesTouchingAtTheirApex) {
  // Two closed fans around vertex 0 (an hourglass): each becomes its own closed vertex.
  BuildResult r = build_and_check(make_soup(7, {{0, 1, 2}, {0, 2, 3}, {0, 3, 1}, {0, 4, 5}, {0, 5, 6}, {0, 6, 4}}));
  EXPECT_EQ(counts(r.report), (Counts{.non_manifold_vertices = 1, .vertex_copies = 1}));
  EXPECT_EQ(boundary_loops(r.mesh), (std::vector<std::size_t>{3, 3}));
}

// ---- orientation -------------------------------------------------------------------------

TEST(Build, InconsistentNeighboursAreFlipped) {
  BuildResult r = build_and_check(make_soup(4, {{0, 1, 2}, {0, 1, 3}}));
  // A tie: the lowest face keeps its orientation.
  EXPECT_EQ(counts(r.report), Counts{.flipped_faces = 1});
  auto flipped = r.mesh.get_face_property<bool>(provenance::kFlipped);
  ASSERT_TRUE(flipped);
  EXPECT_FALSE(flipped[Face(0)]);
  EXPECT_TRUE(flipped[Face(1)]);
  // Flipped face keeps corner 0 and reverses the rest.
  std::vector<Index> corners;
  for (Vertex v : r.mesh.vertices(Face(1))) corners.push_back(v.idx());
  EXPECT_EQ(corners, (std::vector<Index>{0, 3, 1}));
  EXPECT_EQ(boundary_loops(r.mesh), std::vector<std::size_t>{4});
  EXPECT_FALSE(r.mesh.get_vertex_property<std::uint32_t>(provenance::kVertexSource));
}

TEST(Build, TheMinorityIsFlipped) {
  // A 3x3 grid whose faces 0, 4 and 8 are reversed: those three are flipped back.
  Soup soup = grid(3, 3);
  for (std::uint32_t f : {0u, 4u, 8u}) std::reverse(soup.corners.begin() + 4 * f, soup.corners.begin() + 4 * f + 4);
  BuildResult r = build_and_check(soup);
  EXPECT_EQ(counts(r.report), Counts{.flipped_faces = 3});
  EXPECT_EQ(boundary_loops(r.mesh), std::vector<std::size_t>{12});
  auto flipped = r.mesh.get_face_property<bool>(provenance::kFlipped);
  ASSERT_TRUE(flipped);
  for (std::uint32_t f = 0; f < 9; ++f) EXPECT_EQ(flipped[Face(f)], f % 4 == 0) << f;

  // Reversing all but one: the one is flipped, even though it is face 0.
  Soup most = grid(3, 3);
  for (std::uint32_t f = 1; f < 9; ++f) std::reverse(most.corners.begin() + 4 * f, most.corners.begin() + 4 * f + 4);
  EXPECT_EQ(counts(build_and_check(most).report), Counts{.flipped_faces = 1});
}

TEST(Build, OrientationCanBeSwitchedOff) {
  BuildResult r = build_and_check(make_soup(4, {{0, 1, 2}, {0, 1, 3}}), BuildOptions{.orient = false});
  EXPECT_EQ(counts(r.report), (Counts{.non_manifold_edges = 1, .non_manifold_vertices = 2, .vertex_copies = 2}));
  EXPECT_FALSE(r.mesh.get_face_property<bool>(provenance::kFlipped));
}

Soup moebius_strip(std::uint32_t n) {
  // Top vertices t_i = i, bottom b_i = n + i; quads [t_i, b_i, b_i+1, t_i+1], the last one twisted.
  Soup soup = soup_with_vertices(2 * n);
  for (std::uint32_t i = 0; i + 1 < n; ++i) soup.add_face({i, n + i, n + i + 1, i + 1});
  soup.add_face({n - 1, 2 * n - 1, 0, n});
  return soup;
}

TEST(Build, MoebiusStripIsCutOnce) {
  BuildResult r = build_and_check(moebius_strip(5));
  // BFS from face 0 reaches faces 4 and 3 through the twist (flipped: the minority) and
  // meets the unflipped side between faces 2 and 3, where the edge is cut; the cut rung's
  // two end vertices now each hold two boundary fans, so they are split too.
  EXPECT_EQ(counts(r.report),
            (Counts{.non_manifold_vertices = 2, .vertex_copies = 2, .flipped_faces = 2, .unorientable_edges = 1}));
  EXPECT_EQ(boundary_loops(r.mesh).size(), 1u);
  EXPECT_EQ(euler_characteristic(r.mesh), 1);  // a disk
}

TEST(Build, DuplicateFaceMakesAPillow) {
  BuildResult r = build_and_check(make_soup(3, {{0, 1, 2}, {0, 1, 2}}));
  EXPECT_EQ(counts(r.report), Counts{.flipped_faces = 1});
  EXPECT_EQ(count_boundary_halfedges(r.mesh), 0u);
  EXPECT_EQ(euler_characteristic(r.mesh), 2);
}

TEST(Build, ReversedDuplicateNeedsNoFlip) {
  BuildResult r = build_and_check(make_soup(3, {{0, 1, 2}, {2, 1, 0}}));
  EXPECT_EQ(counts(r.report), Counts{});
  EXPECT_EQ(count_boundary_halfedges(r.mesh), 0u);
}

TEST(Build, TriplicateFaceFallsApart) {
  // Every edge has three same-direction sides: nothing can glue, each face stands alone.
  BuildResult r = build_and_check(make_soup(3, {{0, 1, 2}, {0, 1, 2}, {0, 1, 2}}));
  EXPECT_EQ(counts(r.report), (Counts{.non_manifold_edges = 3, .non_manifold_vertices = 3, .vertex_copies = 6}));
  EXPECT_EQ(boundary_loops(r.mesh), (std::vector<std::size_t>{3, 3, 3}));
}

// ---- degenerate faces ----------------------------------------------------------------------

TEST(Build, ConsecutiveRepeatedVertex) {
  BuildResult r = build_and_check(make_soup(3, {{0, 0, 1, 2}}));
  EXPECT_EQ(counts(r.report), (Counts{.non_manifold_vertices = 1, .vertex_copies = 1, .repeated_vertex_faces = 1}));
  EXPECT_EQ(r.mesh.valence(Face(0)), 4u);
}

TEST(Build, NonConsecutiveRepeatedVertex) {
  BuildResult r = build_and_check(make_soup(3, {{0, 1, 0, 2}}));
  EXPECT_EQ(counts(r.report), (Counts{.non_manifold_vertices = 1, .vertex_copies = 1, .repeated_vertex_faces = 1}));
}

TEST(Build, RepeatedVertexWhoseFanClosesIsCut) {
  // Around vertex 0 the faces [0,0,1,2], [1,0,3], [3,0,2] form one fan from the quad's
  // second corner back to its first: the fan is cut before the quad comes up again (edge
  // 0-2), which also separates the two corners of vertex 2.
  BuildResult r = build_and_check(make_soup(4, {{0, 0, 1, 2}, {1, 0, 3}, {3, 0, 2}}));
  EXPECT_EQ(counts(r.report), (Counts{.non_manifold_vertices = 2, .vertex_copies = 2, .repeated_vertex_faces = 1}));
}

TEST(Build, DegenerateFacesAreSkippedAndReported) {
  Soup soup = make_soup(5, {{0, 1, 2}, {}, {3}, {3, 4}, {0, 0, 1}, {2, 2, 2}, {1, 3, 1, 3}, {2, 1, 3}});
  BuildResult r = build_and_check(soup);
  EXPECT_EQ(r.maps.skipped_faces, (std::vector<std::uint32_t>{1, 2, 3, 4, 5, 6}));
  EXPECT_EQ(counts(r.report), (Counts{.skipped_faces = 6, .isolated_vertices = 1}));
  EXPECT_EQ(r.maps.face_source, (std::vector<std::uint32_t>{0, 7}));
  auto source = r.mesh.get_face_property<std::uint32_t>(provenance::kFaceSource);
  ASSERT_TRUE(source);
  EXPECT_EQ(source[Face(1)], 7u);
  ASSERT_FALSE(r.report.messages.empty());
  EXPECT_NE(r.report.messages[0].find("skipped 6 faces"), std::string::npos) << r.report.messages[0];
}

// ---- errors ----------------------------------------------------------------------------------

std::string error_of(const Soup& soup) {
  try {
    build(soup);
  } catch (const Error& e) {
    return e.what();
  }
  return "no error";
}

TEST(Build, RejectsIndexOutOfRange) {
  const std::string message = error_of(make_soup(3, {{0, 1, 2}, {0, 1, 7}}));
  EXPECT_NE(message.find("face 1"), std::string::npos) << message;
  EXPECT_NE(message.find("vertex 7"), std::string::npos) << message;
}

TEST(Build, RejectsNonFiniteCoordinates) {
  Soup soup = make_soup(3, {{0, 1, 2}});
  soup.positions[1][2] = std::numeric_limits<float>::quiet_NaN();
  std::string message = error_of(soup);
  EXPECT_NE(message.find("vertex 1"), std::string::npos) << message;
  EXPECT_NE(message.find("NaN"), std::string::npos) << message;
  soup.positions[1][2] = 0;
  soup.positions[2][0] = -std::numeric_limits<float>::infinity();
  message = error_of(soup);
  EXPECT_NE(message.find("vertex 2"), std::string::npos) << message;
  EXPECT_NE(message.find("infinite"), std::string::npos) << message;
}

TEST(Build, RejectsSizesThatDoNotAddUp) {
  Soup soup = make_soup(4, {{0, 1, 2}});
  soup.corners.push_back(3);
  const std::string message = error_of(soup);
  EXPECT_NE(message.find("3 corners"), std::string::npos) << message;
  EXPECT_NE(message.find("4"), std::string::npos) << message;
}

TEST(Build, RejectsChannelsOfTheWrongLength) {
  Soup soup = make_soup(3, {{0, 1, 2}});
  soup.add_channel("uv", Domain::corner, ScalarType::f32, 2).data.resize(8);
  const std::string message = error_of(soup);
  EXPECT_NE(message.find("uv"), std::string::npos) << message;
}

TEST(Build, RejectsReservedChannelNames) {
  Soup soup = make_soup(3, {{0, 1, 2}});
  soup.add_channel(provenance::kVertexSource, Domain::vertex, ScalarType::u32, 1);
  EXPECT_NE(error_of(soup).find("reserved"), std::string::npos);
}

// ---- attributes ------------------------------------------------------------------------------

// Fills every channel with distinct bytes so a misplaced element shows.
void add_all_channels(Soup& soup, std::uint32_t seed) {
  soup.add_channel("normal", Domain::vertex, ScalarType::f32, 3);
  soup.add_channel("quality", Domain::vertex, ScalarType::f64, 1);
  soup.add_channel("material", Domain::face, ScalarType::i32, 1);
  soup.add_channel("color", Domain::face, ScalarType::u8, 4);
  soup.add_channel("uv", Domain::corner, ScalarType::f32, 2);
  soup.add_channel("color", Domain::corner, ScalarType::u8, 4);
  std::mt19937 rng(seed);
  for (Channel& c : soup.channels)
    for (std::byte& b : c.data) b = std::byte(rng() & 0xff);
}

TEST(Build, ChannelsOfAllDomainsRoundTrip) {
  // Flips, a non-manifold edge, a bowtie, a repeated vertex and a skipped face at once.
  Soup soup = make_soup(9, {{0, 1, 2}, {0, 1, 3}, {1, 0, 4}, {0, 5, 6}, {6, 6, 7, 8}, {7, 8, 7}});
  add_all_channels(soup, 7);
  BuildResult r = build_and_check(soup);
  EXPECT_TRUE(r.report.repaired());
  EXPECT_EQ(r.mesh.vertex_properties().get_channel("normal")->size(), r.mesh.vertices_size());
  EXPECT_EQ(r.mesh.halfedge_properties().get_channel("uv")->size(), r.mesh.halfedges_size());

  // Corner data sits on the half-edge pointing to the corner; boundary halves hold zeros.
  const ChannelArray* uv = r.mesh.halfedge_properties().get_channel("uv");
  const Channel* soup_uv = soup.find("uv", Domain::corner);
  EXPECT_EQ(std::memcmp(uv->element(r.mesh.halfedge(Face(0)).idx()), soup_uv->data.data(), uv->stride()), 0);
  for (Halfedge h : r.mesh.halfedges()) {
    if (!r.mesh.is_boundary(h)) continue;
    for (std::size_t k = 0; k < uv->stride(); ++k) EXPECT_EQ(uv->element(h.idx())[k], std::byte{0});
  }
  // Vertex copies carry their source's data.
  const ChannelArray* normal = r.mesh.vertex_properties().get_channel("normal");
  for (std::size_t v = soup.n_vertices(); v < r.mesh.vertices_size(); ++v)
    EXPECT_EQ(std::memcmp(normal->element(v), normal->element(r.maps.vertex_source[v]), normal->stride()), 0);
}

TEST(Build, ChannelsOfACleanMeshRoundTrip) {
  Soup soup = grid(4, 4);
  add_all_channels(soup, 11);
  BuildResult r = build_and_check(soup);
  EXPECT_EQ(counts(r.report), Counts{});
  EXPECT_EQ(n_properties(r.mesh), soup.channels.size());  // no provenance
}

TEST(Build, ExtractGroupsChannelsByDomain) {
  // A soup listing a corner channel before a vertex channel gets them back vertex first;
  // each channel is unchanged.
  Soup soup = grid(2, 2);
  soup.add_channel("uv", Domain::corner, ScalarType::f32, 2).data[5] = std::byte{9};
  soup.add_channel("quality", Domain::vertex, ScalarType::f32, 1).data[3] = std::byte{7};
  const Soup out = extract(build(soup).mesh);
  ASSERT_EQ(out.channels.size(), 2u);
  EXPECT_EQ(out.channels[0], soup.channels[1]);
  EXPECT_EQ(out.channels[1], soup.channels[0]);
}

TEST(Build, ExtractWithoutRestoringKeepsTheCopies) {
  Soup soup = make_soup(5, {{0, 1, 2}, {0, 3, 4}, {0, 1, 3}});
  BuildResult r = build(soup);
  const Soup raw = extract(r.mesh, ExtractOptions{.restore_source = false});
  EXPECT_EQ(raw.n_vertices(), r.mesh.n_vertices());
  EXPECT_EQ(raw.n_faces(), soup.n_faces());
  // And that soup builds cleanly: the repairs are in its topology now.
  BuildResult again = build_and_check(raw);
  EXPECT_FALSE(again.report.repaired());
}

TEST(Build, ExtractSkipsDeletedElements) {
  BuildResult r = build(grid(2, 1));
  r.mesh.delete_face(Face(0));
  const Soup out = extract(r.mesh);
  EXPECT_EQ(out.n_faces(), 1u);
  EXPECT_EQ(out.n_vertices(), 4u);
  for (std::uint32_t v : out.corners) EXPECT_LT(v, 4u);
  EXPECT_TRUE(validate(build(out).mesh));
}

// ---- determinism and randomized soups --------------------------------------------------------

// Every connectivity array and property of a mesh, to compare two builds.
auto signature(const Mesh& m) {
  std::vector<std::tuple<Index, Index, Index, Index>> halfedges;
  for (Halfedge h : m.halfedges())
    halfedges.emplace_back(m.to_vertex(h).idx(), m.face(h).idx(), m.next(h).idx(), m.prev(h).idx());
  std::vector<Index> vertices, faces;
  for (Vertex v : m.vertices()) vertices.push_back(m.halfedge(v).idx());
  for (Face f : m.faces()) faces.push_back(m.halfedge(f).idx());
  return std::make_tuple(halfedges, vertices, faces, m.positions(),
                         extract(m, ExtractOptions{.restore_source = false}));
}

Soup random_soup(std::mt19937& rng, bool with_channels) {
  const std::uint32_t nv = 3 + rng() % 8;
  const std::uint32_t nf = 1 + rng() % 24;
  Soup soup = soup_with_vertices(nv);
  std::vector<std::uint32_t> face;
  for (std::uint32_t f = 0; f < nf; ++f) {
    face.clear();
    const std::uint32_t size = 3 + rng() % 4;
    for (std::uint32_t k = 0; k < size; ++k) face.push_back(rng() % nv);
    soup.add_face(face);
  }
  if (with_channels) add_all_channels(soup, rng());
  return soup;
}

TEST(Build, Deterministic) {
  std::mt19937 rng(5);
  for (int i = 0; i < 50; ++i) {
    Soup soup = random_soup(rng, true);
    EXPECT_EQ(signature(build(soup).mesh), signature(build(soup).mesh));
  }
  Soup big = grid(400, 300);
  EXPECT_EQ(signature(build(big).mesh), signature(build(big).mesh));
}

// The local path decides non-manifold edges and vertices per vertex; the general path
// (taken when a face is skipped) by sorting all edges. Both must build the same mesh.
void expect_same_as_general_path(const Soup& soup) {
  Soup forced = soup;
  forced.add_face({0, 0, 0});  // skipped: forces the general path, changes nothing else
  const BuildResult local = build(soup), general = build(forced);
  EXPECT_EQ(std::get<0>(signature(local.mesh)), std::get<0>(signature(general.mesh)));
  EXPECT_EQ(std::get<1>(signature(local.mesh)), std::get<1>(signature(general.mesh)));
  EXPECT_EQ(std::get<2>(signature(local.mesh)), std::get<2>(signature(general.mesh)));
  BuildReport expected = general.report;
  expected.skipped_faces = 0;
  EXPECT_EQ(counts(local.report), counts(expected));
}

TEST(Build, LocalAndGeneralPathsAgree) {
  std::mt19937 rng(77);
  int compared = 0;
  for (int i = 0; i < 20000 && compared < 300; ++i) {
    Soup soup = random_soup(rng, false);
    const BuildResult r = build(soup);
    // Only soups the local path takes: nothing skipped, repeated or flipped.
    if (r.report.skipped_faces || r.report.repeated_vertex_faces || r.report.flipped_faces ||
        r.report.unorientable_edges)
      continue;
    SCOPED_TRACE("iteration " + std::to_string(i));
    expect_same_as_general_path(soup);
    ++compared;
    if (HasFailure()) break;
  }
  EXPECT_GT(compared, 50);
  expect_same_as_general_path(make_soup(6, {{0, 1, 2}, {1, 0, 3}, {0, 1, 4}, {1, 0, 5}}));
}

TEST(Build, RandomSoupsAlwaysValidateAndRoundTrip) {
  std::mt19937 rng(20240611);
  std::size_t repaired = 0;
  for (int i = 0; i < 3000; ++i) {
    SCOPED_TRACE("iteration " + std::to_string(i));
    Soup soup = random_soup(rng, i % 4 == 0);
    BuildResult r = build_and_check(soup, BuildOptions{.orient = i % 5 != 0});
    repaired += r.report.repaired();
    if (HasFailure()) break;
  }
  EXPECT_GT(repaired, 2000u);  // the generator does produce pathological soups
}

TEST(Build, RandomSurfacesWithFewDefects) {
  // Larger soups: a grid of triangles with a few faces reversed, duplicated or rewired.
  std::mt19937 rng(99);
  for (int i = 0; i < 40; ++i) {
    SCOPED_TRACE("iteration " + std::to_string(i));
    Soup soup = grid(12, 9);
    std::vector<std::vector<std::uint32_t>> faces;
    for (std::size_t f = 0; f < soup.n_faces(); ++f) {
      const std::uint32_t* q = soup.corners.data() + 4 * f;
      faces.push_back({q[0], q[1], q[2]});
      faces.push_back({q[0], q[2], q[3]});
    }
    for (int k = 0; k < 6; ++k) {
      auto& f = faces[rng() % faces.size()];
      switch (rng() % 3) {
        case 0:
          std::reverse(f.begin(), f.end());
          break;
        case 1:
          faces.push_back(f);
          break;
        case 2:
          f[rng() % 3] = rng() % soup.n_vertices();
          break;
      }
    }
    Soup tri;
    tri.positions = soup.positions;
    for (auto& f : faces) tri.add_face(f);
    build_and_check(tri);
    if (HasFailure()) break;
  }
}

// ---- real meshes -----------------------------------------------------------------------------

Soup read_or_skip(const std::string& name, bool& present) {
  const std::string path = std::string(HEDGE_MESH_DIR) + "/" + name;
  present = std::filesystem::exists(path);
  return present ? read_mesh(path) : Soup{};
}

class BuildRealMesh : public ::testing::TestWithParam<const char*> {};

TEST_P(BuildRealMesh, BuildsValidatesAndRoundTrips) {
  bool present = false;
  const auto t0 = std::chrono::steady_clock::now();
  Soup soup = read_or_skip(GetParam(), present);
  if (!present) GTEST_SKIP() << GetParam() << " not found in " << HEDGE_MESH_DIR;
  const auto t1 = std::chrono::steady_clock::now();
  BuildResult r = build(soup);
  const auto t2 = std::chrono::steady_clock::now();
  const Validation v = validate(r.mesh);
  EXPECT_TRUE(v) << v.message;
  EXPECT_EQ(r.mesh.n_faces(), soup.n_faces() - r.report.skipped_faces);
  const auto t3 = std::chrono::steady_clock::now();
  const Soup back = extract(r.mesh);
  const auto t4 = std::chrono::steady_clock::now();
  EXPECT_EQ(back, without_faces(soup, r.maps.skipped_faces));
  if (soup.n_faces() < 300000) expect_same_as_general_path(soup);
  auto ms = [](auto a, auto b) { return std::chrono::duration<double, std::milli>(b - a).count(); };
  std::cout << "[ timing ] " << GetParam() << ": " << soup.n_vertices() << " vertices, " << soup.n_faces()
            << " faces; read " << ms(t0, t1) << " ms, build " << ms(t1, t2) << " ms, extract " << ms(t3, t4)
            << " ms\n[ report ] " << counts(r.report) << "\n"
            << messages(r.report);
  if (std::string(GetParam()) == "dragon_res4.ply") {
    EXPECT_GT(r.report.non_manifold_edges, 0u);
  }
  if (!r.report.repaired()) {
    EXPECT_EQ(n_properties(r.mesh), 0u);
  }
}

INSTANTIATE_TEST_SUITE_P(Build, BuildRealMesh,
                         ::testing::Values("bunny.off", "dragon_res4.ply", "dragon_res3.ply", "dragon_res2.ply",
                                           "dragon.ply"),
                         [](const auto& info) {
                           std::string name = info.param;
                           return name.substr(0, name.find('.'));
                         });

TEST(BuildTiming, Dragon) {
  // Not an assertion: prints the best of a few builds of the full dragon.
  bool present = false;
  Soup soup = read_or_skip("dragon.ply", present);
  if (!present) GTEST_SKIP() << "dragon.ply not found in " << HEDGE_MESH_DIR;
  double best = 1e30;
  for (int i = 0; i < 5; ++i) {
    const auto t0 = std::chrono::steady_clock::now();
    BuildResult r = build(soup);
    const auto t1 = std::chrono::steady_clock::now();
    best = std::min(best, std::chrono::duration<double, std::milli>(t1 - t0).count());
  }
  std::cout << "[ timing ] dragon build, best of 5: " << best << " ms\n";
}

}  // namespace
}  // namespace hedge
