// The half-edge mesh: connectivity, positions and properties of a polygon surface.
//
// Invariants (checked by validate()):
// - half-edges come in pairs h, h^1 (one edge); a half-edge knows its target vertex, its
//   face (invalid on a boundary), next and prev; prev(next(h)) == h.
// - the half-edges of a face form one loop of at least 3, all with that face; halfedge(f)
//   points at corner 0, so the corners of a face are the targets of its loop in order.
// - outer halves of boundary edges form loops too (holes); every vertex is manifold (one
//   fan), and a boundary vertex's halfedge(v) is its outgoing boundary half-edge.
// - deleted elements stay in the arrays until garbage_collect().
// - two edges may join the same two vertices (build() keeps such pinches of the input;
//   repair removes them); validate() accepts them, Euler operations never make new ones.
#pragma once

#include <cstddef>
#include <cstdint>
#include <iterator>
#include <memory>
#include <span>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "hedge/detail/memory.h"
#include "hedge/handles.h"
#include "hedge/properties.h"
#include "hedge/vec.h"

namespace hedge {

class Mesh;

namespace detail {

//! Iterator over all elements of one kind, skipping deleted ones.
template <class H>
class ElementIterator {
 public:
  using value_type = H;
  using difference_type = std::ptrdiff_t;
  ElementIterator() = default;
  ElementIterator(const Mesh* mesh, Index index, Index end) : mesh_(mesh), index_(index), end_(end) { skip(); }
  H operator*() const { return H(index_); }
  ElementIterator& operator++() {
    ++index_;
    skip();
    return *this;
  }
  ElementIterator operator++(int) {
    auto copy = *this;
    ++*this;
    return copy;
  }
  bool operator==(const ElementIterator& other) const { return index_ == other.index_; }

 private:
  void skip();
  const Mesh* mesh_ = nullptr;
  Index index_ = 0;
  Index end_ = 0;
};

template <class H>
struct ElementRange {
  ElementIterator<H> first, last;
  ElementIterator<H> begin() const { return first; }
  ElementIterator<H> end() const { return last; }
};

//! How a loop of half-edges advances, and what it yields per half-edge.
enum class Step : std::uint8_t { next, prev, ccw, cw };
enum class Yield : std::uint8_t { halfedge, to_vertex, from_vertex, face, opposite_face, edge };

//! Circulator over a loop of half-edges (around a face or a vertex) as a C++ range.
//! Yields skip invalid faces (boundary) so "faces around" never returns a hole.
template <Step S, Yield Y>
class LoopIterator {
 public:
  using difference_type = std::ptrdiff_t;
  using value_type = std::conditional_t<Y == Yield::halfedge, Halfedge,
                                        std::conditional_t<Y == Yield::to_vertex || Y == Yield::from_vertex, Vertex,
                                                           std::conditional_t<Y == Yield::edge, Edge, Face>>>;
  LoopIterator() = default;
  LoopIterator(const Mesh* mesh, Halfedge start, bool at_end)
      : mesh_(mesh), start_(start), current_(start), done_(at_end || !start.is_valid()) {
    skip_holes();
  }
  value_type operator*() const;
  LoopIterator& operator++() {
    advance();
    skip_holes();
    return *this;
  }
  LoopIterator operator++(int) {
    auto copy = *this;
    ++*this;
    return copy;
  }
  bool operator==(const LoopIterator& other) const {
    return done_ == other.done_ && (done_ || current_ == other.current_);
  }
  Halfedge halfedge() const { return current_; }

