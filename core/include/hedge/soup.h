// Soup: the neutral exchange form between hosts, files and the mesh. Indexed polygons
// plus attribute channels per vertex, face and corner. Adapters speak only Soup.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "hedge/properties.h"
#include "hedge/vec.h"

namespace hedge {

enum class Domain : std::uint8_t { vertex, face, corner };
const char* domain_name(Domain domain);

//! One attribute: `components` scalars of type `scalar` per element of `domain`, as raw
//! bytes (little-endian host order) so a round trip is bit for bit.
struct Channel {
  std::string name;  //!< e.g. "normal", "color", "uv", "quality", "selected", "material"
  Domain domain = Domain::vertex;
  ScalarType scalar = ScalarType::f32;
  int components = 1;
  std::vector<std::byte> data;

  std::size_t stride() const { return scalar_size(scalar) * static_cast<std::size_t>(components); }
  std::size_t count() const { return stride() ? data.size() / stride() : 0; }

  template <class T>
  T* as() {
    return reinterpret_cast<T*>(data.data());
  }
  template <class T>
  const T* as() const {
    return reinterpret_cast<const T*>(data.data());
  }
  //! A channel of n elements, zero-filled.
  static Channel make(std::string name, Domain domain, ScalarType scalar, int components, std::size_t n);

  bool operator==(const Channel&) const = default;
};

// Channel names shared by files and hosts (other names pass through untouched):
//   "normal"   f32 x3  vertex, face or corner
//   "color"    u8 x4 (RGBA) or f32 x4  vertex, face or corner
//   "uv"       f32 x2  corner (per-wedge texture coordinates) or vertex
//   "quality"  f32 x1  vertex or face
//   "selected" u8 x1   vertex or face
//   "material" i32 x1  face
//   "shape:<name>" f32 x3  vertex: the vertex's offset in another shape of the same mesh
//                  (Blender's shape keys); decimation weighs the error in each shape too
inline constexpr const char* kShapePrefix = "shape:";

//! Polygons over indexed vertices. Face f has face_sizes[f] corners; its corner vertex
//! indices are corners[offset(f) .. offset(f) + face_sizes[f]).
struct Soup {
  std::vector<Point> positions;
  std::vector<std::uint32_t> face_sizes;
  std::vector<std::uint32_t> corners;
  std::vector<Channel> channels;

  std::size_t n_vertices() const { return positions.size(); }
  std::size_t n_faces() const { return face_sizes.size(); }
  std::size_t n_corners() const { return corners.size(); }
  //! Number of elements a channel of this domain must have.
  std::size_t domain_size(Domain domain) const;

  void add_face(std::initializer_list<std::uint32_t> vertices);
  void add_face(const std::vector<std::uint32_t>& vertices);
  //! Prefix sums of face_sizes (size n_faces() + 1).
  std::vector<std::size_t> face_offsets() const;

  Channel* find(const std::string& name, Domain domain);
  const Channel* find(const std::string& name, Domain domain) const;
  //! Adds a zero-filled channel; the reference is valid until the next channel is added.
  Channel& add_channel(std::string name, Domain domain, ScalarType scalar, int components);

  //! Throws Error naming the first problem: sizes that do not add up, indices out of
  //! range, NaN or infinite coordinates, channels of the wrong length.
  void check() const;

  bool operator==(const Soup&) const = default;
};

}  // namespace hedge
