// The invariant checker: every rule of mesh.h, with the first broken one named.
#pragma once

#include <string>

#include "hedge/mesh.h"

namespace hedge {

struct Validation {
  bool ok = true;
  std::string message;  //!< which invariant broke and where, e.g. "half-edge 12: prev(next(h)) is 7"
  explicit operator bool() const { return ok; }
};

//! Checks every invariant of the mesh; O(size of the mesh).
Validation validate(const Mesh& mesh);

//! Throws Error with validate()'s message when the mesh is broken.
void check_valid(const Mesh& mesh, const std::string& context);

}  // namespace hedge
