// Splitting polygons into triangles by their shape: minimum-area dynamic programming over the
// diagonals, or ear clipping in the polygon's best-fit plane; convex or not, planar or not.
#pragma once

#include <cstddef>

#include "hedge/mesh.h"
#include "hedge/progress.h"

namespace hedge {

enum class TriangulationMethod {
  //! The triangulation of least total area (dynamic programming over the diagonals, O(n^3);
  //! ties, as in every planar polygon, go to the one whose worst triangle is best shaped).
  //! Polygons above TriangulateOptions::max_dp_corners are ear-clipped instead.
  min_area,
  //! Ear clipping in the plane of Newell's normal: O(n) for convex polygons, about O(n log n)
  //! for typical non-convex ones (reflex corners are looked up in a tree of boxes).
  ear_clipping,
};

//! "min_area", "ear_clipping"; throws Error naming the choices otherwise.
const char* triangulation_method_name(TriangulationMethod method);

struct TriangulateOptions {
  TriangulationMethod method = TriangulationMethod::min_area;
  std::size_t max_dp_corners = 100;  //!< min_area: larger polygons are ear-clipped
  //! Only the selected polygons (the "selected" face channel a host's selection fills).
  bool selection_only = false;
  //! Keep a copy of the mesh while working, so that a cancelled or failed run leaves it as
  //! it was. run_operation() turns it off: its mesh is built for the run and dropped on failure.
  bool keep_input_on_failure = true;
};

struct TriangulateReport {
  std::size_t polygons = 0;     //!< faces that had more than 3 corners
  std::size_t triangles = 0;    //!< the triangles they became (n - 2 for a polygon of n corners)
  std::size_t ear_clipped = 0;  //!< polygons done by ear clipping (by choice or by size)
  //! Polygons with no triangulation of positively oriented triangles in their plane (their
  //! projection crosses itself, or every valid diagonal exists already as an edge): triangulated
  //! with the constraint on shape relaxed.
  std::size_t relaxed = 0;
  //! Polygons that could not be split at all without doubling an existing edge: a vertex was
  //! added at the centroid of what remained, and triangles fanned around it.
  std::size_t centroid_vertices = 0;
};

//! Splits every face of more than 3 corners (every selected one, with selection_only) into triangles, by
//! Mesh::insert_edge, so each diagonal keeps every invariant. A diagonal is never one that exists already as an edge
//! elsewhere (the mesh stays manifold). In the polygon's plane (Newell's normal) every triangle
//! is counter-clockwise, so the triangles cover exactly the polygon and none is flipped.
//!
//! Attributes: new corners at an existing vertex copy that face's corner value there (UVs stay
//! per face), the new faces copy the polygon's face attributes, vertices are untouched; a
//! centroid vertex (rare, see TriangulateReport) blends its polygon's vertices and corners.
//!
//! Runs on a copy when there is anything to do, so an error or a cancellation leaves the
//! mesh as it was.
TriangulateReport triangulate(Mesh& mesh, const TriangulateOptions& options, Progress& progress = Progress::none());

}  // namespace hedge