 private:
  void advance();
  void skip_holes() {
    if constexpr (Y == Yield::face || Y == Yield::opposite_face)
      while (!done_ && !(**this).is_valid()) advance();
  }
  const Mesh* mesh_ = nullptr;
  Halfedge start_, current_;
  bool done_ = true;
};

template <Step S, Yield Y>
struct LoopRange {
  const Mesh* mesh;
  Halfedge start;
  LoopIterator<S, Y> begin() const { return {mesh, start, false}; }
  LoopIterator<S, Y> end() const { return {mesh, start, true}; }
};

}  // namespace detail

//! Index maps returned by garbage_collect(): old index -> new index (invalid when deleted).
struct GarbageMaps {
  std::vector<Index> vertices, edges, faces;
  //! A half-edge's new index: the two half-edges of an edge stay together, in their order,
  //! so this is its edge's new index with the same side (no array of its own: a mesh has
  //! twice as many half-edges as edges, and the map would be the largest of all).
  Index halfedge(Index old) const {
    const Index e = edges[old >> 1];
    return e == kInvalidIndex ? kInvalidIndex : 2 * e + (old & 1);
  }
};

class Mesh {
 public:
  Mesh() = default;

  // ---- sizes -------------------------------------------------------------------------
  //! Live element counts (deleted ones excluded).
  std::size_t n_vertices() const { return vertices_size() - deleted_.vertices; }
  std::size_t n_halfedges() const { return halfedges_size() - 2 * deleted_.edges; }
  std::size_t n_edges() const { return edges_size() - deleted_.edges; }
  std::size_t n_faces() const { return faces_size() - deleted_.faces; }
  //! Array sizes, deleted elements included: the bound for handle indices.
  std::size_t vertices_size() const { return vertex_halfedge_.size(); }
  std::size_t halfedges_size() const { return halfedges_.size(); }
  std::size_t edges_size() const { return halfedges_.size() / 2; }
  std::size_t faces_size() const { return face_halfedge_.size(); }
  bool is_empty() const { return n_vertices() == 0; }
  void clear();
  void reserve(std::size_t vertices, std::size_t edges, std::size_t faces);
  void shrink_to_fit();

  // ---- half-edge connectivity, all O(1) ----------------------------------------------
  Vertex to_vertex(Halfedge h) const { return halfedges_[h.idx()].vertex; }
  Vertex from_vertex(Halfedge h) const { return to_vertex(opposite(h)); }
  Face face(Halfedge h) const { return halfedges_[h.idx()].face; }
  Halfedge next(Halfedge h) const { return halfedges_[h.idx()].next; }
  Halfedge prev(Halfedge h) const { return halfedges_[h.idx()].prev; }
  static Halfedge opposite(Halfedge h) { return hedge::opposite(h); }
  //! Next outgoing half-edge of from_vertex(h), counter-clockwise / clockwise.
  Halfedge ccw_rotated(Halfedge h) const { return opposite(prev(h)); }
  Halfedge cw_rotated(Halfedge h) const { return next(opposite(h)); }
  static Edge edge(Halfedge h) { return edge_of(h); }
  static Halfedge halfedge(Edge e, unsigned side) { return halfedge_of(e, side); }
  Vertex vertex(Edge e, unsigned side) const { return to_vertex(halfedge(e, side)); }
  Face face(Edge e, unsigned side) const { return face(halfedge(e, side)); }
  //! Outgoing half-edge of v: a boundary one when v is on the boundary; invalid when isolated.
  Halfedge halfedge(Vertex v) const { return vertex_halfedge_[v.idx()]; }
  //! The half-edge of corner 0 of f.
  Halfedge halfedge(Face f) const { return face_halfedge_[f.idx()]; }

  bool is_boundary(Halfedge h) const { return !face(h).is_valid(); }
  bool is_boundary(Edge e) const { return is_boundary(halfedge(e, 0)) || is_boundary(halfedge(e, 1)); }
  bool is_boundary(Vertex v) const {
    Halfedge h = halfedge(v);
    return !(h.is_valid() && face(h).is_valid());
  }
  //! True when some edge of f lies on the boundary.
  bool is_boundary(Face f) const;
  bool is_isolated(Vertex v) const { return !halfedge(v).is_valid(); }
  //! Hints that h's connectivity is about to be read (starts loading it into cache); changes
  //! nothing. Precondition: h is valid.
  void prefetch(Halfedge h) const { detail::prefetch(&halfedges_[h.idx()]); }
  //! The same for f's half-edge.
  void prefetch(Face f) const { detail::prefetch(&face_halfedge_[f.idx()]); }
  //! The same for e's half-edges and its deletion mark.
  void prefetch(Edge e) const {
    detail::prefetch(&halfedges_[halfedge(e, 0).idx()]);
    if (!edeleted_.empty()) detail::prefetch(&edeleted_[e.idx()]);
  }
  //! The same for v's outgoing half-edge and position.
  void prefetch(Vertex v) const {
    detail::prefetch(&vertex_halfedge_[v.idx()]);
    detail::prefetch(&positions_[v.idx()]);
  }

