// Laplacian smoothing of vertex positions: uniform, cotangent (Desbrun et al. 1999) and
// Taubin's shrink-free λ|μ filter (Taubin 1995).
#pragma once

#include <cstddef>
#include <string>

#include "hedge/mesh.h"
#include "hedge/progress.h"

namespace hedge {

enum class SmoothingMethod {
  uniform,    //!< move toward the mean of the neighbours (umbrella operator); shrinks the shape
  cotangent,  //!< cotangent-weighted mean (Desbrun et al. 1999): follows the surface, less tangential drift
  taubin,     //!< a λ step then a μ step with the uniform weights (Taubin 1995): smooths without shrinking
};

//! "uniform", "cotangent", "taubin"; throws Error naming the choices otherwise.
const char* smoothing_method_name(SmoothingMethod method);

struct SmoothOptions {
  SmoothingMethod method = SmoothingMethod::uniform;
  int iterations = 10;    //!< 1 or more; Taubin counts one λ step plus one μ step as one iteration
  double strength = 0.5;  //!< λ in (0, 1]: the fraction of the way to the weighted mean per step
  //! Boundary vertices stay where they are; otherwise they are smoothed along their boundary
  //! curve (the mean of their two boundary neighbours), never across the hole.
  bool preserve_boundary = true;
  double pass_band = 0.1;  //!< Taubin's k_PB: μ = -λ / (1 - k_PB λ)
  //! Only selected vertices move (the "selected" vertex channel a host's selection fills; the
  //! vertices inside the selected faces when there is only a face selection).
  bool selection_only = false;
  unsigned threads = 0;  //!< 0: hedge::thread_count()
};

struct SmoothReport {
  int iterations = 0;
  std::size_t moved_vertices = 0;                      //!< vertices free to move (not fixed boundary, not isolated)
  double lambda = 0, mu = 0;                           //!< the steps used (mu only for Taubin)
  double mean_displacement = 0, max_displacement = 0;  //!< from the original positions
  std::string message;                                 //!< non-empty when the strength was limited for stability
};

//! Smooths the positions in `options.iterations` Jacobi steps (all vertices move at once, from
//! the previous step's positions). Connectivity and every property stay as they are; only
//! positions change, and the vertex and face "normal" channels, recomputed from the new shape
//! (corner normals are kept: they may carry hard edges).
//!
//! Cotangent weights are recomputed every step from the current shape, per edge
//! (cot α + cot β) / 2 with each cotangent clamped to ±cot(3°) and negative edge weights set
//! to 0, then normalized by the vertex's weight sum; a vertex whose weights all vanish uses
//! the uniform mean. In polygons, the angle opposite an edge is taken at the polygon's centroid.
//! Taubin steps stay stable for λ up to about 0.68 (μ step amplification on the highest
//! frequencies); larger strengths are limited to that, and the report says so.
//!
//! Throws Error for strength outside (0, 1] or iterations < 1; Cancelled through progress;
//! either way the mesh is left untouched.
SmoothReport smooth(Mesh& mesh, const SmoothOptions& options, Progress& progress = Progress::none());

}  // namespace hedge
