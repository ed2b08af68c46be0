// Decimation: quadric error metric edge collapse (Garland & Heckbert 1997), carrying every
// vertex and per-corner attribute, keeping boundaries and UV seams, refusing fold-overs.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "hedge/mesh.h"
#include "hedge/progress.h"

namespace hedge {

struct DecimateOptions {
  //! Number of triangles to reach; 0 means "use target_ratio".
  std::size_t target_faces = 0;
  //! Fraction of the triangles to keep (0 to 1) when target_faces is 0.
  double target_ratio = 0.5;
  //! Stop before any collapse whose error exceeds this fraction of the bounding-box
  //! diagonal; 0 = no limit. The error of a collapse is the area-weighted RMS distance of
  //! the new vertex to the planes of the original triangles merged into it.
  double max_error = 0;
  //! Boundary vertices never move; boundary edges only collapse along the boundary, into
  //! one of their two end points; boundary loops keep their number.
  bool preserve_boundary = true;
  //! Per-corner attributes (UVs, corner normals and colours) stay continuous: a vertex on
  //! a seam only collapses along the seam, seam junctions stay, and the merged corners
  //! ("wedges") are interpolated consistently on both sides.
  bool preserve_uv_seams = true;
  //! Refuse collapses that flip a triangle (turn its normal by 90 degrees or more) or leave
  //! it degenerate.
  bool prevent_flips = true;
  //! With prevent_flips, the rotation of a triangle's normal one collapse may cause at
  //! first; when no collapse is left within it, the limit relaxes to 90 degrees (flips stay
  //! refused). Small turns per collapse keep folds from building up over many collapses:
  //! 30 degrees lowers the Hausdorff distance on the dragon by a fifth.
  double max_normal_change_degrees = 30;
  //! Refuse collapses that create a triangle of quality (2 r_in / r_out) below this, unless
  //! the triangles they replace were already worse.
  double min_quality = 0;
  //! Only the selected faces (the "selected" face channel a host's selection fills) change:
  //! vertices with a face outside the selection neither move nor go, and target_ratio applies
  //! to the selected faces (target_faces stays a count of all faces).
  bool selection_only = false;
  //! A vertex attribute (one number per vertex; in Blender a vertex group, in MeshLab
  //! "quality") saying where detail matters: a vertex of weight w counts its error
  //! 1 + weight_strength * w times, so weighted regions keep more triangles. Weights are
  //! taken as 0 to 1; values outside that range are first rescaled from their minimum and
  //! maximum. Empty: no weights.
  std::string weight_attribute;
  double weight_strength = 10;
  //! A vertex attribute whose non-zero vertices are locked: they neither move nor go.
  //! Empty: none.
  std::string lock_attribute;
  //! Threads for the set-up and for the collapses, which run region by region on all of
  //! them until the last few; the result is the same for any count. 0: hedge::thread_count().
  unsigned threads = 0;
  //! Keep a copy of the mesh while working, so that a cancelled or failed run leaves it as
  //! it was. run_operation() turns it off: its mesh is built for the run and dropped on failure.
  bool keep_input_on_failure = true;
};

struct DecimateReport {
  std::size_t faces_before = 0, faces_after = 0;
  std::size_t vertices_before = 0, vertices_after = 0;
  std::size_t target_faces = 0;
  std::size_t triangulated_faces = 0;  //!< polygons split into triangles first
  std::size_t collapses = 0;
  std::size_t locked_vertices = 0;  //!< by lock_attribute
  //! Largest error of a collapse done, as a fraction of the bounding-box diagonal.
  double max_error = 0;
  //! Why it stopped: "target reached", "max_error reached", "no legal collapse left",
  //! "target is odd on a closed surface" (stopped one face above it), "nothing to do".
  std::string stopped_by;
  std::vector<std::string> messages;  //!< what a user should know about the weights
};

//! Simplifies a triangle mesh to options.target_faces triangles (or target_ratio of them)
//! by collapsing the edge of least quadric error first (Garland & Heckbert, "Surface
//! Simplification Using Quadric Error Metrics", SIGGRAPH 1997), placing the new vertex at
//! the quadric's minimum (over the edge when that is singular). Polygons are triangulated
//! first. Vertex properties are interpolated at the new vertex; per-corner properties are
//! interpolated per wedge (Hoppe 1999), so UV charts stay continuous. Other shapes of the
//! mesh ("shape:" vertex channels, soup.h) weigh in: each vertex also has a quadric of its
//! faces in each shape, a collapse costs the sum of its errors in all of them (placed by the
//! mesh's own quadric, its offsets blended like attributes), and the error reported and
//! compared with max_error is the mean over the shapes. Hits the target
//! exactly when the topology allows it: an interior collapse removes two triangles, a
//! boundary one removes one, so on closed surfaces an odd target stops one triangle above.
//! Throws Error on bad options, leaving the mesh untouched; when cancelled through
//! `progress` the mesh is restored as it was.
DecimateReport decimate(Mesh& mesh, const DecimateOptions& options, Progress& progress = Progress::none());

}  // namespace hedge