  //! Number of edges at v / corners of f.
  std::size_t valence(Vertex v) const;
  std::size_t valence(Face f) const;
  bool is_triangle_mesh() const;
  bool is_quad_mesh() const;
  //! Half-edge from a to b, or invalid; O(valence(a)).
  Halfedge find_halfedge(Vertex a, Vertex b) const;
  Edge find_edge(Vertex a, Vertex b) const;

  // ---- low-level setters (builders and Euler operations) ------------------------------
  void set_vertex(Halfedge h, Vertex v) { halfedges_[h.idx()].vertex = v; }
  void set_face(Halfedge h, Face f) { halfedges_[h.idx()].face = f; }
  //! Links h -> n (sets next(h) and prev(n)).
  void set_next(Halfedge h, Halfedge n) {
    halfedges_[h.idx()].next = n;
    halfedges_[n.idx()].prev = h;
  }
  void set_halfedge(Vertex v, Halfedge h) { vertex_halfedge_[v.idx()] = h; }
  void set_halfedge(Face f, Halfedge h) { face_halfedge_[f.idx()] = h; }
  //! Makes halfedge(v) the boundary outgoing half-edge when there is one (restores the
  //! invariant after local changes); O(valence).
  void adjust_outgoing_halfedge(Vertex v);

  //! New elements with default properties; new_edge returns the half-edge from -> to.
  Vertex new_vertex();
  Halfedge new_edge(Vertex from, Vertex to);
  Face new_face();
  //! Bulk allocation for builders: appends n elements with invalid connectivity.
  void resize(std::size_t vertices, std::size_t edges, std::size_t faces);
  //! As resize(), but the connectivity of the new elements is left unset (garbage): for
  //! builders that then set every field themselves, on several threads, so that the new
  //! memory is touched once. Precondition for the mesh to be valid again: the caller sets
  //! to_vertex, face, next and prev of every new half-edge, and halfedge() of every new
  //! vertex and face (invalid ones included). Positions and properties are initialised.
  void resize_unset(std::size_t vertices, std::size_t edges, std::size_t faces);

  // ---- geometry ----------------------------------------------------------------------
  Point& position(Vertex v) { return positions_[v.idx()]; }
  const Point& position(Vertex v) const { return positions_[v.idx()]; }
  std::vector<Point>& positions() { return positions_; }
  const std::vector<Point>& positions() const { return positions_; }

  // ---- element ranges, skipping deleted elements --------------------------------------
  detail::ElementRange<Vertex> vertices() const;
  detail::ElementRange<Halfedge> halfedges() const;
  detail::ElementRange<Edge> edges() const;
  detail::ElementRange<Face> faces() const;

