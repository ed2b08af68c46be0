// Tests of the Mesh class itself: allocation, circulators, properties, deletion and
// garbage collection. Euler operations have their own file.
#include "hedge/mesh.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <map>
#include <string>
#include <tuple>
#include <vector>

#include "hedge/build.h"
#include "hedge/error.h"
#include "hedge/io.h"
#include "hedge/provenance.h"
#include "hedge/threads.h"
#include "hedge/topology.h"
#include "hedge/validate.h"
#include "parallel.h"
#include "test_meshes.h"

namespace hedge {
namespace {

// A 3x3 grid of vertices, 4 quads, counter-clockwise seen from +z.
Mesh quad_grid() {
  Mesh m;
  std::vector<Vertex> v;
  for (int y = 0; y < 3; ++y)
    for (int x = 0; x < 3; ++x) v.push_back(m.add_vertex(Point{{float(x), float(y), 0}}));
  for (int y = 0; y < 2; ++y)
    for (int x = 0; x < 2; ++x) m.add_quad(v[y * 3 + x], v[y * 3 + x + 1], v[(y + 1) * 3 + x + 1], v[(y + 1) * 3 + x]);
  return m;
}

// A closed tetrahedron.
Mesh tetrahedron() {
  Mesh m;
  Vertex a = m.add_vertex(Point{{0, 0, 0}}), b = m.add_vertex(Point{{1, 0, 0}});
  Vertex c = m.add_vertex(Point{{0, 1, 0}}), d = m.add_vertex(Point{{0, 0, 1}});
  m.add_triangle(a, c, b);
  m.add_triangle(a, b, d);
  m.add_triangle(b, c, d);
  m.add_triangle(c, a, d);
  return m;
}

template <class Range>
auto collect(const Range& range) {
  std::vector<std::decay_t<decltype(*range.begin())>> out;
  for (auto x : range) out.push_back(x);
  return out;
}

TEST(Mesh, HandlesArePairedHalfedges) {
  EXPECT_EQ(opposite(Halfedge(6)), Halfedge(7));
  EXPECT_EQ(opposite(Halfedge(7)), Halfedge(6));
  EXPECT_EQ(edge_of(Halfedge(7)), Edge(3));
  EXPECT_EQ(halfedge_of(Edge(3), 1), Halfedge(7));
  EXPECT_FALSE(Vertex().is_valid());
  EXPECT_EQ(Vertex().idx(), kInvalidIndex);
}

TEST(Mesh, GridCountsAndBoundary) {
  Mesh m = quad_grid();
  ASSERT_TRUE(validate(m)) << validate(m).message;
  EXPECT_EQ(m.n_vertices(), 9u);
  EXPECT_EQ(m.n_faces(), 4u);
  EXPECT_EQ(m.n_edges(), 12u);
  EXPECT_EQ(m.n_halfedges(), 24u);
  EXPECT_TRUE(m.is_quad_mesh());
  EXPECT_FALSE(m.is_boundary(Vertex(4)));
  for (int i : {0, 1, 2, 3, 5, 6, 7, 8}) EXPECT_TRUE(m.is_boundary(Vertex(i))) << i;
  // A boundary vertex's halfedge is its outgoing boundary half-edge.
  for (int i : {0, 1, 2, 3, 5, 6, 7, 8}) EXPECT_TRUE(m.is_boundary(m.halfedge(Vertex(i)))) << i;
  TopologyStats t = topology_stats(m);
  EXPECT_EQ(t.boundary_loops, 1u);
  EXPECT_EQ(t.components, 1u);
  EXPECT_EQ(t.euler_characteristic, 1);
  EXPECT_EQ(t.genus, 0);
}

TEST(Mesh, CirculatorsAroundInteriorVertexCounterClockwise) {
  Mesh m = quad_grid();
  Vertex center(4);
  auto ring = collect(m.vertices(center));
  ASSERT_EQ(ring.size(), 4u);
  // Counter-clockwise seen from +z: the sequence 5 -> 7 -> 3 -> 1 up to rotation.
  std::vector<Vertex> expected = {Vertex(5), Vertex(7), Vertex(3), Vertex(1)};
  auto start = std::find(expected.begin(), expected.end(), ring[0]);
  ASSERT_NE(start, expected.end());
  std::rotate(expected.begin(), start, expected.end());
  EXPECT_EQ(ring, expected);
  // Clockwise is the reverse order from the same start.
  auto cw = collect(m.vertices_cw(center));
  std::vector<Vertex> reversed = {ring[0], ring[3], ring[2], ring[1]};
  EXPECT_EQ(cw, reversed);
  EXPECT_EQ(collect(m.faces(center)).size(), 4u);
  EXPECT_EQ(collect(m.edges(center)).size(), 4u);
  EXPECT_EQ(m.valence(center), 4u);
  for (Halfedge h : m.outgoing(center)) EXPECT_EQ(m.from_vertex(h), center);
}

TEST(Mesh, CirculatorsSkipHolesAroundBoundaryVertex) {
  Mesh m = quad_grid();
  Vertex corner(0), side(1);
  EXPECT_EQ(collect(m.faces(corner)).size(), 1u);
  EXPECT_EQ(collect(m.vertices(corner)).size(), 2u);
  EXPECT_EQ(collect(m.faces(side)).size(), 2u);
  EXPECT_EQ(collect(m.faces_cw(side)).size(), 2u);
  EXPECT_EQ(m.valence(side), 3u);
}

TEST(Mesh, FaceCirculatorsStartAtCornerZero) {
  Mesh m = quad_grid();
  auto corners = collect(m.vertices(Face(0)));
  EXPECT_EQ(corners, (std::vector<Vertex>{Vertex(0), Vertex(1), Vertex(4), Vertex(3)}));
  EXPECT_EQ(collect(m.halfedges(Face(0))).size(), 4u);
  auto reversed = collect(m.halfedges_reversed(Face(0)));
  EXPECT_EQ(reversed.size(), 4u);
  EXPECT_EQ(m.to_vertex(reversed[1]), Vertex(3));
  // Face 0 (lower left) touches faces 1 (right) and 2 (above).
  auto neighbours = collect(m.faces(Face(0)));
  std::sort(neighbours.begin(), neighbours.end());
  EXPECT_EQ(neighbours, (std::vector<Face>{Face(1), Face(2)}));
  EXPECT_EQ(collect(m.edges(Face(3))).size(), 4u);
}

TEST(Mesh, IsolatedVertexHasEmptyRanges) {
  Mesh m;
  Vertex v = m.add_vertex(Point{{1, 2, 3}});
  EXPECT_TRUE(m.is_isolated(v));
  EXPECT_TRUE(m.is_boundary(v));
  EXPECT_TRUE(collect(m.vertices(v)).empty());
  EXPECT_TRUE(collect(m.faces(v)).empty());
  EXPECT_EQ(m.position(v), (Point{{1, 2, 3}}));
  EXPECT_TRUE(validate(m)) << validate(m).message;
}

TEST(Mesh, FindHalfedge) {
  Mesh m = quad_grid();
  Halfedge h = m.find_halfedge(Vertex(0), Vertex(1));
  ASSERT_TRUE(h.is_valid());
  EXPECT_EQ(m.from_vertex(h), Vertex(0));
  EXPECT_EQ(m.to_vertex(h), Vertex(1));
  EXPECT_FALSE(m.find_halfedge(Vertex(0), Vertex(4)).is_valid());
  EXPECT_EQ(m.find_edge(Vertex(1), Vertex(0)), Mesh::edge(h));
}

TEST(Mesh, PropertiesFollowElements) {
  Mesh m = quad_grid();
  auto weight = m.add_vertex_property<float>("weight", 2.0f);
  EXPECT_EQ(weight[Vertex(3)], 2.0f);
  weight[Vertex(3)] = 7.0f;
  auto same = m.get_vertex_property<float>("weight");
  ASSERT_TRUE(same);
  EXPECT_EQ(same[Vertex(3)], 7.0f);
  EXPECT_FALSE(m.get_vertex_property<int>("weight"));  // wrong type is not found
  EXPECT_THROW(m.add_vertex_property<float>("weight"), Error);
  Vertex v = m.add_vertex(Point{});
  EXPECT_EQ(weight[v], 2.0f);  // new elements get the default
  auto label = m.face_property<int>("label", -1);
  EXPECT_EQ(label[Face(2)], -1);
  m.face_properties().remove("label");
  EXPECT_FALSE(m.get_face_property<int>("label"));

  auto* uv = m.halfedge_properties().add_channel("uv", ScalarType::f32, 2);
  EXPECT_EQ(uv->size(), m.halfedges_size());
  EXPECT_EQ(uv->stride(), 8u);
}

TEST(Mesh, InterpolateNumbersAndPickOthers) {
  Mesh m;
  for (int i = 0; i < 3; ++i) m.add_vertex(Point{{float(i), 0, 0}});
  auto value = m.add_vertex_property<float>("value");
  auto id = m.add_vertex_property<int>("id");
  value[Vertex(0)] = 1;
  value[Vertex(1)] = 3;
  id[Vertex(0)] = 10;
  id[Vertex(1)] = 20;
  std::vector<Index> from = {0, 1};
  std::vector<float> weights = {0.25f, 0.75f};
  m.vertex_properties().interpolate(2, from, weights);
  EXPECT_FLOAT_EQ(value[Vertex(2)], 2.5f);
  EXPECT_EQ(id[Vertex(2)], 20);  // integers take the heaviest source
}

TEST(Mesh, InterpolationDoesNotInheritProvenance) {
  Mesh m;
  for (int i = 0; i < 3; ++i) m.add_vertex(Point{{float(i), 0, 0}});
  auto source = m.add_vertex_property<std::uint32_t>(provenance::kVertexSource, kInvalidIndex);
  source[Vertex(0)] = 0;
  source[Vertex(1)] = 0;
  source[Vertex(2)] = 2;
  std::vector<Index> from = {0, 1};
  std::vector<float> weights = {0.5f, 0.5f};
  m.vertex_properties().interpolate(2, from, weights);
  EXPECT_EQ(source[Vertex(2)], kInvalidIndex);  // a new vertex has no source of its own
  m.vertex_properties().copy_element(0, 2);
  EXPECT_EQ(source[Vertex(2)], 0u);  // a copy shares its source
}

TEST(Mesh, DeleteFaceAndGarbageCollect) {
  Mesh m = quad_grid();
  auto tag = m.add_vertex_property<int>("tag");
  for (Vertex v : m.vertices()) tag[v] = int(v.idx()) * 10;
  m.delete_face(Face(0));
  ASSERT_TRUE(validate(m)) << validate(m).message;
  EXPECT_EQ(m.n_faces(), 3u);
  EXPECT_TRUE(m.is_deleted(Vertex(0)));  // the corner vertex lost its only face
  EXPECT_EQ(m.n_vertices(), 8u);
  EXPECT_EQ(m.n_edges(), 10u);
  EXPECT_TRUE(m.has_garbage());
  std::size_t live = 0;
  for ([[maybe_unused]] Face f : m.faces()) ++live;
  EXPECT_EQ(live, 3u);

  GarbageMaps maps = m.garbage_collect();
  ASSERT_TRUE(validate(m)) << validate(m).message;
  EXPECT_FALSE(m.has_garbage());
  EXPECT_EQ(m.vertices_size(), 8u);
  EXPECT_EQ(m.faces_size(), 3u);
  EXPECT_EQ(maps.vertices[0], kInvalidIndex);
  EXPECT_EQ(maps.vertices[1], 0u);  // relative order kept
  EXPECT_EQ(maps.faces[1], 0u);
  // A half-edge keeps its side of its edge.
  for (Index e = 0; e < maps.edges.size(); ++e)
    for (Index side = 0; side < 2; ++side)
      EXPECT_EQ(maps.halfedge(2 * e + side), maps.edges[e] == kInvalidIndex ? kInvalidIndex : 2 * maps.edges[e] + side);
  EXPECT_EQ(std::count(maps.edges.begin(), maps.edges.end(), kInvalidIndex), 2);  // the corner's two edges
  EXPECT_EQ(tag[Vertex(0)], 10);  // properties moved with their vertices
  EXPECT_EQ(tag[Vertex(7)], 80);
  EXPECT_EQ(m.position(Vertex(0)), (Point{{1, 0, 0}}));
  EXPECT_EQ(topology_stats(m).boundary_loops, 1u);
}

TEST(Mesh, CompactIsGarbageCollectWithoutMaps) {
  // A grid large enough for several blocks of 64 deletion marks, with faces deleted in an
  // irregular pattern (vertices, edges and faces all go, in runs and alone).
  constexpr int n = 24;
  Mesh m;
  std::vector<Vertex> v;
  for (int y = 0; y <= n; ++y)
    for (int x = 0; x <= n; ++x) v.push_back(m.add_vertex(Point{{float(x), float(y), float(x * y % 7)}}));
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x)
      m.add_quad(v[y * (n + 1) + x], v[y * (n + 1) + x + 1], v[(y + 1) * (n + 1) + x + 1], v[(y + 1) * (n + 1) + x]);
  auto tag = m.add_vertex_property<int>("tag");
  for (Vertex w : m.vertices()) tag[w] = int(w.idx()) * 3;
  for (Face f : m.faces())
    if ((f.idx() * 37) % 11 < 4 || (f.idx() > 100 && f.idx() < 180)) m.delete_face(f);
  ASSERT_TRUE(m.has_garbage());
  Mesh a = m, b = m;
  a.garbage_collect();
  b.compact();
  // (Deleting faces may leave vertices pinched, which validate() names: the same in both.)
  EXPECT_EQ(validate(b).message, validate(a).message);
  EXPECT_FALSE(b.has_garbage());
  test::expect_same_elements(b, a);
  for (Vertex w : a.vertices()) EXPECT_EQ(b.get_vertex_property<int>("tag")[w], a.get_vertex_property<int>("tag")[w]);
  // Nothing deleted: nothing changes.
  Mesh c = a;
  c.compact();
  EXPECT_EQ(c.vertices_size(), a.vertices_size());
  EXPECT_EQ(c.halfedge(Vertex(5)), a.halfedge(Vertex(5)));
}

TEST(Mesh, ReorderRenumbersLiveElementsAndCarriesEverything) {
  Mesh m = quad_grid();
  auto tag = m.add_vertex_property<int>("tag");
  auto face_tag = m.add_face_property<int>("face tag");
  for (Vertex v : m.vertices()) tag[v] = int(v.idx()) * 10;
  for (Face f : m.faces()) face_tag[f] = int(f.idx()) + 100;
  m.delete_face(Face(0));  // vertex 0 goes with it
  auto reversed = [](auto range) {
    std::vector<Index> order;
    for (auto x : range) order.push_back(x.idx());
    std::reverse(order.begin(), order.end());
    return order;
  };
  const std::vector<Index> vo = reversed(m.vertices()), eo = reversed(m.edges()), fo = reversed(m.faces());
  // Each face's corner positions, in order from corner 0, by its tag.
  auto corners_by_tag = [&] {
    std::map<int, std::vector<Point>> out;
    for (Face f : m.faces())
      for (Vertex v : m.vertices(f)) out[face_tag[f]].push_back(m.position(v));
    return out;
  };
  const auto before = corners_by_tag();

  const GarbageMaps maps = m.reorder(vo, eo, fo);
  ASSERT_TRUE(validate(m)) << validate(m).message;
  EXPECT_FALSE(m.has_garbage());
  EXPECT_EQ(m.vertices_size(), 8u);
  EXPECT_EQ(m.faces_size(), 3u);
  EXPECT_EQ(maps.vertices[0], kInvalidIndex);
  EXPECT_EQ(maps.vertices[8], 0u);  // the last vertex comes first
  EXPECT_EQ(maps.faces[3], 0u);
  EXPECT_EQ(tag[Vertex(0)], 80);  // properties moved with their elements
  EXPECT_EQ(m.position(Vertex(0)), (Point{{2, 2, 0}}));
  EXPECT_EQ(face_tag[Face(0)], 103);
  EXPECT_EQ(corners_by_tag(), before);  // same faces, same corners, same order around
  EXPECT_EQ(topology_stats(m).boundary_loops, 1u);
}

TEST(Mesh, ReorderRefusesAnOrderThatIsNotOneOfTheLiveElements) {
  Mesh m = quad_grid();
  m.delete_face(Face(0));
  const Mesh before = m;
  std::vector<Index> vo, eo, fo;
  for (Vertex v : m.vertices()) vo.push_back(v.idx());
  for (Edge e : m.edges()) eo.push_back(e.idx());
  for (Face f : m.faces()) fo.push_back(f.idx());
  auto refused = [&](std::vector<Index> v, std::vector<Index> e, std::vector<Index> f, const char* says) {
    try {
      m.reorder(v, e, f);
      ADD_FAILURE() << "accepted an order that " << says;
    } catch (const Error& error) {
      EXPECT_NE(std::string(error.what()).find(says), std::string::npos) << error.what();
    }
    EXPECT_EQ(m.vertices_size(), before.vertices_size());
    EXPECT_TRUE(m.has_garbage());  // nothing changed
  };
  std::vector<Index> twice = vo;
  twice.back() = twice.front();
  refused(twice, eo, fo, "twice");
  std::vector<Index> dead = fo;
  dead.front() = 0;  // the deleted face
  refused(vo, eo, dead, "deleted");
  std::vector<Index> short_list(eo.begin(), eo.end() - 1);
  refused(vo, short_list, fo, "the mesh has");
  std::vector<Index> beyond = vo;
  beyond.back() = 99;
  refused(beyond, eo, fo, "does not exist");
}

TEST(Mesh, DeleteVertexRemovesItsFaces) {
  Mesh m = quad_grid();
  m.delete_vertex(Vertex(4));
  ASSERT_TRUE(validate(m)) << validate(m).message;
  EXPECT_EQ(m.n_faces(), 0u);
  EXPECT_EQ(m.n_edges(), 0u);
  EXPECT_EQ(m.n_vertices(), 0u);
  m.garbage_collect();
  EXPECT_TRUE(m.is_empty());
  EXPECT_TRUE(validate(m)) << validate(m).message;
}

TEST(Mesh, DeleteEdgeOpensAHole) {
  Mesh m = tetrahedron();
  EXPECT_EQ(topology_stats(m).euler_characteristic, 2);
  EXPECT_EQ(topology_stats(m).boundary_loops, 0u);
  m.delete_edge(Edge(0));
  ASSERT_TRUE(validate(m)) << validate(m).message;
  EXPECT_EQ(m.n_faces(), 2u);
  m.garbage_collect();
  ASSERT_TRUE(validate(m)) << validate(m).message;
  EXPECT_EQ(topology_stats(m).boundary_loops, 1u);
}

TEST(Mesh, CopiesAreDeep) {
  Mesh a = quad_grid();
  auto p = a.add_vertex_property<int>("p", 1);
  Mesh b = a;
  auto q = b.get_vertex_property<int>("p");
  q[Vertex(0)] = 5;
  EXPECT_EQ(p[Vertex(0)], 1);
  EXPECT_EQ(b.n_faces(), a.n_faces());
  EXPECT_TRUE(validate(b)) << validate(b).message;
}

TEST(Mesh, ValidateNamesTheBrokenInvariant) {
  Mesh m = quad_grid();
  Halfedge h = m.halfedge(Face(0));
  m.set_next(h, m.next(m.next(h)));  // skip a corner: the loops no longer close properly
  Validation v = validate(m);
  EXPECT_FALSE(v);
  EXPECT_NE(v.message.find("half-edge"), std::string::npos) << v.message;

  Mesh n = quad_grid();
  n.set_halfedge(Vertex(0), n.next(n.halfedge(Vertex(0))));
  EXPECT_FALSE(validate(n));
  EXPECT_NE(validate(n).message.find("vertex 0"), std::string::npos) << validate(n).message;
  EXPECT_THROW(check_valid(n, "test"), Error);
}

// validate() checks each pass on several threads: whatever their number, it names the first
// broken element in index order, as one thread checking in order does.
TEST(Mesh, ValidateNamesTheFirstBreakOnAnyThreadCount) {
  const std::string path = std::string(HEDGE_MESH_DIR) + "/bunny.off";
  if (!std::filesystem::exists(path)) GTEST_SKIP() << "bunny.off not found in " << HEDGE_MESH_DIR;
  const Mesh bunny = build(read_mesh(path)).mesh;
  ASSERT_TRUE(validate(bunny)) << validate(bunny).message;
  const Index nv = static_cast<Index>(bunny.vertices_size()), nh = static_cast<Index>(bunny.halfedges_size());
  auto broken_vertices = [&] {  // two vertices far apart whose half-edge does not leave them
    Mesh m = bunny;
    for (Index v : {nv - 7, Index(11)}) m.set_halfedge(Vertex(v), m.next(m.halfedge(Vertex(v))));
    return m;
  };
  auto broken_halfedges = [&] {  // two loops that skip a corner, far apart
    Mesh m = bunny;
    for (Index h : {nh - 40, Index(30)}) m.set_next(Halfedge(h), m.next(m.next(Halfedge(h))));
    return m;
  };
  for (const auto& [what, mesh, expected] : {std::tuple{"vertices", broken_vertices(), std::string("vertex 11:")},
                                             std::tuple{"half-edges", broken_halfedges(), std::string("half-edge ")}}) {
    set_thread_count(1);
    const Validation one = validate(mesh);
    ASSERT_FALSE(one) << what;
    EXPECT_EQ(one.message.rfind(expected, 0), 0u) << what << ": " << one.message;
    for (unsigned threads : {2u, 3u, 8u}) {
      set_thread_count(threads);
      testing::set_parallel_grain(64);
      const std::size_t splits = testing::parallel_splits();
      EXPECT_EQ(validate(mesh).message, one.message) << what << ", " << threads << " threads";
      EXPECT_GT(testing::parallel_splits(), splits) << what << ": no pass ran on several threads";
      testing::set_parallel_grain(0);
    }
    set_thread_count(0);
  }
}

// Two closed fans at one vertex (two tetrahedra glued at a corner): each fan closes, so only
// counting the half-edges that leave the vertex tells that its rotation misses half of them.
TEST(Mesh, ValidateFindsAVertexWithTwoClosedFans) {
  const std::vector<Point> corners = {{{0, 0, 0}}, {{1, 0, 0}}, {{0, 1, 0}}, {{0, 0, 1}}};
  std::vector<Point> points = corners;
  for (const Point& p : corners) points.push_back(Point{{p[0] + 3, p[1], p[2]}});
  const std::vector<std::vector<Index>> tetrahedron = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  std::vector<std::vector<Index>> faces = tetrahedron;
  for (auto f : tetrahedron) {
    for (Index& v : f) v += 4;
    faces.push_back(f);
  }
  Mesh m = test::make_mesh(points, faces);
  ASSERT_TRUE(validate(m)) << validate(m).message;
  for (Halfedge h : m.halfedges())
    if (m.to_vertex(h) == Vertex(4)) m.set_vertex(h, Vertex(0));
  m.set_halfedge(Vertex(4), Halfedge());  // left isolated
  const std::string expected = "vertex 0: non-manifold, its fan holds 3 of its 6 edges";
  EXPECT_EQ(validate(m).message, expected);
  for (unsigned threads : {2u, 3u}) {
    set_thread_count(threads);
    testing::set_parallel_grain(1);
    EXPECT_EQ(validate(m).message, expected) << threads << " threads";
    testing::set_parallel_grain(0);
  }
  set_thread_count(0);
}

TEST(Mesh, HeapBytesCountsArrays) {
  Mesh m = quad_grid();
  m.shrink_to_fit();
  // 24 half-edges of 16 bytes, 9 vertices (4 + 12 bytes), 4 faces of 4 bytes, at least.
  EXPECT_GE(m.heap_bytes(), 24u * 16 + 9u * 16 + 4u * 4);
}

}  // namespace
}  // namespace hedge
