// Laying a mesh out in memory along a space-filling curve: elements near one another on the
// surface are then near in the arrays, so a walk over a neighbourhood touches few cache lines.
// Algorithms that visit the mesh in index order (remeshing's passes) or region by region
// (decimation's phases) miss the cache far less on such a layout than on a file's order or
// on the order subdivision leaves (every new vertex after all the old ones).
#pragma once

#include <cstdint>
#include <vector>

#include "hedge/detail/memory.h"
#include "hedge/mesh.h"

namespace hedge::detail {

//! A mesh's normalized frame: the centre of its vertices' bounding box and the box's
//! diagonal (1 when that is zero or not finite). (p - center) / scale lies in the box
//! centred on the origin whose diagonal is 1. On up to `threads` threads (0: all).
struct Frame {
  Vec3d center;
  double scale = 1;
};
Frame normalized_frame(const Mesh& m, unsigned threads = 0);

//! The Morton code of a point of a normalized frame (the bounding box centred on the
//! origin, its diagonal 1): `bits` per axis (at most 10), interleaved, of the grid moved by
//! `offset` (wrapping around).
std::uint32_t morton_cell(const Vec3f& p, double offset, int bits);

//! Renumbers m: vertices along the Morton order of their places, faces and edges by the new
//! number of their first vertex. Deleted elements go, as in garbage_collect(). Geometry,
//! attributes and connectivity are unchanged; only the numbering is.
GarbageMaps sort_spatially(Mesh& m, unsigned threads = 0);

//! Four partitions of a mesh's vertices into regions, for work done region by region on
//! several threads in phases (decimation's collapses, remeshing's collapses and flips).
//! Regions are runs of about equal numbers of vertices along the Morton order of two grids a
//! third of the box apart (so that the great planes of one grid's octree, where regions
//! always part, are not the other's), each run shifted by half a run or not. Phases take
//! them in turn (phase(k)), so that what lay on one phase's borders lies inside the next
//! phase's regions.
class RegionPartitions {
 public:
  static constexpr std::uint16_t kNone = 0xffff;  //!< no region: never a vertex's

  RegionPartitions() = default;
  //! Of m's vertices, placed by (position - center) * inv_scale (a normalized frame; deleted
  //! vertices too, wherever they were left). `regions` is clamped to [1, kNone - 1].
  RegionPartitions(const Mesh& m, const Vec3d& center, double inv_scale, std::size_t regions, unsigned threads);

  std::size_t regions() const { return regions_; }
  //! How many vertices the partitions cover.
  std::size_t size() const { return maps_[0].size(); }
  //! Covers one more vertex (vertex size()), putting it in vertex `like`'s regions: a vertex
  //! added to a mesh in the middle of an edge goes where one of its ends is.
  void append_like(std::size_t like) {
    for (auto& map : maps_) map.push_back(map[like]);
  }
  //! Phase k's map from a vertex to its region.
  const std::uint16_t* phase(int k) const { return maps_[2 * (k % 2) + (k % 4 >= 2)].data(); }

 private:
  std::size_t regions_ = 0;
  // Left unset by resize(): each is written whole on all threads, which share the first touch.
  std::vector<std::uint16_t, UnsetAllocator<std::uint16_t>> maps_[4];
};

}  // namespace hedge::detail