  // ---- circulators: ranges over the neighbourhood, O(1) per element --------------------
  //! Outgoing half-edges of v, counter-clockwise (starting at halfedge(v)).
  detail::LoopRange<detail::Step::ccw, detail::Yield::halfedge> outgoing(Vertex v) const { return {this, halfedge(v)}; }
  //! Outgoing half-edges of v, clockwise.
  detail::LoopRange<detail::Step::cw, detail::Yield::halfedge> outgoing_cw(Vertex v) const {
    return {this, halfedge(v)};
  }
  //! Neighbour vertices of v, counter-clockwise.
  detail::LoopRange<detail::Step::ccw, detail::Yield::to_vertex> vertices(Vertex v) const {
    return {this, halfedge(v)};
  }
  detail::LoopRange<detail::Step::cw, detail::Yield::to_vertex> vertices_cw(Vertex v) const {
    return {this, halfedge(v)};
  }
  //! Faces around v, counter-clockwise; holes are skipped.
  detail::LoopRange<detail::Step::ccw, detail::Yield::face> faces(Vertex v) const { return {this, halfedge(v)}; }
  detail::LoopRange<detail::Step::cw, detail::Yield::face> faces_cw(Vertex v) const { return {this, halfedge(v)}; }
  //! Edges around v, counter-clockwise.
  detail::LoopRange<detail::Step::ccw, detail::Yield::edge> edges(Vertex v) const { return {this, halfedge(v)}; }
  detail::LoopRange<detail::Step::cw, detail::Yield::edge> edges_cw(Vertex v) const { return {this, halfedge(v)}; }
  //! Half-edges of f in order, starting at corner 0.
  detail::LoopRange<detail::Step::next, detail::Yield::halfedge> halfedges(Face f) const { return {this, halfedge(f)}; }
  detail::LoopRange<detail::Step::prev, detail::Yield::halfedge> halfedges_reversed(Face f) const {
    return {this, halfedge(f)};
  }
  //! Corner vertices of f in order.
  detail::LoopRange<detail::Step::next, detail::Yield::to_vertex> vertices(Face f) const { return {this, halfedge(f)}; }
  detail::LoopRange<detail::Step::next, detail::Yield::edge> edges(Face f) const { return {this, halfedge(f)}; }
  //! Faces sharing an edge with f; boundary edges are skipped.
  detail::LoopRange<detail::Step::next, detail::Yield::opposite_face> faces(Face f) const {
    return {this, halfedge(f)};
  }
  //! Half-edges of the loop through h (a face or a hole).
  detail::LoopRange<detail::Step::next, detail::Yield::halfedge> loop(Halfedge h) const { return {this, h}; }

  // ---- properties ----------------------------------------------------------------------
  template <class T>
  VertexProperty<T> add_vertex_property(const std::string& name, T def = T()) {
    return VertexProperty<T>(vprops_.add<T>(name, def));
  }
  template <class T>
  VertexProperty<T> get_vertex_property(const std::string& name) const {
    return VertexProperty<T>(vprops_.get<T>(name));
  }
  template <class T>
  VertexProperty<T> vertex_property(const std::string& name, T def = T()) {
    return get_or_add<Vertex, T>(vprops_, name, def);
  }
  template <class T>
  HalfedgeProperty<T> add_halfedge_property(const std::string& name, T def = T()) {
    return HalfedgeProperty<T>(hprops_.add<T>(name, def));
  }
  template <class T>
  HalfedgeProperty<T> get_halfedge_property(const std::string& name) const {
    return HalfedgeProperty<T>(hprops_.get<T>(name));
  }
  template <class T>
  HalfedgeProperty<T> halfedge_property(const std::string& name, T def = T()) {
    return get_or_add<Halfedge, T>(hprops_, name, def);
  }
  template <class T>
  EdgeProperty<T> add_edge_property(const std::string& name, T def = T()) {
    return EdgeProperty<T>(eprops_.add<T>(name, def));
  }
  template <class T>
  EdgeProperty<T> get_edge_property(const std::string& name) const {
    return EdgeProperty<T>(eprops_.get<T>(name));
  }
  template <class T>
  EdgeProperty<T> edge_property(const std::string& name, T def = T()) {
    return get_or_add<Edge, T>(eprops_, name, def);
  }
  template <class T>
  FaceProperty<T> add_face_property(const std::string& name, T def = T()) {
    return FaceProperty<T>(fprops_.add<T>(name, def));
  }
  template <class T>
  FaceProperty<T> get_face_property(const std::string& name) const {
    return FaceProperty<T>(fprops_.get<T>(name));
  }
  template <class T>
  FaceProperty<T> face_property(const std::string& name, T def = T()) {
    return get_or_add<Face, T>(fprops_, name, def);
  }

