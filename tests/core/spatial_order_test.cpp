// detail::sort_spatially and the Morton cells it and decimation's regions share.
#include "spatial_order.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <numeric>
#include <random>
#include <set>
#include <vector>

#include "hedge/build.h"
#include "test_meshes.h"

namespace hedge {
namespace {

TEST(SpatialOrder, MortonCellsInterleaveTheAxes) {
  // One bit per axis: the eight octants of the box get the eight codes, x the lowest bit.
  std::set<std::uint32_t> codes;
  for (int z = 0; z < 2; ++z)
    for (int y = 0; y < 2; ++y)
      for (int x = 0; x < 2; ++x) {
        const Vec3f p{{x ? 0.25f : -0.25f, y ? 0.25f : -0.25f, z ? 0.25f : -0.25f}};
        const std::uint32_t code = detail::morton_cell(p, 0, 1);
        EXPECT_EQ(code, std::uint32_t(x | (y << 1) | (z << 2)));
        codes.insert(code);
      }
  EXPECT_EQ(codes.size(), 8u);
  // Ten bits per axis: the far corner is the last cell; an offset wraps around.
  EXPECT_EQ(detail::morton_cell(Vec3f{{0.49999f, 0.49999f, 0.49999f}}, 0, 10), (1u << 30) - 1);
  EXPECT_EQ(detail::morton_cell(Vec3f{{-0.5f, -0.5f, -0.5f}}, 0, 10), 0u);
  EXPECT_EQ(detail::morton_cell(Vec3f{{0.4f, 0.4f, 0.4f}}, 0.5, 1), 0u);
}

// A wavy 60 x 60 height field whose vertices and faces are numbered at random, with each
// vertex's original number as a property.
Mesh shuffled_field() {
  Soup soup = test::height_field(60, 1.0, [](double x, double y) { return 0.1 * std::sin(6 * x) * std::cos(5 * y); });
  std::vector<std::uint32_t> perm(soup.positions.size());
  std::iota(perm.begin(), perm.end(), 0u);
  std::shuffle(perm.begin(), perm.end(), std::mt19937(7));
  Soup shuffled;
  shuffled.positions.resize(soup.positions.size());
  for (std::size_t i = 0; i < perm.size(); ++i) shuffled.positions[perm[i]] = soup.positions[i];
  std::vector<std::size_t> faces(soup.n_faces());
  std::iota(faces.begin(), faces.end(), std::size_t(0));
  std::shuffle(faces.begin(), faces.end(), std::mt19937(8));
  // Height fields are triangles: face f's corners are corners[3f .. 3f + 3).
  for (std::size_t f : faces)
    shuffled.add_face({perm[soup.corners[3 * f]], perm[soup.corners[3 * f + 1]], perm[soup.corners[3 * f + 2]]});
  Mesh m = build(shuffled).mesh;
  auto original = m.add_vertex_property<int>("original");
  for (Vertex v : m.vertices()) original[v] = int(v.idx());
  return m;
}

// The mean distance in the vertex array between the two ends of an edge.
double mean_edge_span(const Mesh& m) {
  double sum = 0;
  for (Edge e : m.edges()) sum += std::abs(double(m.vertex(e, 0).idx()) - double(m.vertex(e, 1).idx()));
  return sum / double(m.n_edges());
}

// Every face as its corners' places, starting from the smallest, so that the same face
// reads the same whatever the numbering.
std::multiset<std::vector<std::array<float, 3>>> faces_by_place(const Mesh& m) {
  std::multiset<std::vector<std::array<float, 3>>> out;
  for (Face f : m.faces()) {
    std::vector<std::array<float, 3>> corners;
    for (Vertex v : m.vertices(f)) corners.push_back({m.position(v)[0], m.position(v)[1], m.position(v)[2]});
    std::rotate(corners.begin(), std::min_element(corners.begin(), corners.end()), corners.end());
    out.insert(corners);
  }
  return out;
}

TEST(SpatialOrder, RenumbersNearElementsNearAndChangesNothingElse) {
  Mesh m = shuffled_field();
  const Mesh before = m;
  const double span_before = mean_edge_span(m);
  detail::sort_spatially(m);
  ASSERT_VALID(m);
  EXPECT_EQ(m.n_vertices(), before.n_vertices());
  EXPECT_EQ(m.n_edges(), before.n_edges());
  EXPECT_EQ(m.n_faces(), before.n_faces());
  EXPECT_EQ(faces_by_place(m), faces_by_place(before));
  // Properties follow their vertices.
  auto original = m.get_vertex_property<int>("original");
  for (Vertex v : m.vertices()) EXPECT_EQ(m.position(v), before.position(Vertex(Index(original[v]))));
  // Near on the surface is near in the arrays: the random numbering put an edge's ends a
  // third of the array apart on average.
  EXPECT_GT(span_before, 1000);
  EXPECT_LT(mean_edge_span(m), span_before / 10);
  // Faces follow the same order: a face's neighbours are numbered near it.
  double face_span = 0;
  for (Edge e : m.edges())
    if (!m.is_boundary(e)) face_span += std::abs(double(m.face(e, 0).idx()) - double(m.face(e, 1).idx()));
  EXPECT_LT(face_span / double(m.n_edges()), span_before / 5);
}

TEST(SpatialOrder, DropsDeletedElements) {
  Mesh m = shuffled_field();
  m.delete_face(Face(10));
  m.delete_face(Face(11));
  const std::size_t faces = m.n_faces(), vertices = m.n_vertices();
  detail::sort_spatially(m);
  ASSERT_VALID(m);
  EXPECT_FALSE(m.has_garbage());
  EXPECT_EQ(m.faces_size(), faces);
  EXPECT_EQ(m.vertices_size(), vertices);
}

}  // namespace
}  // namespace hedge
