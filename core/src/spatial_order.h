// Laying a mesh out in memory along a space-filling curve: elements near one another on the
// surface are then near in the arrays, so a walk over a neighbourhood touches few cache lines.
// Algorithms that visit the mesh in index order (remeshing's passes) or region by region
// (decimation's phases) miss the cache far less on such a layout than on a file's order or
// on the order subdivision leaves (every new vertex after all the old ones).
#pragma once

#include <cstdint>

#include "hedge/mesh.h"

namespace hedge::detail {

//! A mesh's normalized frame: the centre of its vertices' bounding box and the box's
//! diagonal (1 when that is zero or not finite). (p - center) / scale lies in the box
//! centred on the origin whose diagonal is 1.
struct Frame {
  Vec3d center;
  double scale = 1;
};
Frame normalized_frame(const Mesh& m);

//! The Morton code of a point of a normalized frame (the bounding box centred on the
//! origin, its diagonal 1): `bits` per axis (at most 10), interleaved, of the grid moved by
//! `offset` (wrapping around).
std::uint32_t morton_cell(const Vec3f& p, double offset, int bits);

//! Renumbers m: vertices along the Morton order of their places, faces along that of their
//! centroids, edges by the new number of their first end. Deleted elements go, as in
//! garbage_collect(). Geometry, attributes and connectivity are unchanged; only the
//! numbering is.
GarbageMaps sort_spatially(Mesh& m, unsigned threads = 0);

}  // namespace hedge::detail