  //! The containers, for code that handles properties generically (builders, GC, IO).
  PropertyContainer& vertex_properties() { return vprops_; }
  PropertyContainer& halfedge_properties() { return hprops_; }
  PropertyContainer& edge_properties() { return eprops_; }
  PropertyContainer& face_properties() { return fprops_; }
  const PropertyContainer& vertex_properties() const { return vprops_; }
  const PropertyContainer& halfedge_properties() const { return hprops_; }
  const PropertyContainer& edge_properties() const { return eprops_; }
  const PropertyContainer& face_properties() const { return fprops_; }

  // ---- deletion and garbage collection -------------------------------------------------
  // The marks exist once something was deleted (or prepare_deletion_marks() made them).
  bool is_deleted(Vertex v) const { return !vdeleted_.empty() && vdeleted_[v.idx()]; }
  bool is_deleted(Edge e) const { return !edeleted_.empty() && edeleted_[e.idx()]; }
  bool is_deleted(Halfedge h) const { return is_deleted(edge(h)); }
  bool is_deleted(Face f) const { return !fdeleted_.empty() && fdeleted_[f.idx()]; }
  bool has_garbage() const { return deleted_.vertices || deleted_.edges || deleted_.faces; }
  //! Removes f; its edges that end up with no face on either side are deleted too, and
  //! vertices left without edges are deleted (pmp semantics). A vertex whose fan this
  //! leaves with two gaps is non-manifold (validate() says so): callers that delete
  //! several faces around a vertex must rebuild or repair it.
  void delete_face(Face f);
  //! Removes the faces on both sides of e, then as delete_face().
  void delete_edge(Edge e);
  //! Removes every face around v, then as delete_face(); an isolated v is deleted.
  void delete_vertex(Vertex v);
  //! Compacts the arrays, keeping the relative order of the live elements.
  GarbageMaps garbage_collect();
  //! garbage_collect() without its maps, for callers that hold no indices: the maps span
  //! every old element, and on a mesh that lost most of them writing them (fresh memory)
  //! costs more than compacting what is left.
  void compact();
  //! Renumbers the live elements: vertex_order[i] (an index now) becomes vertex i, and so
  //! for edges and faces; each order lists every live element once. Deleted elements go, as
  //! in garbage_collect(). For laying a mesh out in memory to suit an algorithm's walks
  //! (detail::sort_spatially()). Throws Error, changing nothing, when an order is not such a
  //! list.
  GarbageMaps reorder(std::span<const Index> vertex_order, std::span<const Index> edge_order,
                      std::span<const Index> face_order);

  // ---- Euler operations (euler.cpp); each keeps every invariant ------------------------
  //! A new isolated vertex.
  Vertex add_vertex(const Point& p);
  //! Adds a polygon over existing vertices (at least 3, counter-clockwise). Throws Error,
  //! leaving the mesh unchanged, when the face would make a vertex or edge non-manifold.
  Face add_face(std::span<const Vertex> vertices);
  Face add_triangle(Vertex a, Vertex b, Vertex c);
  Face add_quad(Vertex a, Vertex b, Vertex c, Vertex d);
  //! Puts a face on a closed chain of boundary half-edges (to_vertex(h[i]) ==
  //! from_vertex(h[i+1])); throws Error when they are not such a chain (a whole hole).
  //! Corner 0 is from_vertex(h[0]), as add_face(vertices) would make it.
  Face add_face(std::span<const Halfedge> halfedges);
  //! Fills the hole whose loop holds boundary half-edge h with one face. Throws Error,
  //! leaving the mesh unchanged, when the loop cannot be one face: fewer than 3 edges (two
  //! edges joining the same two vertices) or a vertex passed twice.
  Face fill_hole(Halfedge h);
  //! Removes an isolated vertex; throws Error when v has edges.
  void remove_isolated_vertex(Vertex v);

  //! A flip is legal on an interior edge between two triangles whose other two vertices
  //! are not already joined by an edge, and whose interior end vertices keep valence >= 3
  //! (a boundary end vertex may drop to 2, as in the two-triangle square).
  bool is_flip_ok(Edge e) const;
  //! Rotates e inside the quad formed by its two triangles; each face keeps its index and
  //! one outer edge per side. Throws Error, changing nothing, unless is_flip_ok(e).
  void flip(Edge e);

