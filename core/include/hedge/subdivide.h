// Subdivision surfaces: Loop, Catmull–Clark, √3 and midpoint refinement. Each step builds
// the refined mesh directly into fresh arrays and carries every vertex, corner and face attribute.
#pragma once

#include <cstddef>

#include "hedge/mesh.h"
#include "hedge/progress.h"

namespace hedge {

enum class SubdivisionScheme {
  loop,           //!< Loop 1987: triangles 1 -> 4, C2 box-spline stencils (triangle meshes only)
  catmull_clark,  //!< Catmull & Clark 1978: every n-gon -> n quads (any polygon mesh)
  sqrt3,          //!< Kobbelt 2000: 1 -> 3 split at the centroid, then flip the old edges (triangle meshes only)
  midpoint,       //!< linear: triangles 1 -> 4 at edge midpoints, n-gons -> n quads at the centroid
};

//! "loop", "catmull_clark", "sqrt3", "midpoint"; throws Error naming the choices otherwise.
const char* subdivision_scheme_name(SubdivisionScheme scheme);

struct SubdivideOptions {
  SubdivisionScheme scheme = SubdivisionScheme::loop;
  int iterations = 1;                   //!< refinement steps, 1 or more
  std::size_t max_faces = 200'000'000;  //!< refuse (before starting) results larger than this
  unsigned threads = 0;                 //!< for the stencils and the connectivity; 0: thread_count()
  //! Degrees, 0 to 180: an interior edge whose two faces' normals differ by more is a crease
  //! (kept sharp, see subdivide()). 180: none.
  double crease_angle = 180;
  //! Refine only the selected faces (the "selected" face channel, selection.h); the others come
  //! back as they were, and so does the border between the two (see subdivide()).
  bool selection_only = false;
};

struct SubdivideReport {
  std::size_t faces_before = 0;                    //!< of the input
  std::size_t vertices = 0, edges = 0, faces = 0;  //!< of the result
  int iterations = 0;
  std::size_t crease_edges = 0;  //!< interior edges of the input found sharper than crease_angle
};

//! Face count after `options.iterations` steps of `options.scheme`, without refining.
//! Precondition for loop and sqrt3: a triangle mesh (with selection_only: triangles where
//! selected). (sqrt3 with a crease angle measures the creases, which its trisecting steps cut
//! in three.) With selection_only an upper bound: the unselected faces plus the selected ones
//! counted as if every edge of theirs were split (the closures below make fewer).
std::size_t subdivided_face_count(const Mesh& mesh, const SubdivideOptions& options);

//! Refines the mesh `options.iterations` times.
//!
//! Preconditions: loop and sqrt3 need a triangle mesh (Error otherwise: triangulate first);
//! catmull_clark and midpoint take any polygon mesh. Boundaries follow each scheme's
//! boundary rules: Loop and Catmull–Clark move boundary vertices by the cubic B-spline
//! curve rule (1/8, 6/8, 1/8) and put boundary edge points at the midpoints, so a boundary
//! is a curve refined on its own; √3 follows Kobbelt's rule: boundary edges and vertices
//! stay through odd steps, and every even step (the 2nd, 4th, ... of one call) cuts each
//! boundary edge in three with the univariate ternary stencils ((1, 16, 10)/27 for the new
//! points, (4, 19, 4)/27 for the old), so an even number of iterations refines the
//! boundary as finely as the interior.
//!
//! Creases (options.crease_angle < 180) are found once, on the input; the two halves of a
//! crease edge stay creases in later steps, new edges never are. Loop follows Hoppe et al.
//! 1994 ("Piecewise smooth surface reconstruction"), Catmull–Clark the sharp creases of DeRose,
//! Kass & Truong 1998, with boundary edges counted as crease edges: a crease edge point is the
//! midpoint; a vertex on two crease edges (or a boundary vertex on its two boundary edges)
//! takes the curve rule (1/8, 6/8, 1/8) over the two far ends; a corner (three or more, e.g.
//! a boundary vertex with an interior crease) stays where it is; a dart (one crease) takes
//! the smooth rule. Copies of a vertex split by build() are classified each on its own.
//! sqrt3 treats a crease as a boundary seen from both sides (Kobbelt 2000's boundary rule):
//! a crease is never flipped, it is cut in three on the even steps with the ternary stencils
//! above, a vertex on two sharp edges (creases or boundary edges) stays through odd steps and
//! takes (4, 19, 4)/27 along them on even ones; corners stay, darts are smooth, and where a
//! crease ends (at a corner or a dart) its new points are the linear thirds. midpoint is
//! linear, so creases change nothing there.
//!
//! Attributes: vertex properties are blended with the same stencils as positions (integer
//! channels take the value of the heaviest source); corner properties are blended
//! linearly inside each old face (midpoints, centroids), so seams stay seams; face
//! properties are copied to the child faces; edge properties are copied to the two halves of
//! a split edge. The mesh's own "hedge:" bookkeeping is copied for continuing elements and
//! left at its default for new ones (a new vertex has no source vertex). "normal" channels
//! are refreshed: vertex and face normals recomputed from the refined shape, corner normals
//! (blended per face, so hard edges stay hard) scaled back to unit length.
//!
//! selection_only: only the selected faces are refined; every other face comes back with the
//! same corners at bit-identical positions, so the border between selected and unselected
//! faces stays where it is, closed (selection.h). An edge with an unselected face on either
//! side (on any copy of it, for edges build() split) is a border edge: it is never split,
//! flipped or cut. A vertex with an unselected face around it (or a copy of a split vertex)
//! keeps its position and attributes; the other vertices, edge points and face points take
//! the scheme's usual stencils (which may read border vertices). Selected faces that have
//! border edges are closed without T-junctions:
//! - loop, and midpoint on triangles: a triangle with 3 split edges gives 4 as usual; with 2,
//!   the corner triangle between the two edge points, and the quad left over cut along its
//!   shorter diagonal (measured with the edge points at the midpoints; on a tie, the one from
//!   the unsplit edge's second corner in the face's order), so 3; with 1, the edge point
//!   joined to the opposite corner, so 2; with none it stays as it is.
//! - catmull_clark, and midpoint on polygons: a face point joins every edge point of the face;
//!   each piece runs from one edge point along the rim (corners, unsplit edges included) to the
//!   next and back through the face point, so a piece with an unsplit edge has more than 4
//!   corners. With a single split edge, the face point joins that edge point and the
//!   ((n + 1) / 2, rounded down)-th corner after it along the face (a triangle's opposite
//!   corner, a quad's second): two pieces.
//!   A face with no split edge (all its corners are on the border) stays as it is.
//! - sqrt3: every selected triangle is split 1 -> 3 at its centroid; an old edge is flipped
//!   only between two selected faces; the even steps cut the boundary edges of selected faces
//!   and creases between selected faces, never a border edge. So along the border the
//!   triangles keep the old edge, as along a boundary on odd steps, on every step.
//! Children of a selected face stay selected, so later iterations refine the same region.
//! The pieces along the border keep its whole edges while the selection around them shrinks,
//! so over several iterations they grow long and thin: the price of a border that stays.
//! loop and sqrt3 need only the selected faces to be triangles. Nothing selected: the mesh is
//! returned unchanged.
//!
//! Numbering (on a mesh without deleted elements): old vertices keep their indices; loop,
//! catmull_clark and midpoint put the point of edge e at vertex V + e and face points after
//! those, in face order; sqrt3 puts the point of face f at V + f. With selection_only, the
//! points that are not made (unsplit edges, unselected faces) leave no gap: the others follow
//! in the same order.
//!
//! Throws Error, leaving the mesh untouched, for (selected) polygons under loop/sqrt3, results above
//! options.max_faces, crease_angle outside 0 to 180; Cancelled
//! through progress likewise.
SubdivideReport subdivide(Mesh& mesh, const SubdivideOptions& options, Progress& progress = Progress::none());

}  // namespace hedge
