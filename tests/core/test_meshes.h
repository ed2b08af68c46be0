// Small meshes for unit tests, made with the low-level setters so that tests of one part
// depend on nothing but the Mesh class itself.
#pragma once

#include <gtest/gtest.h>

#include <cstring>
#include <map>
#include <utility>
#include <vector>

#include "hedge/mesh.h"
#include "hedge/soup.h"
#include "hedge/validate.h"

//! Fails the test (ASSERT) or records a failure (EXPECT) naming the broken invariant.
#define ASSERT_VALID(mesh)                                  \
  do {                                                      \
    const ::hedge::Validation validation_ = validate(mesh); \
    ASSERT_TRUE(validation_.ok) << validation_.message;     \
  } while (0)
#define EXPECT_VALID(mesh)                                  \
  do {                                                      \
    const ::hedge::Validation validation_ = validate(mesh); \
    EXPECT_TRUE(validation_.ok) << validation_.message;     \
  } while (0)

namespace hedge::test {

//! The same arrays element for element and bit for bit: sizes, positions, every half-edge's
//! vertex, face, next and prev, and every vertex's and face's half-edge.
inline void expect_same_elements(const Mesh& a, const Mesh& b) {
  ASSERT_EQ(a.vertices_size(), b.vertices_size());
  ASSERT_EQ(a.edges_size(), b.edges_size());
  ASSERT_EQ(a.faces_size(), b.faces_size());
  EXPECT_EQ(std::memcmp(a.positions().data(), b.positions().data(), sizeof(Point) * a.positions().size()), 0);
  for (Halfedge h : a.halfedges()) {
    ASSERT_EQ(a.to_vertex(h), b.to_vertex(h)) << "half-edge " << h.idx();
    ASSERT_EQ(a.next(h), b.next(h)) << "half-edge " << h.idx();
    ASSERT_EQ(a.prev(h), b.prev(h)) << "half-edge " << h.idx();
    ASSERT_EQ(a.face(h), b.face(h)) << "half-edge " << h.idx();
  }
  for (Face f : a.faces()) ASSERT_EQ(a.halfedge(f), b.halfedge(f));
  for (Vertex v : a.vertices()) ASSERT_EQ(a.halfedge(v), b.halfedge(v));
}

//! A manifold mesh from points and counter-clockwise faces; corner 0 of a face is the target
//! of halfedge(f), and boundary loops are linked. The faces must form a manifold surface.
inline Mesh make_mesh(const std::vector<Point>& points, const std::vector<std::vector<Index>>& faces) {
  Mesh mesh;
  for (const Point& p : points) mesh.position(mesh.new_vertex()) = p;
  std::map<std::pair<Index, Index>, Halfedge> between;
  auto halfedge_from_to = [&](Index a, Index b) {
    if (auto it = between.find({a, b}); it != between.end()) return it->second;
    Halfedge h = mesh.new_edge(Vertex(a), Vertex(b));
    between[{a, b}] = h;
    between[{b, a}] = opposite(h);
    return h;
  };
  for (const auto& corners : faces) {
    const Face f = mesh.new_face();
    const std::size_t n = corners.size();
    std::vector<Halfedge> loop;  // loop[i] points to corners[i]
    for (std::size_t i = 0; i < n; ++i) loop.push_back(halfedge_from_to(corners[(i + n - 1) % n], corners[i]));
    for (std::size_t i = 0; i < n; ++i) {
      mesh.set_face(loop[i], f);
      mesh.set_next(loop[i], loop[(i + 1) % n]);
      mesh.set_halfedge(Vertex(corners[i]), loop[(i + 1) % n]);
    }
    mesh.set_halfedge(f, loop[0]);
  }
  std::map<Index, Halfedge> boundary_out;
  for (Index i = 0; i < mesh.halfedges_size(); ++i)
    if (mesh.is_boundary(Halfedge(i))) boundary_out[mesh.from_vertex(Halfedge(i)).idx()] = Halfedge(i);
  for (auto [v, h] : boundary_out) {
    mesh.set_next(h, boundary_out.at(mesh.to_vertex(h).idx()));
    mesh.set_halfedge(Vertex(v), h);
  }
  return mesh;
}

//! An n x n grid of squares over [0, size]^2, two triangles each, at z = height(x, y): an
//! open surface with one boundary loop.
template <class Height>
Soup height_field(int n, double size, Height height) {
  Soup s;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      const double x = size * i / n, y = size * j / n;
      s.positions.push_back(Point{{float(x), float(y), float(height(x, y))}});
    }
  auto id = [n](int i, int j) { return std::uint32_t(j * (n + 1) + i); };
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      s.add_face({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      s.add_face({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  return s;
}

}  // namespace hedge::test