  //! Inserts v (an isolated vertex) in the middle of e; both faces gain a corner
  //! (polygon-aware) and keep their corner 0. Returns the half-edge that points to v along
  //! halfedge(e, 0)'s direction.
  Halfedge split_edge(Edge e, Vertex v);
  //! Splits e at v and connects v to the opposite corner of each adjacent triangle
  //! (2 triangles become 4). Returns the half-edge that points to v. Throws Error when a
  //! face of e is not a triangle or both triangles share their third corner.
  Halfedge split_edge_triangles(Edge e, Vertex v);
  //! Replaces f by a fan of triangles around the new vertex v (an isolated vertex); f keeps
  //! the triangle of its corner 0.
  void split_face(Face f, Vertex v);

  //! Legal when h0 and h1 are distinct, non-adjacent half-edges of the same face and
  //! their targets are not joined already.
  bool is_insert_ok(Halfedge h0, Halfedge h1) const;
  //! Splits the face of h0 and h1 by a new edge from to_vertex(h0) to to_vertex(h1).
  //! Returns the new half-edge from to_vertex(h0) to to_vertex(h1). The face keeps h0's
  //! side; the new face (h1's side, corner 0 at to_vertex(h0)) copies its properties.
  //! Throws Error, changing nothing, unless is_insert_ok(h0, h1).
  Halfedge insert_edge(Halfedge h0, Halfedge h1);
  //! Legal when e is interior, its two faces differ, and merging them gives a face that
  //! visits each vertex once.
  bool is_removal_ok(Edge e) const;
  //! Merges the two faces of e into one; the face with the lower index survives, keeping
  //! its corner 0. Throws Error, changing nothing, unless is_removal_ok(e).
  void remove_edge(Edge e);

  //! Link condition and boundary rules for collapsing h (from_vertex into to_vertex):
  //! the one-rings of the end vertices share only the opposite corners of the incident
  //! triangles, and no two triangles would coincide (tetrahedron); an interior edge may
  //! not join two boundary vertices; a triangle at h may not have both other edges on the
  //! boundary; no other face may pass through both end vertices.
  bool is_collapse_ok(Halfedge h) const;
  //! Moves from_vertex(h) onto to_vertex(h) and removes it, the edge and degenerate
  //! triangles (larger polygons lose a corner). Throws Error, changing nothing, unless
  //! is_collapse_ok(h).
  void collapse(Halfedge h);
  //! collapse(h) without its legality test, for callers that have just made that test, or
  //! a stricter one, on the mesh as it is (decimate does; the test walks both one-rings and
  //! costs as much as the collapse). Precondition: is_collapse_ok(h); otherwise the mesh is
  //! left broken. Debug builds check the precondition and throw Error when it fails.
  void collapse_unchecked(Halfedge h);
  //! Counts of deleted elements.
  struct Deletions {
    std::size_t vertices = 0, edges = 0, faces = 0;
  };
  //! collapse_unchecked(h) for several threads at once, each collapsing where no other
  //! reads or writes (no two collapses whose closed one-rings share a vertex): deletions are
  //! counted in the caller's `tally`, which add_deletions() folds into the mesh afterwards.
  //! Precondition besides collapse_unchecked(h)'s: prepare_deletion_marks() was called, so
  //! that marking an element resizes no array. Until add_deletions(), n_vertices() and the
  //! like count the deleted elements as present.
  void collapse_unchecked(Halfedge h, Deletions& tally);
  void prepare_deletion_marks();
  void add_deletions(const Deletions& tally);

  //! Splits f into triangles by a fan of new edges from corner 0 (no geometry involved;
  //! the triangulate operation chooses diagonals by shape); O(corners). When a diagonal
  //! from corner 0 exists already outside f, the fan starts at the next corner that has
  //! none; throws Error when no corner works.
  void triangulate(Face f);
  void triangulate();

  // ---- memory ------------------------------------------------------------------------
  //! Heap bytes held by the mesh (capacities of all arrays and properties).
  std::size_t heap_bytes() const;

