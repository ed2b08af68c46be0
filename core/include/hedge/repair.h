// Mesh repair: keep the repairs build() made (manifold splits, consistent orientation) and
// remove what stays broken: degenerate and duplicate faces, near-duplicate vertices, pinches.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "hedge/mesh.h"
#include "hedge/progress.h"

namespace hedge {

struct RepairOptions {
  //! Weld vertices at most this far apart (absolute units); 0 leaves vertices alone.
  double weld_distance = 0;
  bool remove_isolated_vertices = true;
};

//! What build() had repaired, read back from the provenance it stores in the mesh.
struct BuildRepairs {
  std::size_t non_manifold_edges = 0;     //!< soup edges of 3+ faces, split into several mesh edges
  std::size_t non_manifold_vertices = 0;  //!< soup vertices split into several mesh vertices
  std::size_t vertex_copies = 0;          //!< mesh vertices added by those splits
  std::size_t faces_flipped = 0;
  std::size_t repeated_vertex_faces = 0;  //!< faces visiting a soup vertex more than once
  std::size_t edges_cut = 0;              //!< 2-face soup edges left as two boundary edges (unorientable, repeats)
  std::size_t skipped_faces = 0;          //!< faces build() left out, as far as the mesh shows (see repair())
};

//! Counts the repairs recorded in the mesh's provenance ("hedge:source" per vertex and per
//! face, "hedge:flipped" per face); all zero for a mesh that needed none. O(mesh log mesh).
BuildRepairs build_repairs(const Mesh& mesh);

struct RepairReport {
  // Repairs kept in the result (read back from the provenance of the mesh the result
  // was made from: the input, or the rebuild after welding / removing duplicates).
  std::size_t non_manifold_edges_split = 0;
  std::size_t non_manifold_vertices_split = 0;
  std::size_t vertex_copies_added = 0;
  std::size_t faces_flipped = 0;
  std::size_t repeated_vertex_faces_split = 0;
  std::size_t edges_cut = 0;
  // Removals.
  std::size_t degenerate_faces_removed = 0;  //!< zero area: skipped by build(), welded flat, collapsed or deleted
  std::size_t degenerate_faces_deleted = 0;  //!< of those, deleted because no collapse was legal (they leave a hole)
  std::size_t duplicate_faces_removed = 0;   //!< same vertex set as an earlier face
  std::size_t vertices_welded = 0;           //!< vertices merged into a nearby one
  std::size_t pinched_faces_removed = 0;     //!< faces on a second edge between the same two vertices
  std::size_t isolated_vertices_removed = 0;
  std::vector<std::string> messages;
};

//! Repairs `mesh` (normally fresh from build()) so that extract() returns a soup that builds
//! without any repair:
//! 1. build()'s splits of non-manifold edges and vertices and its orientation flips are
//!    kept: the provenance that lets extract() undo them is removed;
//! 2. with weld_distance > 0, vertices that close are merged, in chains, into the first
//!    (lowest index) of each group, which keeps its position (grid of cells, O(n log n)),
//!    faces left with fewer than 3 distinct vertices go, and the mesh is rebuilt (welding
//!    may make new non-manifold places, which the rebuild splits and the report counts);
//! 3. duplicate faces (the same vertex set as an earlier face) are removed before that
//!    rebuild, so the survivor glues to its neighbours;
//! 4. faces of zero area collapse their shortest edge when the link condition allows, and
//!    are deleted otherwise; faces the collapses leave over one vertex set are removed as
//!    duplicates;
//! 5. where a non-manifold edge's extra face stays attached at both ends (two edges join the
//!    same two vertices, which a soup cannot express), the extra faces are removed;
//! 6. isolated vertices are removed (optional).
//! Faces that build() skipped cannot be seen in the mesh except as gaps in the face
//! provenance; skipped faces at the very end of the soup are not counted.
//! Throws Error (or Cancelled) leaving `mesh` unchanged.
RepairReport repair(Mesh& mesh, const RepairOptions& options = {}, Progress& progress = Progress::none());

}  // namespace hedge
