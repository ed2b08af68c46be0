// Distances between points and surfaces: an AABB tree over triangles for closest-point
// queries, and a sampled symmetric Hausdorff distance between two meshes.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <span>
#include <vector>

#include "hedge/mesh.h"
#include "hedge/vec.h"

namespace hedge {

//! The point of a triangle nearest to a query point.
struct ClosestPoint {
  Vec3d point{};
  double distance = std::numeric_limits<double>::infinity();
  Index triangle = kInvalidIndex;  //!< index into the tree's triangles; invalid when none was found
  Vec3d barycentric{};             //!< weights of the triangle's corners 0, 1, 2 (sum 1)
  bool found() const { return triangle != kInvalidIndex; }
};

//! Closest point of triangle (a, b, c) to p, with its barycentric coordinates; handles
//! degenerate triangles (it then lies on an edge or a corner).
ClosestPoint closest_point_on_triangle(const Vec3d& p, const Vec3d& a, const Vec3d& b, const Vec3d& c);

//! A bounding-volume hierarchy (axis-aligned boxes, binned surface-area heuristic, flat
//! node array) over a fixed set of triangles. Coordinates are stored as given (float, like
//! mesh positions) so the tree is exact for them; queries are in double precision.
//! Immutable after construction; queries may run concurrently from several threads.
class TriangleTree {
 public:
  TriangleTree() = default;
  //! The faces of a mesh; polygons are fanned from corner 0 and deleted faces skipped.
  //! face(triangle) gives each triangle's face back.
  explicit TriangleTree(const Mesh& mesh);
  //! A triangle soup: positions and corner index triples (checked: throws Error on an
  //! index out of range).
  TriangleTree(std::span<const Point> positions, std::span<const std::array<Index, 3>> triangles);

  std::size_t n_triangles() const { return triangles_.size(); }
  bool empty() const { return triangles_.empty(); }
  //! The mesh face a triangle came from (mesh constructor), else the triangle itself.
  Face face(Index triangle) const { return faces_.empty() ? Face(triangle) : faces_[triangle]; }
  //! Where a triangle lies in the tree's own order, in which triangles near one another
  //! in space mostly are near: queries taken in this order of their hints reuse the
  //! branches the last one brought into cache.
  Index tree_order(Index triangle) const { return position_[triangle]; }
  //! The triangle's corners, in the order given.
  std::array<Vec3d, 3> corners(Index triangle) const;
  //! Bounding box of all triangles.
  Vec3d box_min() const;
  Vec3d box_max() const;

  //! Closest point of all triangles to p. Triangles farther than max_distance are
  //! ignored (the result is not found() when none is nearer); a tight bound prunes more.
  ClosestPoint closest_point(const Vec3d& p, double max_distance = std::numeric_limits<double>::infinity()) const;
  //! As above, starting from a guess: the distance to triangle `hint` (e.g. the answer for
  //! a nearby point) bounds the search from the start, which makes it much cheaper.
  ClosestPoint closest_point_with_hint(const Vec3d& p, Index hint) const;
  //! Closest point among the triangles whose normal (right-hand rule over the corners as
  //! given) has a positive dot product with `direction`; not found() when none is nearer
  //! than max_distance.
  ClosestPoint closest_point_facing(const Vec3d& p, const Vec3d& direction,
                                    double max_distance = std::numeric_limits<double>::infinity()) const;

  //! Heap bytes held.
  std::size_t heap_bytes() const;

 private:
  struct Node {
    // Box as floats: input coordinates are floats, so min/max of them are exact.
    float lo[3], hi[3];
    //! Leaf: first triangle (in tree order); inner node: index of the second child (the
    //! first child follows the node directly).
    Index index;
    Index count;  //!< triangles in a leaf; 0 for an inner node
  };
  struct Triangle {
    Point a, b, c;
  };
  // The tree's arrays, tens of megabytes on a big mesh: on huge pages, and written whole
  // without a fill first (detail::UnsetAllocator).
  template <class T>
  using Array = std::vector<T, detail::UnsetAllocator<T>>;
  void build(Array<Triangle> triangles, Array<Index> original);
  //! With `facing`, only triangles whose normal points to its side (positive dot product).
  void search(const Vec3d& p, ClosestPoint& best, double& best_sq, const Vec3d* facing = nullptr) const;

  Array<Node> nodes_;
  Array<Triangle> triangles_;  //!< in tree (leaf) order
  Array<Index> original_;      //!< tree order -> caller's triangle index
  Array<Index> position_;      //!< caller's triangle index -> tree order
  Array<Face> faces_;          //!< caller's triangle index -> mesh face
};

struct HausdorffOptions {
  //! Random samples on the faces, per face of average area: a face gets samples in
  //! proportion to its area (about density * n_faces in all), stratified inside the face.
  double sample_density = 4.0;
  bool sample_vertices = true;        //!< also measure from every vertex
  bool sample_edge_midpoints = true;  //!< and from the midpoint of every edge
  std::uint64_t seed = 1;             //!< same seed, same samples, same result
  unsigned threads = 0;               //!< worker threads (1 = this thread only, 0 = hedge::thread_count())
};

//! Distances from the samples of one surface to the other surface.
struct OneSidedDistance {
  double max = 0;   //!< largest distance of any sample
  double mean = 0;  //!< mean over the area samples (an estimate of the mean over the
                    //!< surface); over all samples when there are none
  double rms = 0;   //!< root mean square, same samples as mean
  std::size_t samples = 0;
  Vec3d worst_sample{};  //!< the sample that gave max
};

struct HausdorffResult {
  OneSidedDistance a_to_b, b_to_a;
  double max = 0;  //!< symmetric Hausdorff distance: max of both sides
};

//! Sampled distance from the surface `from` to the triangles of `to` (built once and
//! reused, e.g. the original mesh while simplifying).
OneSidedDistance one_sided_distance(const Mesh& from, const TriangleTree& to, const HausdorffOptions& options = {});

//! Sampled symmetric Hausdorff distance between two meshes (vertices, edge midpoints and
//! stratified random points on the faces, both ways). Deterministic for a seed, whatever
//! the number of threads. Throws Error when either mesh has no faces.
HausdorffResult hausdorff(const Mesh& a, const Mesh& b, const HausdorffOptions& options = {});

//! Faces of `mesh` turned over against the surface of `reference`: a face counts when, at
//! three or more of four points inside it (centroid and three points toward its corners), the
//! nearest reference triangle faces the other way (negative dot product of the normals) and
//! no reference triangle facing the face's way lies within half the face's longest edge
//! beyond it (where the reference has two layers that close, a thin part or a sheet seen
//! from both sides, the nearest triangle says nothing). Degenerate faces are not counted.
std::size_t flipped_faces(const Mesh& mesh, const TriangleTree& reference);

}  // namespace hedge
