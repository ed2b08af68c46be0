// What the subdivision steps share and need not inline (subdivide_refine.h).
#include "subdivide_refine.h"

#include <limits>
#include <numbers>
#include <typeinfo>
#include <utility>
#include <vector>

#include "hedge/error.h"
#include "hedge/normals.h"
#include "hedge/vec.h"

namespace hedge::subdivision {

unsigned threads_for(const std::vector<Target>& all, unsigned threads) {
  for (const Target& t : all)
    if (t.array->type() == typeid(bool)) return 1;
  return threads;
}

std::vector<Target> targets(PropertyContainer& c) {
  std::vector<Target> out;
  for (std::size_t i = 0; i < c.count(); ++i) {
    Target t;
    t.array = &c.at(i);
    t.internal = t.array->is_internal();
    if (t.array->type() == typeid(ChannelArray)) t.channel = static_cast<ChannelArray*>(t.array);
    out.push_back(t);
  }
  return out;
}

void check_index_range(std::size_t vertices, std::size_t edges, std::size_t faces) {
  const std::size_t limit = std::numeric_limits<Index>::max() - 1;
  if (vertices > limit || 2 * edges > limit || faces > limit)
    throw Error("subdivide: the result would have more elements than 32-bit indices can number");
}

void copy_parents(PropertyContainer from, PropertyContainer& to, std::size_t default_slot,
                  const std::vector<Index>& map, std::size_t size) {
  if (from.count()) {
    from.resize(default_slot + 1);
    from.permute(map);
  } else {
    from.resize(size);
  }
  to = std::move(from);
}

std::vector<bool> detect_creases(const Mesh& m, double degrees) {
  const std::vector<Vec3f> normal = face_normals(m);
  std::vector<bool> crease(m.edges_size(), false);
  for (Edge e : m.edges()) {
    if (m.is_boundary(e)) continue;
    const Vec3d n0 = to_double(normal[m.face(Mesh::halfedge(e, 0)).idx()]);
    const Vec3d n1 = to_double(normal[m.face(Mesh::halfedge(e, 1)).idx()]);
    if (sqrnorm(n0) == 0 || sqrnorm(n1) == 0) continue;
    crease[e.idx()] = angle_between(n0, n1) * 180.0 / std::numbers::pi > degrees;
  }
  return crease;
}

std::vector<bool> split_creases(const std::vector<bool>& crease, std::size_t edges_after) {
  std::vector<bool> next(edges_after, false);
  for (std::size_t e = 0; e < crease.size(); ++e) next[2 * e] = next[2 * e + 1] = crease[e];
  return next;
}

}  // namespace hedge::subdivision
