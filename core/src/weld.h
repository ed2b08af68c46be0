// extract()'s guard on the weld: copies of one source vertex are welded back only where
// that makes no defect the input did not have. Private to the core.
#pragma once

#include <cstdint>
#include <vector>

#include "hedge/mesh.h"
#include "hedge/soup.h"

namespace hedge::detail {

//! Where each mesh vertex goes in extract()'s output: `vmap[mesh vertex]` is its output
//! vertex, `order[output vertex]` the mesh vertex whose data that output vertex takes. The
//! first `n_sourced` output vertices weld the copies of one source vertex each, ascending by
//! source (`source[mesh vertex]`, build()'s "hedge:source"); the rest weld nothing.
struct Weld {
  std::vector<std::uint32_t> vmap, order;
  std::uint32_t n_sourced = 0;
};

//! Compares the welded output with `input`, the soup build() was given, around every output
//! vertex that welds two or more copies of an input vertex, and gives copies their own output
//! vertex (appended to `order`) until the output has no non-manifold edge, non-manifold vertex,
//! duplicate face or face repeating a vertex there beyond what the input had. Sources past the input's vertices
//! are an operation's own welds (subdivision's split-edge points): the non-manifold edges
//! and duplicate faces they make follow the operation's rule and stay (edits made after the
//! operation are not checked there: extract and build first); their non-manifold vertices
//! do not. Returns the number of copies moved.
std::size_t keep_new_defects_apart(const Mesh& mesh, const std::vector<std::uint32_t>& source, const Soup& input,
                                   Weld& weld);

}  // namespace hedge::detail
