// Translation between MeshLab's mesh (the CMeshO of a MeshModel) and hedge's Soup. Plain
// vcg/MeshModel code with no plugin interface in it, so every MeshLab glue version shares it.
#pragma once

#include <cstddef>

#include "hedge/soup.h"
#include "meshlab_api.h"

namespace hedge::meshlab {

//! The live (not deleted) vertices and faces of `model`, in order, with every attribute its
//! data mask says it holds: vertex normal, colour, quality, texture coordinate and selection;
//! per-wedge texture coordinates (corner "uv") with their texture index (face "material");
//! face colour, quality and selection; named per-vertex and per-face custom attributes
//! (passed through as raw channels). Selection channels exist only when something is selected.
//! A polygonal mesh (MM_POLYGONAL: triangles joined by faux edges) gives its polygons.
Soup soup_from_mesh(const MeshModel& model);

struct MeshWriteReport {
  bool geometry_changed = true;           //!< positions or connectivity differ from the input soup
  std::size_t polygons_triangulated = 0;  //!< faces of more than 3 corners, stored as faux-edge fans
  std::size_t edges_dropped = 0;          //!< vcg edge elements (wireframe) the fresh mesh has no place for
};

//! Replaces the mesh of `model` by `result`: a fresh, compacted CMeshO with the data mask
//! switched on for every channel `result` carries, bounding box and face normals updated, and
//! vertex normals recomputed unless the geometry is exactly that of `input` (then the
//! carried normals stay, so a no-op is bit for bit). Derived data that the change makes stale
//! (vcg adjacency, curvature) is switched off. Only allocation can fail once it has started.
MeshWriteReport write_soup_to_mesh(const Soup& result, const Soup& input, MeshModel& model);

}  // namespace hedge::meshlab
