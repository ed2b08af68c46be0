// The report operation: figures that describe a mesh, without changing it.
#pragma once

#include <cstddef>

#include "hedge/geometry.h"
#include "hedge/mesh.h"
#include "hedge/topology.h"

namespace hedge {

struct MeshStatistics {
  TopologyStats topology;
  std::size_t triangles = 0, quads = 0, polygons = 0;  //!< faces by corner count (polygons: 5+)
  std::size_t degenerate_faces = 0;                   //!< faces of (near) zero area
  std::size_t multi_edges = 0;                         //!< edges joining two vertices already joined by another edge
  double edge_length_min = 0, edge_length_mean = 0, edge_length_max = 0, edge_length_stddev = 0;
  double min_angle_degrees = 0;      //!< smallest angle of any triangle
  double mean_min_angle_degrees = 0; //!< mean over triangles of their smallest angle
  double quality_min = 0, quality_mean = 0;  //!< triangle quality 2 r_in / r_out (1 = equilateral)
  double area = 0, volume = 0;               //!< volume is meaningful for closed surfaces
  Vec3d bbox_min{}, bbox_max{};
  double bbox_diagonal = 0;
  std::size_t valence_min = 0, valence_max = 0;
  double valence_irregular_fraction = 0;  //!< interior vertices with valence != 6
};

MeshStatistics mesh_statistics(const Mesh& mesh);

}  // namespace hedge
