#include "selection.h"

#include <algorithm>
#include <cstddef>
#include <cstring>

#include "hedge/error.h"
#include "welded_copies.h"

namespace hedge::detail {
namespace {
constexpr const char* kSelected = "selected";

// Any non-zero byte counts: the channel's scalar type is whatever the host or file gave.
std::vector<std::uint8_t> flags_of(const ChannelArray* channel, std::size_t n) {
  std::vector<std::uint8_t> out(n, 0);
  if (!channel) return out;
  const std::size_t stride = channel->stride(), count = std::min(n, channel->size());
  for (std::size_t i = 0; i < count; ++i) {
    const std::byte* e = channel->element(i);
    out[i] = std::any_of(e, e + stride, [](std::byte b) { return b != std::byte{0}; });
  }
  return out;
}

// The first number of element i, whatever the channel's scalar type.
double scalar_at(const ChannelArray& channel, std::size_t i) {
  return with_scalar(channel.scalar(), [&]<class T>() {
    T x;
    std::memcpy(&x, channel.element(i), sizeof x);
    return static_cast<double>(x);
  });
}
}  // namespace

std::vector<std::uint8_t> selected_faces(const Mesh& mesh) {
  return flags_of(mesh.face_properties().get_channel(kSelected), mesh.faces_size());
}

std::vector<std::uint8_t> selected_vertices(const Mesh& mesh) {
  if (const ChannelArray* channel = mesh.vertex_properties().get_channel(kSelected))
    return flags_of(channel, mesh.vertices_size());
  return inside_selection(mesh, selected_faces(mesh));
}

std::vector<std::uint8_t> inside_selection(const Mesh& mesh, const std::vector<std::uint8_t>& faces) {
  std::vector<std::uint8_t> out(mesh.vertices_size(), 0);
  // Copies of one host vertex (build() split it) weld back to one position, which their
  // unselected faces would share: they hold still.
  const WeldedCopies copies(mesh);
  for (Vertex v : mesh.vertices()) {
    if (mesh.is_isolated(v) || copies.is_copy(v)) continue;
    bool inside = true;
    for (Halfedge h : mesh.outgoing(v)) {
      const Face f = mesh.face(h);
      if (f.is_valid() && !faces[f.idx()]) {
        inside = false;
        break;
      }
    }
    out[v.idx()] = inside;
  }
  return out;
}

std::vector<double> vertex_values(const Mesh& mesh, const std::string& name, const std::string& what) {
  const PropertyContainer& properties = mesh.vertex_properties();
  const ChannelArray* channel = properties.get_channel(name);
  if (!channel) {
    std::string known;
    for (const std::string& n : properties.names())
      if (properties.get_channel(n) && !properties.find(n)->is_internal()) known += (known.empty() ? "" : ", ") + n;
    throw Error(what + ": the mesh has no vertex attribute '" + name + "'" +
                (known.empty() ? " (it has none)" : "; its vertex attributes are: " + known));
  }
  if (channel->components() != 1)
    throw Error(what + ": the vertex attribute '" + name + "' holds " + std::to_string(channel->components()) +
                " numbers per vertex; one is needed");
  std::vector<double> out(mesh.vertices_size(), 0);
  for (std::size_t i = 0; i < std::min(out.size(), channel->size()); ++i) out[i] = scalar_at(*channel, i);
  return out;
}

bool has_selection(const Mesh& mesh) {
  const auto any = [](const std::vector<std::uint8_t>& flags) {
    return std::find(flags.begin(), flags.end(), 1) != flags.end();
  };
  return any(selected_faces(mesh)) ||
         any(flags_of(mesh.vertex_properties().get_channel(kSelected), mesh.vertices_size()));
}

}  // namespace hedge::detail
