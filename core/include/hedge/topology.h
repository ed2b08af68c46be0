// Counts that describe a surface's topology: boundary loops, components, Euler
// characteristic and genus. Used by `hedge info` and the report operation.
#pragma once

#include <cstddef>
#include <cstdint>

#include "hedge/mesh.h"

namespace hedge {

struct TopologyStats {
  std::size_t vertices = 0, edges = 0, faces = 0, halfedges = 0;
  std::size_t isolated_vertices = 0;
  std::size_t boundary_loops = 0;
  std::size_t boundary_edges = 0;
  std::size_t components = 0;             //!< connected components of faces and edges; isolated vertices not counted
  std::int64_t euler_characteristic = 0;  //!< V - E + F over non-isolated vertices
  std::int64_t genus = 0;                 //!< (2 components - boundary loops - chi) / 2, for orientable surfaces
};

//! O(size of the mesh).
TopologyStats topology_stats(const Mesh& mesh);

//! Component id per face (faces joined by an edge share an id; ids count from 0 in face
//! order); returns the number of components.
std::size_t face_components(const Mesh& mesh, std::vector<Index>& component_of_face);

//! Per vertex: the input vertex it stands for once build()'s copies are welded again (its
//! "hedge:source"), or vertices_size() + its index when it has none (a vertex an operation
//! made). Empty when `mesh` has no sources.
std::vector<std::uint64_t> welded_vertex_ids(const Mesh& mesh);

//! Per edge: true for the boundary edges that are seams of build()'s splits, where the
//! input's surface goes on: welded through the vertices' sources ("hedge:source"), another
//! face holds the same edge. All false (empty when `mesh` has no sources) otherwise; real
//! holes and borders are not seams. O(E log E).
std::vector<bool> split_seam_edges(const Mesh& mesh);

}  // namespace hedge
