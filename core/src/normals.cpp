// Face and vertex normals (see normals.h). The vertex pass scatters each face's vector
// area to its corners: every face is visited once, where a per-vertex gather would
// compute each face valence-many times.
#include "hedge/normals.h"

#include <algorithm>
#include <cstring>

#include "hedge/error.h"

namespace hedge {

namespace {

//! Twice the vector area of the loop starting at h0 (cross products of a fan from corner 0).
inline Vec3f twice_area_vector(const Mesh& mesh, Halfedge h0) {
  const Point& p0 = mesh.position(mesh.to_vertex(h0));
  Halfedge h1 = mesh.next(h0);
  Halfedge h2 = mesh.next(h1);
  Vec3f e1 = mesh.position(mesh.to_vertex(h1)) - p0;
  Vec3f sum{};
  for (;;) {
    Vec3f e2 = mesh.position(mesh.to_vertex(h2)) - p0;
    sum += cross(e1, e2);
    h2 = mesh.next(h2);
    if (h2 == h0) break;
    e1 = e2;
  }
  return sum;
}

}  // namespace

Vec3f face_area_vector(const Mesh& mesh, Face f) { return twice_area_vector(mesh, mesh.halfedge(f)) * 0.5f; }

Vec3f face_normal(const Mesh& mesh, Face f) { return normalize(twice_area_vector(mesh, mesh.halfedge(f))); }

std::vector<Vec3f> face_normals(const Mesh& mesh) {
  std::vector<Vec3f> normals(mesh.faces_size());
  for (Face f : mesh.faces()) normals[f.idx()] = face_normal(mesh, f);
  return normals;
}

std::vector<Vec3f> vertex_normals(const Mesh& mesh) {
  std::vector<Vec3f> normals(mesh.vertices_size());
  vertex_normals(mesh, normals);
  return normals;
}

void vertex_normals(const Mesh& mesh, std::span<Vec3f> out) {
  if (out.size() != mesh.vertices_size())
    throw Error("vertex_normals: output has " + std::to_string(out.size()) + " entries, the mesh " +
                std::to_string(mesh.vertices_size()) + " vertices");
  std::fill(out.begin(), out.end(), Vec3f{});
  const auto n_faces = static_cast<Index>(mesh.faces_size());
  const bool check_deleted = mesh.n_faces() != mesh.faces_size();
  for (Index i = 0; i < n_faces; ++i) {
    const Face f(i);
    if (check_deleted && mesh.is_deleted(f)) continue;
    const Halfedge h0 = mesh.halfedge(f);
    const Halfedge h1 = mesh.next(h0);
    const Halfedge h2 = mesh.next(h1);
    const Vertex a = mesh.to_vertex(h0), b = mesh.to_vertex(h1), c = mesh.to_vertex(h2);
    if (mesh.next(h2) == h0) {  // triangle: the common case, no loop
      const Point& pa = mesh.position(a);
      const Vec3f n = cross(mesh.position(b) - pa, mesh.position(c) - pa);
      out[a.idx()] += n;
      out[b.idx()] += n;
      out[c.idx()] += n;
      continue;
    }
    const Vec3f n = twice_area_vector(mesh, h0);
    Halfedge h = h0;
    do {
      out[mesh.to_vertex(h).idx()] += n;
      h = mesh.next(h);
    } while (h != h0);
  }
  for (Vec3f& n : out) n = normalize(n);
}

void refresh_normal_channels(Mesh& mesh, bool vertices, bool faces) {
  auto fill = [](ChannelArray* c, const std::vector<Vec3f>& normals) {
    if (!c || c->scalar() != ScalarType::f32 || c->components() != 3) return;
    for (std::size_t i = 0; i < normals.size() && i < c->size(); ++i)
      std::memcpy(c->element(i), &normals[i], sizeof(Vec3f));
  };
  if (vertices)
    if (ChannelArray* c = mesh.vertex_properties().get_channel("normal")) fill(c, vertex_normals(mesh));
  if (faces)
    if (ChannelArray* c = mesh.face_properties().get_channel("normal")) fill(c, face_normals(mesh));
}

}  // namespace hedge
