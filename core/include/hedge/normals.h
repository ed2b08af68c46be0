// Face and vertex normals: area-weighted and polygon-aware (the vector area of a polygon,
// Newell's method), computed in one pass over the faces.
#pragma once

#include <span>
#include <vector>

#include "hedge/mesh.h"

namespace hedge {

//! Vector area of f: normal direction, length = area. For a non-planar polygon this is
//! Newell's normal (the area of its projection is largest across this direction), summed
//! as a fan from corner 0 so small faces far from the origin keep their precision.
Vec3f face_area_vector(const Mesh& mesh, Face f);

//! Unit normal of f, counter-clockwise corners facing the viewer; zero for a degenerate face.
Vec3f face_normal(const Mesh& mesh, Face f);

//! Unit normals of all faces, indexed by face index (faces_size() entries); deleted and
//! degenerate faces get zero.
std::vector<Vec3f> face_normals(const Mesh& mesh);

//! Unit vertex normals, indexed by vertex index (vertices_size() entries): the normalized
//! sum of the vector areas of the faces around each vertex, so big faces count more
//! (area weighting). Isolated and deleted vertices, and vertices whose faces cancel
//! out, get zero. O(corners), one pass over the faces and one over the vertices.
std::vector<Vec3f> vertex_normals(const Mesh& mesh);

//! As above, into caller-owned storage (reused across calls); out.size() must be
//! vertices_size(), throws Error otherwise.
void vertex_normals(const Mesh& mesh, std::span<Vec3f> out);

//! After positions changed: recomputes the hosts' "normal" channels (float x3) of vertices
//! and/or faces from the new shape, so hosts do not show stale shading. Channels of another
//! type are left alone.
void refresh_normal_channels(Mesh& mesh, bool vertices, bool faces);

}  // namespace hedge
