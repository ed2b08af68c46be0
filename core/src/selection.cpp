#include "selection.h"

#include <algorithm>
#include <cstddef>

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

bool has_selection(const Mesh& mesh) {
  const auto any = [](const std::vector<std::uint8_t>& flags) {
    return std::find(flags.begin(), flags.end(), 1) != flags.end();
  };
  return any(selected_faces(mesh)) ||
         any(flags_of(mesh.vertex_properties().get_channel(kSelected), mesh.vertices_size()));
}

}  // namespace hedge::detail
