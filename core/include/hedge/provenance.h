// Provenance: the arrays build() adds to a mesh to say where its elements came from in the
// soup, so that extract() can give the host its own topology back. Declared here once; the
// contract below is to provenance what mesh.h's invariants are to connectivity.
//
// What build() records, only where it repaired something (a clean build adds no array):
//   vertex kVertexSource  u32   the soup vertex a mesh vertex stands for; present when build()
//                               split a vertex into copies (non-manifold edges and vertices,
//                               faces visiting a vertex twice). extract() welds the vertices
//                               of one source into one output vertex.
//   face   kFaceSource    u32   the soup face a mesh face was built from; present when build()
//                               skipped faces (fewer than 3 distinct vertices).
//   face   kFlipped       bool  build() reversed the face (c0, cn-1, ..., c1) to orient its
//                               component; extract() reverses it back.
//   face   kRepeats       bool  the soup face visits a vertex more than once; extract() lets its
//                               copies weld back into one face as they came.
//
// What operations keep: the arrays are TypedArrays named with kPrefix (is_internal()), never
// soup channels: a soup may not use the prefix and extract() does not emit them. An element
// that continues an input element keeps its values; an element made new, or from several
// old ones, takes the array's default (kInvalidIndex: no source, never welded; false), with
// one exception: a face that fills a hole takes kFlipped from its neighbours, so that it turns
// back with them. repair() removes kVertexSource, kFaceSource and kFlipped once it has made
// build()'s repairs the mesh's own.
#pragma once

namespace hedge::provenance {

//! Every provenance array's name starts with this; it is reserved in soups.
inline constexpr char kPrefix[] = "hedge:";

inline constexpr char kVertexSource[] = "hedge:source";  //!< vertex, u32
inline constexpr char kFaceSource[] = "hedge:source";    //!< face, u32
inline constexpr char kFlipped[] = "hedge:flipped";      //!< face, bool
inline constexpr char kRepeats[] = "hedge:repeats";      //!< face, bool

}  // namespace hedge::provenance
