// Edge flips toward a Delaunay triangulation (Lawson's algorithm), never across a feature,
// a boundary or an attribute seam.
#pragma once

#include <cstddef>

#include "hedge/mesh.h"
#include "hedge/progress.h"

namespace hedge {

struct DelaunayOptions {
  //! Edges whose two triangles meet at a dihedral angle above this (degrees, 0 for coplanar)
  //! are features and never flipped; a flip whose new edge would exceed it is refused too,
  //! so flips never fold the surface.
  double feature_angle = 30;
  //! An edge is locally Delaunay when its two opposite angles sum to at most π + epsilon
  //! (radians); the slack stops flipping back and forth between co-circular choices.
  double angle_epsilon = 1e-6;
  //! Flips allowed per edge of the mesh before giving up (curved surfaces may not converge).
  double flip_budget_per_edge = 50;
  //! Only edges between two selected faces (the "selected" face channel a host's selection
  //! fills) are flipped.
  bool selection_only = false;
  //! Keep a copy of the mesh while working, so that a cancelled or failed run leaves it as
  //! it was. run_operation() turns it off: its mesh is built for the run and dropped on failure.
  bool keep_input_on_failure = true;
};

//! Why interior edges are left non-Delaunay, counted over the whole mesh after flipping.
struct DelaunayCensus {
  std::size_t interior_edges = 0;
  std::size_t non_delaunay = 0;  //!< all interior edges failing the angle test, whatever the reason
  std::size_t features = 0;      //!< of those: dihedral angle above feature_angle
  std::size_t seams = 0;         //!< of those: corner or face attributes differ across the edge
  //! of those: is_flip_ok refuses (the other diagonal exists, valence 3), or the weld of
  //! build()'s copies would meet the flip (a split non-manifold edge, a new edge already there)
  std::size_t blocked = 0;
  std::size_t folds = 0;       //!< of those: the flipped edge would be a feature or turn a triangle over
  std::size_t unselected = 0;  //!< of those: with selection_only, not between two selected faces
  std::size_t flippable = 0;   //!< of those: none of the above (0 unless the budget ran out)
};

struct DelaunayReport {
  std::size_t flips = 0;
  bool budget_exhausted = false;
  DelaunayCensus before, after;
};

//! Sum of the two angles opposite interior edge e, in radians; both faces must be triangles.
double opposite_angle_sum(const Mesh& mesh, Edge e);

//! Dihedral angle at interior edge e in degrees: 0 when its two faces are coplanar, 180 when
//! folded flat onto each other.
double dihedral_angle_degrees(const Mesh& mesh, Edge e);

//! Counts the interior edges that fail the angle test, by reason (see DelaunayCensus).
//! Precondition: a triangle mesh.
DelaunayCensus delaunay_census(const Mesh& mesh, const DelaunayOptions& options = {});

//! Flips interior edges until each is locally Delaunay or may not be flipped: edges are
//! checked from a stack holding every interior edge, and a flip pushes the four edges around
//! it. On a planar mesh this ends in the Delaunay triangulation (Lawson 1977); on curved
//! surfaces a budget of flip_budget_per_edge × edges stops it, and the report says so.
//!
//! Never flipped: boundary edges, features (dihedral above feature_angle), seams (corner
//! attributes such as UVs or hard-edge normals that differ on the two sides at either end
//! vertex, or face attributes other than "normal" and "quality" that differ between the two
//! faces), flips is_flip_ok refuses, and flips whose new edge would be a feature or turn a
//! triangle over. Attributes: the flip keeps each face with its face attributes and moves corner
//! attributes with their corners (Mesh::flip); face "normal" channels are recomputed.
//!
//! Throws Error, leaving the mesh untouched, when the mesh has faces other than triangles;
//! Cancelled through progress likewise (the flips run on a copy).
DelaunayReport make_delaunay(Mesh& mesh, const DelaunayOptions& options = {}, Progress& progress = Progress::none());

}  // namespace hedge
