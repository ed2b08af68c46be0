// The worked examples of the project's references reproduced exactly: Yin & Goh's records
// tables (7-vertex mesh, two-triangle edge flip) and the circulator orders of McGuire,
// Yin & Goh and OpenMesh (references/000, 003, 004).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "hedge/mesh.h"
#include "hedge/validate.h"

namespace hedge {
namespace {

constexpr int kNone = -1;  // "∅" in the tables

// One row of a records table: half-edge e_k's origin (1-based, as v1..v7 in the paper),
// twin, incident face, next and prev (indices of other rows).
struct Row {
  int origin, twin, face, next, prev;
};

struct Table {
  std::vector<Row> halfedges;
  std::vector<int> face_halfedge;    // f_j -> e_k
  std::vector<int> vertex_halfedge;  // v_i (index i-1) -> e_k
};

// ---- Yin & Goh, the 7-vertex mesh --------------------------------------------------------

const std::vector<Point> kSevenPositions = {Point{{1, 4, 0}}, Point{{3, 4, 0}}, Point{{0, 2, 0}}, Point{{2, 2, 0}},
                                            Point{{4, 2, 0}}, Point{{1, 0, 0}}, Point{{3, 0, 0}}};
const std::vector<std::vector<int>> kSevenFaces = {{1, 3, 4}, {1, 4, 2}, {2, 4, 5}, {3, 6, 4}, {4, 6, 7}, {4, 7, 5}};

const Table kSevenTable = {
    {
        {1, 18, 0, 1, 2},         // e0
        {3, 11, 0, 2, 0},         // e1
        {4, 3, 0, 0, 1},          // e2
        {1, 2, 1, 4, 5},          // e3
        {4, 6, 1, 5, 3},          // e4
        {2, 19, 1, 3, 4},         // e5
        {2, 4, 2, 7, 8},          // e6
        {4, 17, 2, 8, 6},         // e7
        {5, 20, 2, 6, 7},         // e8
        {3, 21, 3, 10, 11},       // e9
        {6, 12, 3, 11, 9},        // e10
        {4, 1, 3, 9, 10},         // e11
        {4, 10, 4, 13, 14},       // e12
        {6, 22, 4, 14, 12},       // e13
        {7, 15, 4, 12, 13},       // e14
        {4, 14, 5, 16, 17},       // e15
        {7, 23, 5, 17, 15},       // e16
        {5, 7, 5, 15, 16},        // e17
        {3, 0, kNone, 19, 21},    // e18
        {1, 5, kNone, 20, 18},    // e19
        {2, 8, kNone, 23, 19},    // e20
        {6, 9, kNone, 18, 22},    // e21
        {7, 13, kNone, 21, 23},   // e22
        {5, 16, kNone, 22, 20},   // e23
    },
    {0, 3, 6, 9, 12, 15},
    {0, 5, 1, 2, 8, 10, 14},
};

// ---- Yin & Goh, the edge flip walk-through -------------------------------------------------

const std::vector<Point> kFlipPositions = {Point{{0, 1, 0}}, Point{{1, 1, 0}}, Point{{0, 0, 0}}, Point{{1, 0, 0}}};
const std::vector<std::vector<int>> kFlipFaces = {{1, 3, 4}, {1, 4, 2}};

const Table kFlipBefore = {
    {
        {1, 6, 0, 1, 2},        // e0
        {3, 7, 0, 2, 0},        // e1
        {4, 3, 0, 0, 1},        // e2
        {1, 2, 1, 4, 5},        // e3
        {4, 8, 1, 5, 3},        // e4
        {2, 9, 1, 3, 4},        // e5
        {3, 0, kNone, 9, 7},    // e6
        {4, 1, kNone, 6, 8},    // e7
        {2, 4, kNone, 7, 9},    // e8
        {1, 5, kNone, 8, 6},    // e9
    },
    {0, 3},
    {0, 5, 1, 2},
};

// The last table of the walk-through. The text stops after relinking next and prev; its
// face column still shows e0 in f0 and e4 in f1, but the loops it has built are
// e3 -> e5 -> e0 (f1, the face of e) and e2 -> e1 -> e4 (f0, the face of twin), so the
// walk-through's final step sets e0.face = f1 and e4.face = f0. That is the table below.
const Table kFlipAfter = {
    {
        {1, 6, 1, 3, 5},        // e0 (face completed: f1)
        {3, 7, 0, 4, 2},        // e1
        {2, 3, 0, 1, 4},        // e2
        {3, 2, 1, 5, 0},        // e3
        {4, 8, 0, 2, 1},        // e4 (face completed: f0)
        {2, 9, 1, 0, 3},        // e5
        {3, 0, kNone, 9, 7},    // e6
        {4, 1, kNone, 6, 8},    // e7
        {2, 4, kNone, 7, 9},    // e8
        {1, 5, kNone, 8, 6},    // e9
    },
    {1, 5},
    {0, 5, 1, 4},
};

Vertex vertex_of(int paper_index) { return Vertex(static_cast<Index>(paper_index - 1)); }

Mesh build(const std::vector<Point>& positions, const std::vector<std::vector<int>>& faces) {
  Mesh m;
  for (const Point& p : positions) m.add_vertex(p);
  for (const auto& f : faces) {
    std::vector<Vertex> v;
    for (int i : f) v.push_back(vertex_of(i));
    m.add_face(std::span<const Vertex>(v));
  }
  return m;
}

int destination(const Table& t, int k) { return t.halfedges[t.halfedges[k].next].origin; }

// The rows must describe a half-edge structure themselves, or a transcription slipped.
::testing::AssertionResult table_is_consistent(const Table& t) {
  const int n = static_cast<int>(t.halfedges.size());
  for (int k = 0; k < n; ++k) {
    const Row& r = t.halfedges[k];
    if (t.halfedges[r.twin].twin != k) return ::testing::AssertionFailure() << "e" << k << ": twin of twin";
    if (t.halfedges[r.next].prev != k) return ::testing::AssertionFailure() << "e" << k << ": prev of next";
    if (t.halfedges[r.twin].origin != destination(t, k))
      return ::testing::AssertionFailure() << "e" << k << ": twin does not start at the destination";
    if (t.halfedges[r.next].face != r.face) return ::testing::AssertionFailure() << "e" << k << ": next in another face";
  }
  for (std::size_t j = 0; j < t.face_halfedge.size(); ++j)
    if (t.halfedges[t.face_halfedge[j]].face != static_cast<int>(j))
      return ::testing::AssertionFailure() << "f" << j << ": its half-edge lies in another face";
  for (std::size_t i = 0; i < t.vertex_halfedge.size(); ++i)
    if (t.halfedges[t.vertex_halfedge[i]].origin != static_cast<int>(i) + 1)
      return ::testing::AssertionFailure() << "v" << i + 1 << ": its half-edge does not start there";
  return ::testing::AssertionSuccess();
}

// Our half-edge ids differ from the paper's (twins are h^1), so e_k is matched to our
// half-edge from its origin to its destination, and that map must be a bijection that
// carries origin, twin, face, next and prev of every row onto ours. Faces must map f_j to
// face j (the order they were added in).
::testing::AssertionResult matches(const Mesh& m, const Table& t, std::vector<Halfedge>& map) {
  const int n = static_cast<int>(t.halfedges.size());
  if (m.n_halfedges() != static_cast<std::size_t>(n))
    return ::testing::AssertionFailure() << m.n_halfedges() << " half-edges, the table has " << n;
  map.assign(n, Halfedge());
  for (int k = 0; k < n; ++k) {
    map[k] = m.find_halfedge(vertex_of(t.halfedges[k].origin), vertex_of(destination(t, k)));
    if (!map[k].is_valid())
      return ::testing::AssertionFailure() << "e" << k << ": no half-edge v" << t.halfedges[k].origin << " -> v"
                                           << destination(t, k);
  }
  std::vector<Halfedge> sorted = map;
  std::sort(sorted.begin(), sorted.end());
  if (std::adjacent_find(sorted.begin(), sorted.end()) != sorted.end())
    return ::testing::AssertionFailure() << "two rows map to the same half-edge";
  for (int k = 0; k < n; ++k) {
    const Row& r = t.halfedges[k];
    const Halfedge h = map[k];
    if (m.from_vertex(h) != vertex_of(r.origin)) return ::testing::AssertionFailure() << "e" << k << ": origin";
    if (Mesh::opposite(h) != map[r.twin]) return ::testing::AssertionFailure() << "e" << k << ": twin";
    if (m.next(h) != map[r.next]) return ::testing::AssertionFailure() << "e" << k << ": next";
    if (m.prev(h) != map[r.prev]) return ::testing::AssertionFailure() << "e" << k << ": prev";
    const Face want = r.face == kNone ? Face() : Face(static_cast<Index>(r.face));
    if (m.face(h) != want)
      return ::testing::AssertionFailure() << "e" << k << ": face " << (m.face(h).is_valid() ? int(m.face(h).idx()) : -1)
                                           << ", the table says " << r.face;
  }
  // A face's half-edge: the paper's leaves corner 0, ours points to it, so ours is the
  // prev of theirs.
  for (std::size_t j = 0; j < t.face_halfedge.size(); ++j) {
    const Face f(static_cast<Index>(j));
    if (m.halfedge(f) != map[t.halfedges[t.face_halfedge[j]].prev])
      return ::testing::AssertionFailure() << "f" << j << ": halfedge(f) does not point to the table's corner 0";
  }
  // A vertex's half-edge: any outgoing one in the paper; ours must be the boundary one on
  // the boundary (OpenMesh's rule, reference 004), which the paper's choice is not always.
  for (std::size_t i = 0; i < t.vertex_halfedge.size(); ++i) {
    const Vertex v(static_cast<Index>(i));
    const Halfedge h = m.halfedge(v);
    if (m.from_vertex(h) != v) return ::testing::AssertionFailure() << "v" << i + 1 << ": halfedge(v) does not leave v";
    bool on_boundary = false;
    for (const Row& r : t.halfedges) on_boundary = on_boundary || (r.origin == int(i) + 1 && r.face == kNone);
    if (on_boundary != m.is_boundary(h))
      return ::testing::AssertionFailure() << "v" << i + 1 << ": halfedge(v) is not the boundary half-edge";
  }
  return ::testing::AssertionSuccess();
}

TEST(Reference, TablesAreConsistent) {
  EXPECT_TRUE(table_is_consistent(kSevenTable));
  EXPECT_TRUE(table_is_consistent(kFlipBefore));
  EXPECT_TRUE(table_is_consistent(kFlipAfter));
}

TEST(Reference, TheExtractedLastFlipTableNeedsItsFaceStep) {
  // As printed (before the face step) the table is not a half-edge structure yet ...
  Table printed = kFlipAfter;
  printed.halfedges[0].face = 0;
  printed.halfedges[4].face = 1;
  EXPECT_FALSE(table_is_consistent(printed));
  // ... and the comparison notices a single wrong cell.
  Mesh m = build(kFlipPositions, kFlipFaces);
  std::vector<Halfedge> map;
  Table wrong = kFlipBefore;
  wrong.halfedges[6].prev = 9;
  EXPECT_FALSE(matches(m, wrong, map));
  wrong = kFlipBefore;
  wrong.face_halfedge = {1, 3};
  EXPECT_FALSE(matches(m, wrong, map));
}

TEST(Reference, SevenVertexMeshRecordsTable) {
  Mesh m = build(kSevenPositions, kSevenFaces);
  ASSERT_TRUE(validate(m)) << validate(m).message;
  EXPECT_EQ(m.n_vertices(), 7u);
  EXPECT_EQ(m.n_halfedges(), 24u);
  EXPECT_EQ(m.n_faces(), 6u);
  std::vector<Halfedge> map;
  ASSERT_TRUE(matches(m, kSevenTable, map));

  // 18 interior and 6 boundary half-edges, the boundary ones being e18..e23.
  std::size_t boundary = 0;
  for (Halfedge h : m.halfedges()) boundary += m.is_boundary(h);
  EXPECT_EQ(boundary, 6u);
  for (int k = 18; k < 24; ++k) EXPECT_TRUE(m.is_boundary(map[k]));

  // Faces list their corners in the order they were given.
  for (std::size_t j = 0; j < kSevenFaces.size(); ++j) {
    std::vector<Vertex> want, got;
    for (int i : kSevenFaces[j]) want.push_back(vertex_of(i));
    for (Vertex v : m.vertices(Face(static_cast<Index>(j)))) got.push_back(v);
    EXPECT_EQ(got, want) << "f" << j;
  }
  // The boundary loop: e18 -> e19 -> e20 -> e23 -> e22 -> e21.
  std::vector<Halfedge> loop;
  for (Halfedge h : m.loop(map[18])) loop.push_back(h);
  EXPECT_EQ(loop, (std::vector<Halfedge>{map[18], map[19], map[20], map[23], map[22], map[21]}));
  // v4 is the only interior vertex.
  for (int i = 1; i <= 7; ++i) EXPECT_EQ(m.is_boundary(vertex_of(i)), i != 4) << "v" << i;
}

TEST(Reference, EdgeFlipWalkThrough) {
  Mesh m = build(kFlipPositions, kFlipFaces);
  ASSERT_TRUE(validate(m)) << validate(m).message;
  std::vector<Halfedge> before;
  ASSERT_TRUE(matches(m, kFlipBefore, before));

  // The input half-edge is e3 (v1 -> v4); its edge is flipped.
  const Edge e = Mesh::edge(before[3]);
  ASSERT_TRUE(m.is_flip_ok(e));
  m.flip(e);
  ASSERT_TRUE(validate(m)) << validate(m).message;
  std::vector<Halfedge> after;
  ASSERT_TRUE(matches(m, kFlipAfter, after));

  // The walk-through recycles e and twin: the same records, now the diagonal v3 - v2. All
  // other half-edges are the same records as before.
  EXPECT_EQ(Mesh::edge(after[3]), e);
  EXPECT_EQ(Mesh::edge(after[2]), e);
  for (int k : {0, 1, 4, 5, 6, 7, 8, 9}) EXPECT_EQ(after[k], before[k]) << "e" << k;
  EXPECT_EQ(m.n_edges(), 5u);
  EXPECT_FALSE(m.find_halfedge(vertex_of(1), vertex_of(4)).is_valid());
}

// ---- circulators (references 000, 003, 004) -------------------------------------------------

std::vector<Vertex> ring(const Mesh& m, Vertex v, bool ccw) {
  std::vector<Vertex> out;
  if (ccw)
    for (Vertex w : m.vertices(v)) out.push_back(w);
  else
    for (Vertex w : m.vertices_cw(v)) out.push_back(w);
  return out;
}

std::vector<Vertex> paper(std::initializer_list<int> ids) {
  std::vector<Vertex> out;
  for (int i : ids) out.push_back(vertex_of(i));
  return out;
}

template <class T>
std::vector<T> rotated_to(std::vector<T> seq, T first) {
  auto it = std::find(seq.begin(), seq.end(), first);
  if (it != seq.end()) std::rotate(seq.begin(), it, seq.end());
  return seq;
}

TEST(Reference, CirculatorsFollowThePapersLoops) {
  Mesh m = build(kSevenPositions, kSevenFaces);
  for (Vertex v : m.vertices()) {
    // Yin & Goh: counter-clockwise is he = he.prev.twin, clockwise he = he.twin.next.
    std::vector<Halfedge> ccw, cw, ours_ccw, ours_cw;
    Halfedge h = m.halfedge(v);
    do {
      ccw.push_back(h);
      h = Mesh::opposite(m.prev(h));
    } while (h != m.halfedge(v));
    do {
      cw.push_back(h);
      h = m.next(Mesh::opposite(h));  // McGuire's vertex loop: edge->pair->next
    } while (h != m.halfedge(v));
    for (Halfedge g : m.outgoing(v)) ours_ccw.push_back(g);
    for (Halfedge g : m.outgoing_cw(v)) ours_cw.push_back(g);
    EXPECT_EQ(ours_ccw, ccw);
    EXPECT_EQ(ours_cw, cw);
  }
  for (Face f : m.faces()) {
    // McGuire's face loop: edge = edge->next, and backwards with prev.
    std::vector<Halfedge> loop, back, ours, ours_back;
    Halfedge h = m.halfedge(f);
    do {
      loop.push_back(h);
      h = m.next(h);
    } while (h != m.halfedge(f));
    do {
      back.push_back(h);
      h = m.prev(h);
    } while (h != m.halfedge(f));
    for (Halfedge g : m.halfedges(f)) ours.push_back(g);
    for (Halfedge g : m.halfedges_reversed(f)) ours_back.push_back(g);
    EXPECT_EQ(ours, loop);
    EXPECT_EQ(ours_back, back);
  }
}

TEST(Reference, RingOrdersOfTheSevenVertexMesh) {
  Mesh m = build(kSevenPositions, kSevenFaces);
  // The interior v4 at (2, 2): its neighbours counter-clockwise as drawn, from v1.
  EXPECT_EQ(rotated_to(ring(m, vertex_of(4), true), vertex_of(1)), paper({1, 3, 6, 7, 5, 2}));
  EXPECT_EQ(rotated_to(ring(m, vertex_of(4), false), vertex_of(1)), paper({1, 2, 5, 7, 6, 3}));
  // Boundary vertices start at their outgoing boundary half-edge (OpenMesh), so their ring
  // begins across the hole: counter-clockwise through the hole first, clockwise through the
  // faces first.
  EXPECT_EQ(ring(m, vertex_of(1), true), paper({2, 3, 4}));
  EXPECT_EQ(ring(m, vertex_of(1), false), paper({2, 4, 3}));
  EXPECT_EQ(ring(m, vertex_of(2), true), paper({5, 1, 4}));
  EXPECT_EQ(ring(m, vertex_of(2), false), paper({5, 4, 1}));
  EXPECT_EQ(ring(m, vertex_of(3), true), paper({1, 6, 4}));
  EXPECT_EQ(ring(m, vertex_of(3), false), paper({1, 4, 6}));
  EXPECT_EQ(ring(m, vertex_of(5), true), paper({7, 2, 4}));
  EXPECT_EQ(ring(m, vertex_of(5), false), paper({7, 4, 2}));
  EXPECT_EQ(ring(m, vertex_of(6), true), paper({3, 7, 4}));
  EXPECT_EQ(ring(m, vertex_of(6), false), paper({3, 4, 7}));
  EXPECT_EQ(ring(m, vertex_of(7), true), paper({6, 5, 4}));
  EXPECT_EQ(ring(m, vertex_of(7), false), paper({6, 4, 5}));

  // Geometrically: every counter-clockwise ring turns exactly once, counter-clockwise.
  for (Vertex v : m.vertices()) {
    const Point c = m.position(v);
    std::vector<Vertex> r = ring(m, v, true);
    double turn = 0;
    for (std::size_t i = 0; i < r.size(); ++i) {
      const Point a = m.position(r[i]) - c, b = m.position(r[(i + 1) % r.size()]) - c;
      double step = std::atan2(double(b[1]), double(b[0])) - std::atan2(double(a[1]), double(a[0]));
      if (step <= 0) step += 2 * std::numbers::pi;
      turn += step;
    }
    EXPECT_NEAR(turn, 2 * std::numbers::pi, 1e-9) << "v" << v.idx() + 1;
  }

  // Faces around v4 counter-clockwise: f0 (between v1 and v3), f3, f4, f5, f2, f1.
  std::vector<Face> around;
  for (Face f : m.faces(vertex_of(4))) around.push_back(f);
  std::vector<Face> want;
  for (Index j : {0u, 3u, 4u, 5u, 2u, 1u}) want.push_back(Face(j));
  EXPECT_EQ(rotated_to(around, Face(0)), want);
  // Around a boundary vertex the hole is skipped.
  std::vector<Face> at_v1, at_v1_cw;
  for (Face f : m.faces(vertex_of(1))) at_v1.push_back(f);
  for (Face f : m.faces_cw(vertex_of(1))) at_v1_cw.push_back(f);
  EXPECT_EQ(at_v1, (std::vector<Face>{Face(0), Face(1)}));
  EXPECT_EQ(at_v1_cw, (std::vector<Face>{Face(1), Face(0)}));
  // Edges around v4: six; faces next to f0: f1 across v4-v1, the hole skipped, f3 across v3-v4.
  std::size_t edges = 0;
  for ([[maybe_unused]] Edge e : m.edges(vertex_of(4))) ++edges;
  EXPECT_EQ(edges, 6u);
  std::vector<Face> next_to_f0;
  for (Face f : m.faces(Face(0))) next_to_f0.push_back(f);
  EXPECT_EQ(next_to_f0, (std::vector<Face>{Face(1), Face(3)}));
  // McGuire's edge queries: the faces bordering v1-v4 are f0 and f1; v1-v3 borders f0 and the hole.
  Edge e14 = m.find_edge(vertex_of(1), vertex_of(4));
  std::vector<Face> sides{m.face(e14, 0), m.face(e14, 1)};
  std::sort(sides.begin(), sides.end());
  EXPECT_EQ(sides, (std::vector<Face>{Face(0), Face(1)}));
  EXPECT_TRUE(m.is_boundary(m.find_edge(vertex_of(1), vertex_of(3))));
}

}  // namespace
}  // namespace hedge
