// Typed 32-bit element handles. An invalid handle is all ones; half-edges live in
// pairs, so opposite(h) = h ^ 1 and edge(h) = h >> 1.
#pragma once

#include <cstdint>
#include <functional>
#include <limits>

namespace hedge {

using Index = std::uint32_t;
inline constexpr Index kInvalidIndex = std::numeric_limits<Index>::max();

//! Common base of the four handle kinds; the Tag keeps them from mixing.
template <class Tag>
class Handle {
 public:
  constexpr Handle() = default;
  constexpr explicit Handle(Index index) : index_(index) {}
  constexpr Index idx() const { return index_; }
  constexpr bool is_valid() const { return index_ != kInvalidIndex; }
  constexpr explicit operator bool() const { return is_valid(); }
  constexpr auto operator<=>(const Handle&) const = default;

 private:
  Index index_ = kInvalidIndex;
};

struct VertexTag;
struct HalfedgeTag;
struct EdgeTag;
struct FaceTag;
using Vertex = Handle<VertexTag>;
using Halfedge = Handle<HalfedgeTag>;
using Edge = Handle<EdgeTag>;
using Face = Handle<FaceTag>;

constexpr Halfedge opposite(Halfedge h) { return Halfedge(h.idx() ^ 1u); }
constexpr Edge edge_of(Halfedge h) { return Edge(h.idx() >> 1); }
//! The half-edge of an edge with the given side (0 or 1).
constexpr Halfedge halfedge_of(Edge e, unsigned side = 0) { return Halfedge((e.idx() << 1) | (side & 1u)); }

}  // namespace hedge

template <class Tag>
struct std::hash<hedge::Handle<Tag>> {
  std::size_t operator()(hedge::Handle<Tag> h) const noexcept { return std::hash<hedge::Index>()(h.idx()); }
};
