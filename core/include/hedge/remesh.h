// Isotropic remeshing: turns a triangle mesh into one of nearly equilateral triangles of
// a chosen edge length, on the same surface (Botsch & Kobbelt 2004).
#pragma once

#include <cstddef>

#include "hedge/mesh.h"
#include "hedge/progress.h"

namespace hedge {

struct RemeshOptions {
  //! Edge length to reach; 0 means the mean edge length of the input.
  double target_edge_length = 0;
  //! Rounds of split / collapse / flip / smooth / project.
  int iterations = 5;
  //! Edges whose faces meet at a dihedral angle above this (degrees) are features: only
  //! split, never collapsed or flipped; their vertices slide along them, and vertices
  //! where other than two feature edges meet stay fixed. 180 turns feature detection off.
  double feature_angle = 45;
  //! Boundary edges are features (split only) and boundary vertices stay fixed. When
  //! false, boundary edges may also collapse and boundary vertices slide along the boundary.
  bool preserve_boundary = true;
  //! Edge length follows curvature: shorter where the surface bends (down to a quarter of
  //! the target), longer where it is flat (up to twice the target).
  bool adaptive = false;
  //! Refuse (before starting) a target length that would make more triangles than this on
  //! the input's area (about area / (sqrt(3)/4 L^2), as equilateral triangles of side L).
  std::size_t max_faces = 200'000'000;
  //! Only the selected faces (the "selected" face channel a host's selection fills) are
  //! remeshed: edges of faces outside it are never split, collapsed or flipped, and their
  //! vertices stay, so those faces and the border come back as they were.
  bool selection_only = false;
};

struct RemeshReport {
  double target_edge_length = 0;  //!< the length used (resolved when the option was 0)
  std::size_t input_faces = 0, output_faces = 0;
  std::size_t output_vertices = 0;
  std::size_t splits = 0, collapses = 0, flips = 0;
  std::size_t feature_edges = 0;       //!< of the input, by the feature angle
  std::size_t fixed_vertices = 0;      //!< of the input: feature corners, boundary (when preserved), welded copies
  std::size_t triangulated_faces = 0;  //!< polygons of the input split into triangles first
};

//! Remeshes `mesh` in place: per iteration, splits edges longer than 4/3 L, collapses edges
//! shorter than 4/5 L (when no edge longer than 4/3 L results), flips edges toward valence
//! 6 (4 on the boundary), smooths tangentially and projects the vertices back onto the
//! input surface. Polygons are triangulated first. Attributes are carried: vertex, corner
//! and face channels are interpolated on splits, corners are continued on flips and
//! collapses, and vertex channels of moved vertices are resampled on the input surface.
//! Throws Error on bad options and on targets forecast above options.max_faces (and
//! Cancelled when progress asks), leaving the mesh as it was.
RemeshReport remesh(Mesh& mesh, const RemeshOptions& options, Progress& progress = Progress::none());

}  // namespace hedge
