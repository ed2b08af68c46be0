// Hole filling after Liepa 2003: triangulate each boundary loop by dynamic programming,
// refine the patch to the density of its surroundings, and fair it (bi-Laplacian).
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "hedge/mesh.h"
#include "hedge/progress.h"

namespace hedge {

//! Laplacian used by the fairing step.
enum class FairingWeights {
  uniform,    //!< umbrella operator: robust on any triangulation
  cotangent,  //!< cotangent weights over Voronoi areas: follows the geometry, not the sampling
};

struct FillHolesOptions {
  //! Holes with more boundary edges than this are left open (and reported); 0 fills every hole.
  std::size_t max_hole_edges = 0;
  //! Split and relax the patch until its triangles are sized like the surrounding ones.
  bool refine = true;
  //! Move the patch's new vertices to minimise the thin-plate energy (Δ²x = 0) with the
  //! surrounding mesh as boundary condition: a patch that continues the surface smoothly.
  bool fair = true;
  //! Cotangent by default: a consistent Laplace-Beltrami, so a patch in a quadric stays on
  //! it far better than with the umbrella (paraboloid 0.010 vs 0.055 worst error, sphere cap
  //! of 30 degrees 0.002 vs 0.042). The weights are measured on the shape a uniform solve
  //! gives first. Holes bordered by polygons (quads...) use the uniform operator.
  FairingWeights weights = FairingWeights::cotangent;
  //! Loops up to this many edges get the optimal (O(n³)) triangulation; longer loops are
  //! first cut by short balanced diagonals into pieces of at most `piece_edges` edges.
  std::size_t max_optimal_edges = 300;
  std::size_t piece_edges = 64;
  //! At most this many new vertices per hole: a hole so large that triangles the size of
  //! its border would exceed it gets proportionally larger triangles.
  //! The bound keeps the fairing solve (sparse Cholesky, superlinear) to about a second.
  std::size_t max_new_vertices_per_hole = 30000;
  //! Only holes whose every border vertex is selected (the "selected" vertex channel a host's
  //! selection fills; without one, the vertices inside the face selection).
  bool selection_only = false;
};

struct FillHolesReport {
  std::size_t holes_found = 0;  //!< boundary loops before filling (or stretches of them, see holes_on_seams)
  std::size_t holes_filled = 0;
  std::size_t holes_skipped = 0;       //!< left open: the five kinds below
  std::size_t holes_too_large = 0;     //!< more than max_hole_edges edges
  std::size_t holes_not_selected = 0;  //!< with selection_only, a border vertex not selected
  //! the border of a face with no neighbour, or a hole of three edges whose corners have a
  //! face already (filling would double it)
  std::size_t lone_faces = 0;
  std::size_t slits = 0;        //!< loops of two edges joining the same two vertices (no triangle fits)
  std::size_t split_seams = 0;  //!< loops along non-manifold edges build() split: not holes, not counted in holes_found
  //! holes part of whose border is such a split edge (a patch would give it another face).
  //! Where a loop with split edges holds a stretch of other edges that leaves a vertex and
  //! comes back to a copy of it, that stretch is a hole of its own and is filled.
  std::size_t holes_on_seams = 0;
  std::size_t largest_skipped_edges = 0;
  std::size_t triangles_added = 0;
  std::size_t vertices_added = 0;
  std::size_t fairing_failures = 0;  //!< patches left unfaired because the solve failed
  std::vector<std::string> messages;
};

//! Fills the holes of `mesh` (every boundary loop within the size limit, as MeshLab's
//! "Close Holes" does, so the single border of an open sheet is filled too). The patch is
//! triangles; faces around the hole keep their shape. New vertices interpolate the vertex
//! attributes of the corners they are inserted between, new faces copy the face attributes
//! of the nearest face across the hole's border, and corner attributes (e.g. "uv") of the
//! border are carried into the patch and interpolated at new vertices.
//! Throws Error (or Cancelled) leaving `mesh` unchanged.
FillHolesReport fill_holes(Mesh& mesh, const FillHolesOptions& options = {}, Progress& progress = Progress::none());

}  // namespace hedge
