// CMeshO <-> Soup: which MeshLab data becomes which channel, and how a result becomes a
// fresh MeshLab mesh. See cmesh_soup.h.
#include "cmesh_soup.h"

#include <vcg/complex/algorithms/update/bounding.h>
#include <vcg/complex/algorithms/update/normal.h>
#include <vcg/complex/allocate.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <limits>
#include <set>
#include <string>
#include <typeindex>
#include <unordered_map>
#include <vector>

#include "hedge/error.h"

namespace hedge::meshlab {
namespace {

constexpr std::uint32_t kNoIndex = std::numeric_limits<std::uint32_t>::max();

// Channels with a meaning this file handles by hand; custom attributes of the same name would
// collide with them and are left out.
bool is_standard_channel(const std::string& name, Domain domain) {
  switch (domain) {
    case Domain::vertex:
      return name == "normal" || name == "color" || name == "quality" || name == "uv" || name == "selected";
    case Domain::face:
      return name == "color" || name == "quality" || name == "selected" || name == "material";
    case Domain::corner:
      return name == "uv";
  }
  return false;
}

// A vcg attribute as a channel: known types keep their meaning (so hedge interpolates floats);
// anything else travels as opaque bytes, which hedge copies from the heaviest source.
struct ChannelType {
  ScalarType scalar;
  int components;
};
ChannelType channel_type_of(const vcg::PointerToAttribute& attribute, std::size_t size) {
  const std::type_index type = attribute._type;
  if (type == typeid(float)) return {ScalarType::f32, 1};
  if (type == typeid(double)) return {ScalarType::f64, 1};
  if (type == typeid(int)) return {ScalarType::i32, 1};
  if (type == typeid(vcg::Point2f)) return {ScalarType::f32, 2};
  if (type == typeid(vcg::Point3f)) return {ScalarType::f32, 3};
  if (type == typeid(vcg::Point3d)) return {ScalarType::f64, 3};
  if (type == typeid(vcg::Color4b)) return {ScalarType::u8, 4};
  return {ScalarType::u8, static_cast<int>(size)};
}

// Named custom attributes of one element kind -> channels. `live` lists the element indices kept.
void read_attributes(const std::set<vcg::PointerToAttribute>& attributes, Domain domain,
                     const std::vector<std::size_t>& live, Soup& soup) {
  for (const vcg::PointerToAttribute& attribute : attributes) {
    // Unnamed attributes are other code's scratch space, not data.
    if (attribute._name.empty() || is_standard_channel(attribute._name, domain) || soup.find(attribute._name, domain))
      continue;
    const auto* handle = static_cast<const vcg::SimpleTempDataBase*>(attribute._handle);
    const std::size_t size = handle->SizeOf();
    const ChannelType type = channel_type_of(attribute, size);
    Channel& channel = soup.add_channel(attribute._name, domain, type.scalar, type.components);
    if (channel.stride() != size) {  // a known type of an unexpected size: keep the bytes
      channel.scalar = ScalarType::u8;
      channel.components = static_cast<int>(size);
      channel.data.resize(live.size() * size);
    }
    for (std::size_t i = 0; i < live.size(); ++i)
      std::memcpy(channel.data.data() + i * size, handle->At(live[i]), size);
  }
}

// Channels that are not standard and match a named attribute of the same size -> that attribute.
// `source` maps each element written to its element in the channel.
void write_attributes(const Soup& result, std::set<vcg::PointerToAttribute>& attributes, Domain domain,
                      const std::vector<std::uint32_t>& source) {
  for (const Channel& channel : result.channels) {
    if (channel.domain != domain || is_standard_channel(channel.name, domain)) continue;
    vcg::PointerToAttribute key;
    key._name = channel.name;
    auto it = attributes.find(key);
    if (it == attributes.end()) continue;
    auto* handle = static_cast<vcg::SimpleTempDataBase*>(it->_handle);
    if (handle->SizeOf() != channel.stride()) continue;
    for (std::size_t i = 0; i < source.size(); ++i)
      std::memcpy(handle->At(i), channel.data.data() + source[i] * channel.stride(), channel.stride());
  }
}

// A channel of the expected layout and length, or null.
template <class T>
const T* typed_channel(const Soup& soup, const char* name, Domain domain, ScalarType scalar, int components) {
  const Channel* channel = soup.find(name, domain);
  if (!channel || channel->scalar != scalar || channel->components != components ||
      channel->count() != soup.domain_size(domain))
    return nullptr;
  return channel->as<T>();
}

// Colours as MeshLab holds them (RGBA bytes); a float colour channel is converted.
std::vector<vcg::Color4b> colors_of(const Soup& soup, Domain domain) {
  std::vector<vcg::Color4b> colors;
  const std::size_t n = soup.domain_size(domain);
  if (const auto* bytes = typed_channel<std::uint8_t>(soup, "color", domain, ScalarType::u8, 4)) {
    colors.resize(n);
    for (std::size_t i = 0; i < n; ++i)
      colors[i] = vcg::Color4b(bytes[4 * i], bytes[4 * i + 1], bytes[4 * i + 2], bytes[4 * i + 3]);
  } else if (const auto* floats = typed_channel<float>(soup, "color", domain, ScalarType::f32, 4)) {
    colors.resize(n);
    auto byte = [](float x) { return static_cast<unsigned char>(std::clamp(x, 0.0f, 1.0f) * 255.0f + 0.5f); };
    for (std::size_t i = 0; i < n; ++i)
      colors[i] =
          vcg::Color4b(byte(floats[4 * i]), byte(floats[4 * i + 1]), byte(floats[4 * i + 2]), byte(floats[4 * i + 3]));
  }
  return colors;
}

struct CornerWedge {
  std::size_t face;
  std::uint8_t wedge;
};

// MeshLab stores a polygon as triangles joined by faux edges. Joins every two triangles that
// share a faux edge and walks each group's real edges into one polygon, starting at its first
// triangle's first real edge (where a fan written by write_soup_to_mesh starts, so polygons
// survive a chain of Hedge filters). A group whose real edges are not one simple loop stays
// separate triangles. Polygons come in the order of their first triangle.
void gather_polygons(const CMeshO& m, const std::vector<std::size_t>& triangles,
                     const std::vector<std::uint32_t>& triangle_vertices, Soup& soup,
                     std::vector<std::size_t>& live_faces, std::vector<CornerWedge>& corner_wedges) {
  const std::size_t n = triangles.size();
  std::vector<std::uint32_t> parent(n);
  for (std::size_t t = 0; t < n; ++t) parent[t] = static_cast<std::uint32_t>(t);
  auto root = [&](std::uint32_t t) {
    while (parent[t] != t) t = parent[t] = parent[parent[t]];
    return t;
  };
  std::vector<std::uint8_t> joined(3 * n, 0);                // this faux edge joins two triangles
  std::unordered_map<std::uint64_t, std::uint32_t> waiting;  // faux edge -> the first triangle side met
  constexpr std::uint32_t kTaken = kNoIndex;
  for (std::size_t t = 0; t < n; ++t)
    for (int j = 0; j < 3; ++j) {
      if (!m.face[triangles[t]].IsF(j)) continue;
      const std::uint32_t a = triangle_vertices[3 * t + j], b = triangle_vertices[3 * t + (j + 1) % 3];
      const std::uint64_t key = (std::uint64_t(std::min(a, b)) << 32) | std::max(a, b);
      const auto side = static_cast<std::uint32_t>(3 * t + j);
      auto [it, first] = waiting.try_emplace(key, side);
      if (first || it->second == kTaken) continue;  // a third faux side on one edge joins nothing
      joined[it->second] = joined[side] = 1;
      parent[root(it->second / 3)] = root(static_cast<std::uint32_t>(t));
      it->second = kTaken;
    }

  // Members of each group in triangle order (counting sort by root).
  std::vector<std::uint32_t> group_start(n + 1, 0), members(n);
  for (std::size_t t = 0; t < n; ++t) ++group_start[root(static_cast<std::uint32_t>(t)) + 1];
  for (std::size_t r = 0; r < n; ++r) group_start[r + 1] += group_start[r];
  std::vector<std::uint32_t> fill(group_start.begin(), group_start.end() - 1);
  for (std::size_t t = 0; t < n; ++t)
    members[fill[root(static_cast<std::uint32_t>(t))]++] = static_cast<std::uint32_t>(t);

  auto emit_triangle = [&](std::uint32_t t) {
    live_faces.push_back(triangles[t]);
    soup.face_sizes.push_back(3);
    for (std::uint8_t j = 0; j < 3; ++j) {
      soup.corners.push_back(triangle_vertices[3 * t + j]);
      corner_wedges.push_back({triangles[t], j});
    }
  };
  struct Side {
    std::uint32_t from, to, triangle;
    std::uint8_t wedge;
  };
  std::vector<Side> sides;
  std::vector<std::uint8_t> walked;
  for (std::size_t t = 0; t < n; ++t) {
    const std::uint32_t r = root(static_cast<std::uint32_t>(t));
    const std::uint32_t* first = members.data() + group_start[r];
    const std::uint32_t* last = members.data() + group_start[r + 1];
    if (*first != t) continue;  // emitted with its group's first triangle
    if (last - first == 1) {
      emit_triangle(static_cast<std::uint32_t>(t));
      continue;
    }
    sides.clear();
    for (const std::uint32_t* g = first; g != last; ++g)
      for (std::uint8_t j = 0; j < 3; ++j)
        if (!joined[3 * *g + j])
          sides.push_back({triangle_vertices[3 * *g + j], triangle_vertices[3 * *g + (j + 1) % 3], *g, j});
    // Walk from the first real side; every step must find exactly one unwalked side.
    walked.assign(sides.size(), 0);
    std::vector<std::size_t> loop;
    std::size_t at = 0;
    bool simple = !sides.empty();
    while (simple && !walked[at]) {
      walked[at] = 1;
      loop.push_back(at);
      std::size_t next = sides.size();
      for (std::size_t k = 0; k < sides.size(); ++k)
        if (sides[k].from == sides[at].to) {
          if (next != sides.size()) simple = false;  // the boundary touches itself
          next = k;
        }
      if (next == sides.size()) simple = false;
      at = next;
    }
    simple = simple && at == 0 && loop.size() == sides.size();
    if (!simple) {
      for (const std::uint32_t* g = first; g != last; ++g) emit_triangle(*g);
      continue;
    }
    live_faces.push_back(triangles[t]);
    soup.face_sizes.push_back(static_cast<std::uint32_t>(loop.size()));
    for (std::size_t k : loop) {
      soup.corners.push_back(sides[k].from);
      corner_wedges.push_back({triangles[sides[k].triangle], sides[k].wedge});
    }
  }
}

bool same_geometry(const Soup& a, const Soup& b) {
  return a.positions.size() == b.positions.size() && a.face_sizes == b.face_sizes && a.corners == b.corners &&
         std::memcmp(a.positions.data(), b.positions.data(), a.positions.size() * sizeof(Point)) == 0;
}

}  // namespace

Soup soup_from_mesh(const MeshModel& model) {
  const CMeshO& m = model.cm;
  Soup soup;

  std::vector<std::uint32_t> vertex_index(m.vert.size(), kNoIndex);
  std::vector<std::size_t> live_vertices;
  live_vertices.reserve(static_cast<std::size_t>(std::max(m.vn, 0)));
  for (std::size_t i = 0; i < m.vert.size(); ++i)
    if (!m.vert[i].IsD()) {
      vertex_index[i] = static_cast<std::uint32_t>(live_vertices.size());
      live_vertices.push_back(i);
    }
  soup.positions.resize(live_vertices.size());
  for (std::size_t i = 0; i < live_vertices.size(); ++i) {
    const auto& p = m.vert[live_vertices[i]].cP();
    soup.positions[i] = Point{{p[0], p[1], p[2]}};
  }

  // A face pointing at a deleted or foreign vertex is a broken mesh: refused, as the core
  // refuses an index out of range (MeshLab 2020.09's OFF and PLY readers keep such faces,
  // pointing past the end of the vertex array).
  auto vertex_of = [&](const CFaceO& f, int j) -> std::uint32_t {
    const CVertexO* v = f.cV(j);
    const std::size_t face = static_cast<std::size_t>(&f - &m.face.front());
    if (v == nullptr) throw Error("face " + std::to_string(face) + " has no vertex " + std::to_string(j));
    const std::ptrdiff_t index = v - m.vert.data();
    if (index < 0 || static_cast<std::size_t>(index) >= m.vert.size())
      throw Error("face " + std::to_string(face) + " uses vertex " + std::to_string(index) + " but there are only " +
                  std::to_string(m.vert.size()) + " vertices (an index out of range in the file)");
    if (vertex_index[static_cast<std::size_t>(index)] == kNoIndex)
      throw Error("face " + std::to_string(face) + " uses vertex " + std::to_string(index) + ", which is deleted");
    return vertex_index[static_cast<std::size_t>(index)];
  };
  std::vector<std::size_t> triangles;
  std::vector<std::uint32_t> triangle_vertices;  // 3 soup vertices per triangle
  triangles.reserve(static_cast<std::size_t>(std::max(m.fn, 0)));
  triangle_vertices.reserve(3 * static_cast<std::size_t>(std::max(m.fn, 0)));
  for (std::size_t i = 0; i < m.face.size(); ++i) {
    const CFaceO& f = m.face[i];
    if (f.IsD()) continue;
    const std::uint32_t a = vertex_of(f, 0), b = vertex_of(f, 1), c = vertex_of(f, 2);
    triangles.push_back(i);
    triangle_vertices.insert(triangle_vertices.end(), {a, b, c});
  }
  // Soup faces: the triangles, or for a polygonal mesh the polygons their faux edges make.
  // live_faces[f] is the MeshLab face soup face f takes its attributes from (a polygon's first
  // triangle); wedge_of(c) the face and wedge soup corner c takes its own from, listed only
  // for polygons (a triangle's corners are its wedges in order).
  std::vector<std::size_t> live_faces;
  std::vector<CornerWedge> corner_wedges;
  const bool polygonal = model.hasDataMask(MeshModel::MM_POLYGONAL);
  if (polygonal) {
    gather_polygons(m, triangles, triangle_vertices, soup, live_faces, corner_wedges);
  } else {
    live_faces = std::move(triangles);
    soup.corners = std::move(triangle_vertices);
    soup.face_sizes.assign(live_faces.size(), 3);
  }
  auto wedge_of = [&](std::size_t c) -> CornerWedge {
    return polygonal ? corner_wedges[c] : CornerWedge{live_faces[c / 3], static_cast<std::uint8_t>(c % 3)};
  };

  const std::size_t nv = live_vertices.size(), nf = live_faces.size();
  if (model.hasDataMask(MeshModel::MM_VERTNORMAL)) {
    auto* n = soup.add_channel("normal", Domain::vertex, ScalarType::f32, 3).as<float>();
    for (std::size_t i = 0; i < nv; ++i)
      for (int k = 0; k < 3; ++k) n[3 * i + k] = m.vert[live_vertices[i]].cN()[k];
  }
  if (model.hasDataMask(MeshModel::MM_VERTCOLOR)) {
    auto* c = soup.add_channel("color", Domain::vertex, ScalarType::u8, 4).as<std::uint8_t>();
    for (std::size_t i = 0; i < nv; ++i)
      for (int k = 0; k < 4; ++k) c[4 * i + k] = m.vert[live_vertices[i]].cC()[k];
  }
  if (model.hasDataMask(MeshModel::MM_VERTQUALITY)) {
    auto* q = soup.add_channel("quality", Domain::vertex, ScalarType::f32, 1).as<float>();
    for (std::size_t i = 0; i < nv; ++i) q[i] = m.vert[live_vertices[i]].cQ();
  }
  if (model.hasDataMask(MeshModel::MM_VERTTEXCOORD) && m.vert.IsTexCoordEnabled()) {
    auto* uv = soup.add_channel("uv", Domain::vertex, ScalarType::f32, 2).as<float>();
    for (std::size_t i = 0; i < nv; ++i) {
      uv[2 * i] = m.vert[live_vertices[i]].cT().U();
      uv[2 * i + 1] = m.vert[live_vertices[i]].cT().V();
    }
  }
  if (std::any_of(live_vertices.begin(), live_vertices.end(), [&](std::size_t i) { return m.vert[i].IsS(); })) {
    auto* s = soup.add_channel("selected", Domain::vertex, ScalarType::u8, 1).as<std::uint8_t>();
    for (std::size_t i = 0; i < nv; ++i) s[i] = m.vert[live_vertices[i]].IsS() ? 1 : 0;
  }

  if (model.hasDataMask(MeshModel::MM_FACECOLOR) && m.face.IsColorEnabled()) {
    auto* c = soup.add_channel("color", Domain::face, ScalarType::u8, 4).as<std::uint8_t>();
    for (std::size_t i = 0; i < nf; ++i)
      for (int k = 0; k < 4; ++k) c[4 * i + k] = m.face[live_faces[i]].cC()[k];
  }
  if (model.hasDataMask(MeshModel::MM_FACEQUALITY) && m.face.IsQualityEnabled()) {
    auto* q = soup.add_channel("quality", Domain::face, ScalarType::f32, 1).as<float>();
    for (std::size_t i = 0; i < nf; ++i) q[i] = m.face[live_faces[i]].cQ();
  }
  if (std::any_of(live_faces.begin(), live_faces.end(), [&](std::size_t i) { return m.face[i].IsS(); })) {
    auto* s = soup.add_channel("selected", Domain::face, ScalarType::u8, 1).as<std::uint8_t>();
    for (std::size_t i = 0; i < nf; ++i) s[i] = m.face[live_faces[i]].IsS() ? 1 : 0;
  }
  if (model.hasDataMask(MeshModel::MM_WEDGTEXCOORD) && m.face.IsWedgeTexCoordEnabled()) {
    auto* uv = soup.add_channel("uv", Domain::corner, ScalarType::f32, 2).as<float>();
    for (std::size_t c = 0; c < soup.corners.size(); ++c) {
      const CornerWedge at = wedge_of(c);
      const auto& wedge = m.face[at.face].cWT(at.wedge);
      uv[2 * c] = wedge.U();
      uv[2 * c + 1] = wedge.V();
    }
    const bool textured =
        std::any_of(live_faces.begin(), live_faces.end(), [&](std::size_t i) { return m.face[i].cWT(0).N() != 0; });
    // MeshLab keeps the texture index per wedge; hedge keeps one per face, the first wedge's.
    if (textured) {
      auto* material = soup.add_channel("material", Domain::face, ScalarType::i32, 1).as<std::int32_t>();
      for (std::size_t i = 0; i < nf; ++i) material[i] = m.face[live_faces[i]].cWT(0).N();
    }
  }

  read_attributes(m.vert_attr, Domain::vertex, live_vertices, soup);
  read_attributes(m.face_attr, Domain::face, live_faces, soup);
  return soup;
}

MeshWriteReport write_soup_to_mesh(const Soup& result, const Soup& input, MeshModel& model) {
  MeshWriteReport report;
  report.geometry_changed = !same_geometry(result, input);

  // Everything read from the result is prepared before the mesh is touched.
  const std::size_t nv = result.n_vertices(), nf = result.n_faces();
  const auto* normals = typed_channel<float>(result, "normal", Domain::vertex, ScalarType::f32, 3);
  const std::vector<vcg::Color4b> vertex_colors = colors_of(result, Domain::vertex);
  const auto* vertex_quality = typed_channel<float>(result, "quality", Domain::vertex, ScalarType::f32, 1);
  const auto* vertex_uv = typed_channel<float>(result, "uv", Domain::vertex, ScalarType::f32, 2);
  const auto* vertex_selected = typed_channel<std::uint8_t>(result, "selected", Domain::vertex, ScalarType::u8, 1);
  const std::vector<vcg::Color4b> face_colors = colors_of(result, Domain::face);
  const auto* face_quality = typed_channel<float>(result, "quality", Domain::face, ScalarType::f32, 1);
  const auto* face_selected = typed_channel<std::uint8_t>(result, "selected", Domain::face, ScalarType::u8, 1);
  const auto* material = typed_channel<std::int32_t>(result, "material", Domain::face, ScalarType::i32, 1);
  const auto* corner_uv = typed_channel<float>(result, "uv", Domain::corner, ScalarType::f32, 2);

  // MeshLab holds triangles; a polygon becomes a fan whose inner edges are faux, which is how
  // MeshLab marks polygonal faces. triangle_face[t] is the result face triangle t came from.
  std::vector<std::uint32_t> triangle_face;
  std::vector<std::uint32_t> triangle_corners;  // 3 result corner indices per triangle
  triangle_face.reserve(nf);
  triangle_corners.reserve(3 * nf);
  const std::vector<std::size_t> offsets = result.face_offsets();
  for (std::size_t f = 0; f < nf; ++f) {
    const std::uint32_t size = result.face_sizes[f];
    if (size > 3) ++report.polygons_triangulated;
    const auto first = static_cast<std::uint32_t>(offsets[f]);
    for (std::uint32_t k = 1; k + 1 < size; ++k) {
      triangle_face.push_back(static_cast<std::uint32_t>(f));
      triangle_corners.insert(triangle_corners.end(), {first, first + k, first + k + 1});
    }
  }
  const std::size_t nt = triangle_face.size();
  std::vector<std::uint32_t> vertex_source(nv);
  for (std::size_t i = 0; i < nv; ++i) vertex_source[i] = static_cast<std::uint32_t>(i);

  int carried = 0;  // what the fresh mesh holds
  if (!vertex_colors.empty()) carried |= MeshModel::MM_VERTCOLOR;
  if (vertex_quality) carried |= MeshModel::MM_VERTQUALITY;
  if (vertex_uv) carried |= MeshModel::MM_VERTTEXCOORD;
  if (!face_colors.empty()) carried |= MeshModel::MM_FACECOLOR;
  if (face_quality) carried |= MeshModel::MM_FACEQUALITY;
  if (corner_uv) carried |= MeshModel::MM_WEDGTEXCOORD;
  if (report.polygons_triangulated) carried |= MeshModel::MM_POLYGONAL;
  // Attribute data the result does not carry, and derived data the new mesh would make stale.
  int dropped = (MeshModel::MM_VERTCOLOR | MeshModel::MM_VERTQUALITY | MeshModel::MM_VERTTEXCOORD |
                 MeshModel::MM_FACECOLOR | MeshModel::MM_FACEQUALITY | MeshModel::MM_WEDGTEXCOORD) &
                ~carried;
  dropped |= MeshModel::MM_FACEFACETOPO | MeshModel::MM_VERTFACETOPO;
  if (report.geometry_changed)
    dropped |= MeshModel::MM_VERTCURV | MeshModel::MM_VERTCURVDIR | MeshModel::MM_FACECURVDIR;

  CMeshO& m = model.cm;
  report.edges_dropped = static_cast<std::size_t>(std::max(m.en, 0));
  m.Clear();
  model.clearDataMask(dropped & ~carried);
  model.updateDataMask(carried);
  vcg::tri::Allocator<CMeshO>::AddVertices(m, nv);
  vcg::tri::Allocator<CMeshO>::AddFaces(m, nt);

  int selected_vertices = 0, selected_faces = 0;
  for (std::size_t i = 0; i < nv; ++i) {
    CVertexO& v = m.vert[i];
    v.P() = Point3m(result.positions[i][0], result.positions[i][1], result.positions[i][2]);
    if (!vertex_colors.empty()) v.C() = vertex_colors[i];
    if (vertex_quality) v.Q() = vertex_quality[i];
    if (vertex_uv) v.T() = vcg::TexCoord2f(vertex_uv[2 * i], vertex_uv[2 * i + 1]);
    if (vertex_selected && vertex_selected[i]) {
      v.SetS();
      ++selected_vertices;
    }
  }
  for (std::size_t t = 0; t < nt; ++t) {
    CFaceO& face = m.face[t];
    const std::uint32_t f = triangle_face[t];
    for (int j = 0; j < 3; ++j) {
      const std::uint32_t corner = triangle_corners[3 * t + j];
      face.V(j) = &m.vert[result.corners[corner]];
      if (corner_uv) {
        face.WT(j) = vcg::TexCoord2f(corner_uv[2 * corner], corner_uv[2 * corner + 1]);
        face.WT(j).N() = static_cast<short>(material ? material[f] : 0);
      }
    }
    if (result.face_sizes[f] > 3) {
      // Edge j joins corners j and j+1; the fan's diagonals are the faux ones.
      const std::uint32_t first = static_cast<std::uint32_t>(offsets[f]), k = triangle_corners[3 * t + 1] - first;
      if (k > 1) face.SetF(0);
      if (k + 2 < result.face_sizes[f]) face.SetF(2);
    }
    if (!face_colors.empty()) face.C() = face_colors[f];
    if (face_quality) face.Q() = face_quality[f];
    if (face_selected && face_selected[f]) {
      face.SetS();
      ++selected_faces;
    }
  }
  m.svn = selected_vertices;
  m.sfn = selected_faces;
  write_attributes(result, m.vert_attr, Domain::vertex, vertex_source);
  write_attributes(result, m.face_attr, Domain::face, triangle_face);

  vcg::tri::UpdateBounding<CMeshO>::Box(m);
  if (nt > 0) vcg::tri::UpdateNormal<CMeshO>::PerFaceNormalized(m);
  if (normals && (!report.geometry_changed || nt == 0)) {
    for (std::size_t i = 0; i < nv; ++i)
      m.vert[i].N() = Point3m(normals[3 * i], normals[3 * i + 1], normals[3 * i + 2]);
  } else if (nt > 0) {
    vcg::tri::UpdateNormal<CMeshO>::PerVertexAngleWeighted(m);  // as MeshModel::UpdateBoxAndNormals
  }
  return report;
}

}  // namespace hedge::meshlab