 private:
  struct HalfedgeRecord {
    Vertex vertex;
    Face face;
    Halfedge next, prev;
  };
  template <class H, class T>
  Property<H, T> get_or_add(PropertyContainer& c, const std::string& name, const T& def) {
    if (auto* a = c.get<T>(name)) return Property<H, T>(a);
    return Property<H, T>(c.add<T>(name, def));
  }
  // garbage_collect(), compact() and reorder(): element i of each array becomes element i
  // of the order given (new -> old); `renumbered` maps references (old -> new) through its
  // vertex(), edge() and face(). Defined and used in mesh.cpp only.
  template <class Renumbered>
  void renumber(std::span<const Index> vertex_order, std::span<const Index> edge_order,
                std::span<const Index> face_order, const Renumbered& renumbered);
  void mark_deleted(Vertex v, Deletions& tally);
  void mark_deleted(Edge e, Deletions& tally);
  void mark_deleted(Face f, Deletions& tally);
  void mark_deleted(Vertex v) { mark_deleted(v, deleted_); }
  void mark_deleted(Edge e) { mark_deleted(e, deleted_); }
  void mark_deleted(Face f) { mark_deleted(f, deleted_); }

  template <class T>
  using Array = std::vector<T, detail::UnsetAllocator<T>>;
  Array<HalfedgeRecord> halfedges_;
  Array<Halfedge> vertex_halfedge_;
  Array<Halfedge> face_halfedge_;
  std::vector<Point> positions_;
  PropertyContainer vprops_, hprops_, eprops_, fprops_;
  // Bytes, not bits: threads collapsing side by side mark neighbouring elements.
  std::vector<std::uint8_t> vdeleted_, edeleted_, fdeleted_;
  Deletions deleted_;
};

// ---- inline definitions of the iterators -----------------------------------------------
namespace detail {

template <class H>
void ElementIterator<H>::skip() {
  if constexpr (std::is_same_v<H, Halfedge>) {
    while (index_ < end_ && mesh_->is_deleted(Halfedge(index_))) ++index_;
  } else {
    while (index_ < end_ && mesh_->is_deleted(H(index_))) ++index_;
  }
}

template <Step S, Yield Y>
typename LoopIterator<S, Y>::value_type LoopIterator<S, Y>::operator*() const {
  if constexpr (Y == Yield::halfedge) return current_;
  if constexpr (Y == Yield::to_vertex) return mesh_->to_vertex(current_);
  if constexpr (Y == Yield::from_vertex) return mesh_->from_vertex(current_);
  if constexpr (Y == Yield::face) return mesh_->face(current_);
  if constexpr (Y == Yield::opposite_face) return mesh_->face(Mesh::opposite(current_));
  if constexpr (Y == Yield::edge) return Mesh::edge(current_);
}

template <Step S, Yield Y>
void LoopIterator<S, Y>::advance() {
  if constexpr (S == Step::next) current_ = mesh_->next(current_);
  if constexpr (S == Step::prev) current_ = mesh_->prev(current_);
  if constexpr (S == Step::ccw) current_ = mesh_->ccw_rotated(current_);
  if constexpr (S == Step::cw) current_ = mesh_->cw_rotated(current_);
  if (current_ == start_) done_ = true;
}

}  // namespace detail

inline detail::ElementRange<Vertex> Mesh::vertices() const {
  auto n = static_cast<Index>(vertices_size());
  return {{this, 0, n}, {this, n, n}};
}
inline detail::ElementRange<Halfedge> Mesh::halfedges() const {
  auto n = static_cast<Index>(halfedges_size());
  return {{this, 0, n}, {this, n, n}};
}
inline detail::ElementRange<Edge> Mesh::edges() const {
  auto n = static_cast<Index>(edges_size());
  return {{this, 0, n}, {this, n, n}};
}
inline detail::ElementRange<Face> Mesh::faces() const {
  auto n = static_cast<Index>(faces_size());
  return {{this, 0, n}, {this, n, n}};
}

}  // namespace hedge
