// The largest mesh hedge can hold: handles are 32-bit indices (all ones is "invalid"), and
// every corner of a face is a half-edge, every edge two. Checked before anything is built
// or allocated, so that a count never wraps around.
#pragma once

#include <cstdint>
#include <string>

#include "hedge/handles.h"

namespace hedge {

//! Most vertices, faces or edges a mesh can index (kInvalidIndex itself means "none").
inline constexpr std::uint64_t kMaxElements = std::uint64_t{kInvalidIndex} - 1;
//! Most half-edges: an even number of indices below kInvalidIndex.
inline constexpr std::uint64_t kMaxHalfedges = kMaxElements & ~std::uint64_t{1};
//! Most corners of a soup: each corner needs a half-edge of its own, and an edge on a
//! boundary a second, outer one, so corners may need twice their number of half-edges.
inline constexpr std::uint64_t kMaxCorners = kMaxHalfedges / 2;
//! Most faces of a soup (each has 3 corners or more).
inline constexpr std::uint64_t kMaxFaces = kMaxCorners / 3;

//! "3,000,000,000 faces asked for, but hedge's 32-bit indices hold at most 715,827,882 faces".
std::string limit_message(std::uint64_t count, std::uint64_t limit, const std::string& what);

//! Throws Error("<context>: " + limit_message(...)) when `count` `what`s exceed `limit`.
void check_limit(const std::string& context, std::uint64_t count, std::uint64_t limit, const std::string& what);

//! 1234567 -> "1,234,567".
std::string with_commas(std::uint64_t n);

}  // namespace hedge
