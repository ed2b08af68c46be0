// build(): Soup -> Mesh, accepting everything a host can hold; extract(): Mesh -> Soup.
// The contract is in docs/architecture.md, "One pipeline".
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "hedge/mesh.h"
#include "hedge/soup.h"

namespace hedge {

//! What building had to repair; hosts show it.
struct BuildReport {
  std::size_t non_manifold_edges = 0;      //!< edges with 3+ faces, or two faces in the same direction that could not be glued
  std::size_t non_manifold_vertices = 0;   //!< vertices split into several manifold copies
  std::size_t vertex_copies = 0;           //!< vertices added by those splits
  std::size_t flipped_faces = 0;           //!< faces reversed to orient their component consistently
  std::size_t unorientable_edges = 0;      //!< edges cut because the surface cannot be oriented (Möbius)
  std::size_t repeated_vertex_faces = 0;   //!< faces that visit a vertex more than once
  std::size_t skipped_faces = 0;           //!< faces with fewer than 3 distinct vertices, not built
  std::size_t isolated_vertices = 0;       //!< vertices no face uses (kept)
  std::vector<std::string> messages;       //!< one line per kind of repair, for people

  bool repaired() const {
    return non_manifold_edges || non_manifold_vertices || flipped_faces || unorientable_edges ||
           repeated_vertex_faces || skipped_faces;
  }
};

//! Where the mesh's elements came from in the soup.
struct BuildMaps {
  std::vector<std::uint32_t> vertex_source;  //!< mesh vertex -> soup vertex (copies share one)
  std::vector<std::uint32_t> face_source;    //!< mesh face -> soup face
  std::vector<std::uint32_t> skipped_faces;  //!< soup faces not built, ascending
};

struct BuildResult {
  Mesh mesh;
  BuildReport report;
  BuildMaps maps;
};

struct BuildOptions {
  //! Orient each connected component consistently (flipping the fewest faces).
  bool orient = true;
};

//! Builds a manifold half-edge mesh from any soup. Non-manifold edges and vertices are split
//! into manifold copies, orientation is made consistent, and the provenance is stored in
//! the mesh so extract() can give the host its own topology back. Throws Error on soups
//! that cannot be geometry (see Soup::check()).
BuildResult build(const Soup& soup, const BuildOptions& options = {});

struct ExtractOptions {
  //! Weld the copies made by build() back into their source vertex, and undo its flips.
  bool restore_source = true;
  //! The soup build() was given, when there is one: copies whose weld would make a
  //! non-manifold edge or vertex or a duplicate face that this soup did not have stay apart.
  const Soup* input = nullptr;
};

struct ExtractReport {
  //! Vertex copies not welded back because welding them would have made a defect: a face
  //! using one vertex twice, or (given ExtractOptions::input) a non-manifold edge or vertex
  //! or a duplicate face the input did not have. They come after every other vertex.
  std::size_t copies_kept_apart = 0;
};

//! Mesh -> Soup. After build() with no change in between, gives back the identical soup
//! (order, values, bit for bit), except faces that build() skipped. Channels come out
//! grouped by domain (vertex, then face, then corner), each group in the soup's order, so
//! a soup that lists its channels that way round-trips exactly. No output face visits a
//! vertex twice: copies that would weld into one within a face stay apart (ExtractReport).
//! Given the input soup, the output also has no more non-manifold edges and vertices and
//! duplicate faces than it (docs/architecture.md, "No mesh comes back worse").
Soup extract(const Mesh& mesh, const ExtractOptions& options = {}, ExtractReport* report = nullptr);

}  // namespace hedge
