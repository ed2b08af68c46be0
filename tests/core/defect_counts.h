// An independent count of the defects a weld can make, from the soup alone: it shares no
// code with build(), extract() or the half-edge mesh, so a test can hold them to it.
#pragma once

#include <algorithm>
#include <cstdint>
#include <numeric>
#include <ostream>
#include <string>
#include <utility>
#include <vector>

#include "hedge/soup.h"

namespace hedge::test {

struct DefectCounts {
  std::size_t non_manifold_edges = 0;     //!< undirected edges used by three or more face sides
  std::size_t non_manifold_vertices = 0;  //!< vertices whose faces make more than one fan
  std::size_t duplicate_faces = 0;        //!< faces whose vertex set an earlier face has
  std::size_t repeating_faces = 0;        //!< faces that list one vertex more than once
  std::size_t border_edges = 0;           //!< edges with one face side: not a defect, a hole's edge
  std::size_t lone_face_edges = 0;        //!< border edges of faces with no neighbour (not holes to fill)

  static constexpr const char* kNames[] = {"non-manifold edges", "non-manifold vertices", "duplicate faces",
                                           "faces repeating a vertex"};
  std::size_t at(int i) const {
    const std::size_t all[] = {non_manifold_edges, non_manifold_vertices, duplicate_faces, repeating_faces};
    return all[i];
  }
};

inline std::ostream& operator<<(std::ostream& os, const DefectCounts& d) {
  return os << "nm edges " << d.non_manifold_edges << ", nm vertices " << d.non_manifold_vertices
            << ", duplicate faces " << d.duplicate_faces << ", repeating faces " << d.repeating_faces
            << " (border edges " << d.border_edges << ")";
}

inline DefectCounts count_defects(const Soup& soup) {
  DefectCounts d;
  std::vector<std::size_t> start(soup.n_faces() + 1, 0);
  for (std::size_t f = 0; f < soup.n_faces(); ++f) start[f + 1] = start[f] + soup.face_sizes[f];
  auto corner = [&](std::size_t f, std::size_t i) { return soup.corners[start[f] + i % soup.face_sizes[f]]; };

  // Faces repeating a vertex, and duplicates: sorted vertex lists compared whole.
  std::vector<std::vector<std::uint32_t>> sets(soup.n_faces());
  for (std::size_t f = 0; f < soup.n_faces(); ++f) {
    auto& s = sets[f];
    s.assign(soup.corners.begin() + start[f], soup.corners.begin() + start[f + 1]);
    std::sort(s.begin(), s.end());
    const std::size_t n = s.size();
    s.erase(std::unique(s.begin(), s.end()), s.end());
    if (s.size() != n) ++d.repeating_faces;
  }
  std::sort(sets.begin(), sets.end());
  for (std::size_t f = 1; f < sets.size(); ++f)
    if (sets[f] == sets[f - 1]) ++d.duplicate_faces;

  // Every face side as (low, high, face); a side from a vertex to itself is no edge.
  struct Side {
    std::uint32_t a, b, face;
  };
  std::vector<Side> sides;
  sides.reserve(soup.n_corners());
  for (std::size_t f = 0; f < soup.n_faces(); ++f)
    for (std::size_t i = 0; i < soup.face_sizes[f]; ++i) {
      const std::uint32_t u = corner(f, i), v = corner(f, i + 1);
      if (u != v) sides.push_back({std::min(u, v), std::max(u, v), std::uint32_t(f)});
    }
  std::sort(sides.begin(), sides.end(),
            [](const Side& x, const Side& y) { return std::tie(x.a, x.b, x.face) < std::tie(y.a, y.b, y.face); });
  std::vector<char> shared(soup.n_faces(), 0);  // a face with a side another face has too
  for (std::size_t i = 0; i < sides.size();) {
    std::size_t j = i;
    while (j < sides.size() && sides[j].a == sides[i].a && sides[j].b == sides[i].b) ++j;
    if (j - i >= 3) ++d.non_manifold_edges;
    if (j - i == 1) ++d.border_edges;
    if (j - i > 1)
      std::for_each(sides.begin() + std::ptrdiff_t(i), sides.begin() + std::ptrdiff_t(j),
                    [&](const Side& side) { shared[side.face] = 1; });
    i = j;
  }
  for (std::size_t f = 0; f < soup.n_faces(); ++f)
    if (!shared[f]) d.lone_face_edges += soup.face_sizes[f];

  // Fans: at each vertex, faces that share an edge through it are one fan (union-find over
  // (vertex, face) incidences joined along each edge's sides, at both of its ends).
  std::vector<std::pair<std::uint32_t, std::uint32_t>> incidences;  // (vertex, face)
  incidences.reserve(soup.n_corners());
  for (std::size_t f = 0; f < soup.n_faces(); ++f)
    for (std::size_t i = 0; i < soup.face_sizes[f]; ++i) incidences.emplace_back(corner(f, i), std::uint32_t(f));
  std::sort(incidences.begin(), incidences.end());
  incidences.erase(std::unique(incidences.begin(), incidences.end()), incidences.end());
  auto find_incidence = [&](std::uint32_t v, std::uint32_t f) {
    return std::size_t(std::lower_bound(incidences.begin(), incidences.end(), std::make_pair(v, f)) -
                       incidences.begin());
  };
  std::vector<std::size_t> parent(incidences.size());
  std::iota(parent.begin(), parent.end(), 0);
  auto root = [&](std::size_t x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  };
  for (std::size_t i = 0; i < sides.size();) {
    std::size_t j = i;
    while (j < sides.size() && sides[j].a == sides[i].a && sides[j].b == sides[i].b) ++j;
    const Side* edge = sides.data() + i;
    for (const std::uint32_t end : {edge->a, edge->b}) {
      const std::size_t first = root(find_incidence(end, edge->face));
      for (const Side* other = edge + 1; other != sides.data() + j; ++other)
        parent[root(find_incidence(end, other->face))] = first;
    }
    i = j;
  }
  for (std::size_t i = 0; i < incidences.size();) {
    std::size_t j = i, fans = 0;
    while (j < incidences.size() && incidences[j].first == incidences[i].first) {
      if (root(j) == j) ++fans;
      ++j;
    }
    if (fans > 1) ++d.non_manifold_vertices;
    i = j;
  }
  return d;
}

}  // namespace hedge::test
