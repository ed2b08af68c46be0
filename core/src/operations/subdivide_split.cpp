// Loop, Catmull–Clark and midpoint subdivision (subdivide.h): one step splits every edge at an
// edge point and every face 1 -> 4 or into quads around a face point. The three schemes share
// the connectivity; they differ only in the stencils of the new points (below, one set per
// scheme).
#include <algorithm>
#include <cstddef>
#include <span>
#include <vector>

#include "hedge/error.h"
#include "hedge/vec.h"
#include "parallel.h"
#include "subdivide_refine.h"

namespace hedge::subdivision {
namespace {

//! How each face splits: triangles of Loop and midpoint 1 -> 4 at the edge points; faces of
//! Catmull–Clark and polygons of midpoint into one quad per corner around a face point.
//! On a mesh of triangles split 1 -> 4 (every Loop step) the offsets are arithmetic and no
//! table is built.
struct SplitPlan {
  bool uniform = false;  // all faces are triangles split 1 -> 4
  std::vector<Index>
      face_point;  // per face: index of its face point among the added vertices after the edge points, or invalid
  std::vector<Index> inner_edge;  // per face: first of its new interior edges (counted after the 2E halves)
  std::vector<Index> child_face;  // per face: first child face
  std::vector<Index> face_of_point;
  Index inner_edges = 0, child_faces = 0;

  Index first_inner_edge(Index f) const { return uniform ? 3 * f : inner_edge[f]; }
  Index first_child(Index f) const { return uniform ? 4 * f : child_face[f]; }
  Index point_of_face(Index f) const { return uniform ? kInvalidIndex : face_point[f]; }
};

//! Edges of f that `region` opens (split): all of them without selection_only.
Index split_edges(const Mesh& m, const Region& region, Face f) {
  Index k = 0;
  for (Halfedge h : m.halfedges(f)) k += region.opens(Mesh::edge(h));
  return k;
}

SplitPlan plan_split(const Mesh& m, SubdivisionScheme scheme, const Region& region) {
  const std::size_t F = m.faces_size();
  SplitPlan plan;
  if (scheme != SubdivisionScheme::catmull_clark && region.all()) {
    bool any_polygon = false;
    for (Index f = 0; f < F && !any_polygon; ++f) {
      const Halfedge h = m.halfedge(Face(f));
      any_polygon = m.next(m.next(m.next(h))) != h;
    }
    plan.uniform = !any_polygon;
  }
  if (plan.uniform) {
    check_index_range(m.vertices_size() + m.edges_size(), 2 * m.edges_size() + 3 * F, 4 * F);
    plan.inner_edges = Index(3 * F);
    plan.child_faces = Index(4 * F);
    return plan;
  }
  plan.face_point.resize(F);
  plan.inner_edge.resize(F);
  plan.child_face.resize(F);
  std::size_t inner = 0, children = 0;
  for (Index f = 0; f < F; ++f) {
    const std::size_t n = face_size(m, Face(f));
    const bool quads = scheme == SubdivisionScheme::catmull_clark || n != 3;
    // With selection_only, k of the n edges split (closures in subdivide.h): a face with
    // none stays whole; a triangle takes k chords, k + 1 pieces; a polygon one spoke per
    // edge point, and two when there is one.
    const std::size_t k = region.all() ? n : (region.refines(Face(f)) ? split_edges(m, region, Face(f)) : 0);
    plan.inner_edge[f] = Index(inner);
    plan.child_face[f] = Index(children);
    if (k == 0) {
      plan.face_point[f] = kInvalidIndex;
      children += 1;
    } else if (quads) {
      plan.face_point[f] = Index(plan.face_of_point.size());
      plan.face_of_point.push_back(f);
      inner += std::max<std::size_t>(k, 2);
      children += std::max<std::size_t>(k, 2);
    } else {
      plan.face_point[f] = kInvalidIndex;
      inner += k;
      children += k + 1;
    }
  }
  check_index_range(m.vertices_size() + m.edges_size() + plan.face_of_point.size(), 2 * m.edges_size() + inner,
                    children);
  plan.inner_edges = Index(inner);
  plan.child_faces = Index(children);
  return plan;
}

//! With selection_only, a piece of a face's rim after the split: the half-edge, the vertex it
//! reaches and the corner slot (refine_corners) of that vertex in the old face.
struct Rim {
  Halfedge h;
  Vertex to;
  Index slot;
};

//! What closing a face needs, kept across the faces of one thread.
struct Scratch {
  std::vector<Rim> rim;
  std::vector<Index> spokes;
  std::vector<Halfedge> loop;
};

// ---- the stencils -----------------------------------------------------------------------------

//! What a step's stencils read: the mesh, its creases (per edge, empty for none) and where the
//! face points are. Added vertices: edge points V..V+E-1, then face points.
struct SplitStencils {
  const Mesh& m;
  const std::vector<bool>& crease;
  const SplitPlan& plan;
  const Region& region;
  Index V = 0, E = 0;

  Index face_point(Face f) const { return V + E + plan.point_of_face(f.idx()); }
  bool is_sharp(Edge e) const { return m.is_boundary(e) || (!crease.empty() && crease[e.idx()]); }
};

//! A face point, for Catmull–Clark's faces and midpoint's polygons: the centroid.
void face_point(const Mesh& m, Face f, Stencil& s) {
  const float w = 1.0f / float(face_size(m, f));
  for (Vertex c : m.vertices(f)) s.add(c.idx(), w);
}

//! The midpoint of e: midpoint's every edge point, and the edge point of a boundary edge or a
//! crease under Loop and Catmull–Clark (a sharp edge is refined as a curve of its own).
void edge_midpoint(const Mesh& m, Edge e, Stencil& s) {
  s.add(m.to_vertex(Mesh::halfedge(e, 0)).idx(), 0.5f);
  s.add(m.to_vertex(Mesh::halfedge(e, 1)).idx(), 0.5f);
}

void midpoint_edge_point(const SplitStencils& r, Edge e, Stencil& s) { edge_midpoint(r.m, e, s); }

//! Loop: 3/8 for the edge's ends, 1/8 for the opposite corners of its two triangles.
void loop_edge_point(const SplitStencils& r, Edge e, Stencil& s) {
  if (r.is_sharp(e)) return edge_midpoint(r.m, e, s);
  const Mesh& m = r.m;
  const Halfedge h0 = Mesh::halfedge(e, 0), h1 = Mesh::halfedge(e, 1);
  s.add(m.to_vertex(h0).idx(), 0.375f);
  s.add(m.to_vertex(h1).idx(), 0.375f);
  s.add(m.to_vertex(m.next(h0)).idx(), 0.125f);
  s.add(m.to_vertex(m.next(h1)).idx(), 0.125f);
}

//! Catmull–Clark: the mean of the edge's ends and its two faces' points.
void catmull_clark_edge_point(const SplitStencils& r, Edge e, Stencil& s) {
  if (r.is_sharp(e)) return edge_midpoint(r.m, e, s);
  const Mesh& m = r.m;
  const Halfedge h0 = Mesh::halfedge(e, 0), h1 = Mesh::halfedge(e, 1);
  s.add(m.to_vertex(h0).idx(), 0.25f);
  s.add(m.to_vertex(h1).idx(), 0.25f);
  s.add(r.face_point(m.face(h0)), 0.25f);
  s.add(r.face_point(m.face(h1)), 0.25f);
}

//! The rules of old vertices that Loop and Catmull–Clark share: isolated vertices, creases and
//! boundaries. Fills s and returns true when one applies; false leaves v to the smooth rule.
bool sharp_vertex(const SplitStencils& r, Vertex v, Stencil& s) {
  const Mesh& m = r.m;
  const Halfedge out_h = m.halfedge(v);
  if (!out_h.is_valid()) {
    s.add(v.idx(), 1.0f);
    return true;
  }
  if (!r.crease.empty()) {
    // Hoppe et al. 1994 / DeRose et al. 1998, boundary edges counting as creases: a corner
    // (3 or more) stays, two interior creases give the curve rule along them, a dart (one)
    // falls through to the smooth rule, a plain boundary vertex to the boundary rule.
    const SharpEdges sharp = sharp_edges(m, r.crease, v);
    if (sharp.count >= 3) {
      s.add(v.idx(), 1.0f);
      return true;
    }
    if (sharp.count == 2 && !m.is_boundary(out_h)) {
      s.add(v.idx(), 0.75f);
      s.add(m.to_vertex(sharp.out[0]).idx(), 0.125f);
      s.add(m.to_vertex(sharp.out[1]).idx(), 0.125f);
      return true;
    }
  }
  if (m.is_boundary(out_h)) {
    // Cubic B-spline on the boundary curve: the two boundary neighbours 1/8 each.
    s.add(v.idx(), 0.75f);
    s.add(m.to_vertex(out_h).idx(), 0.125f);
    s.add(m.from_vertex(m.prev(out_h)).idx(), 0.125f);
    return true;
  }
  return false;
}

//! Midpoint moves nothing.
void midpoint_vertex(const SplitStencils&, Vertex v, Stencil& s) { s.add(v.idx(), 1.0f); }

//! Loop: the vertex keeps 1 - n beta(n), each of its n neighbours beta(n).
void loop_vertex(const SplitStencils& r, Vertex v, Stencil& s) {
  if (sharp_vertex(r, v, s)) return;
  // One walk around v gathers the ring; the weights depend on its size, set afterwards.
  s.add(v.idx(), 0.0f);
  for (Halfedge h : r.m.outgoing(v)) s.add(r.m.to_vertex(h).idx(), 0.0f);
  const std::size_t n = s.size() - 1;
  const float beta = float(loop_beta(n));
  s.weight(0) = float(1.0 - double(n) * double(beta));
  for (std::size_t i = 1; i <= n; ++i) s.weight(i) = beta;
}

//! Catmull–Clark: (Q + 2R + (n - 3) S) / n with Q the mean face point, R the mean edge
//! midpoint: the vertex keeps (n - 2) / n, each neighbour and face point 1 / n^2.
void catmull_clark_vertex(const SplitStencils& r, Vertex v, Stencil& s) {
  if (sharp_vertex(r, v, s)) return;
  // One walk around v gathers the ring; the weights depend on its size, set afterwards.
  s.add(v.idx(), 0.0f);
  for (Halfedge h : r.m.outgoing(v)) {
    s.add(r.m.to_vertex(h).idx(), 0.0f);
    s.add(r.face_point(r.m.face(h)), 0.0f);
  }
  const std::size_t n = (s.size() - 1) / 2;
  s.weight(0) = float(n - 2) / float(n);
  for (std::size_t i = 1; i <= 2 * n; ++i) s.weight(i) = 1.0f / float(n * n);
}

//! A step's positions and vertex properties under one scheme's rules, bound at compile time
//! so that the stencil loops do not branch on the scheme.
template <auto edge_point, auto vertex_point>
void refine_split_vertices(const SplitStencils& r, Mesh& out, const VertexRule& rule, unsigned threads) {
  auto added = [&](Index k, Stencil& s) {
    if (k >= r.E)
      face_point(r.m, Face(r.plan.face_of_point[k - r.E]), s);
    else if (r.region.opens(Edge(k)))
      edge_point(r, Edge(k), s);
    else
      edge_midpoint(r.m, Edge(k), s);  // an unsplit edge: the point is dropped (its faces may have none)
  };
  auto even = [&](Vertex v, Stencil& s) {
    if (r.region.moves(v))
      vertex_point(r, v, s);
    else
      s.add(v.idx(), 1.0f);  // on the border of the selection or outside it: stays
  };
  refine_vertices(r.m, out, rule, threads, added, even);
}

}  // namespace

// ---- the step -----------------------------------------------------------------------------------

Mesh split_step(const Mesh& m, SubdivisionScheme scheme, const std::vector<bool>& crease, const Region& region,
                unsigned threads, Progress& progress, double from, double to) {
  const Index V = Index(m.vertices_size()), E = Index(m.edges_size()), F = Index(m.faces_size());
  const Index H = 2 * E;
  const SplitPlan plan = plan_split(m, scheme, region);
  const Index FP = Index(plan.face_of_point.size());
  const Index V2 = V + E + FP, E2 = 2 * E + plan.inner_edges, F2 = plan.child_faces;

  StepOutput step(m, V2, E2, F2);
  Mesh& out = step.out;
  const bool corner_props = step.corner_props, edge_props = step.edge_props, face_props = step.face_props;
  std::vector<Index>&hmap = step.hmap, &emap = step.emap, &fmap = step.fmap;
  const Index centroid_slot = 2 * H, default_corner = 2 * H + FP;

  // Faces: the halves of their half-edges, the interior edges and the child faces.
  // h[i] points to corner c_i; m_i is the edge point of h[i] (between c_{i-1} and c_i).
  auto split_face = [&](Index f, const Halfedge* h, Index n) {
    const Index ff = plan.first_child(f), ie = 2 * E + plan.first_inner_edge(f);
    auto inner = [&](Index k, unsigned side) { return Halfedge(2 * (ie + k % n) + side); };
    for (Index i = 0; i < n; ++i) {
      out.set_vertex(first_half(h[i]), Vertex(V + Mesh::edge(h[i]).idx()));
      out.set_vertex(second_half(h[i]), m.to_vertex(h[i]));
      if (corner_props) {
        hmap[second_half(h[i]).idx()] = h[i].idx();
        hmap[first_half(h[i]).idx()] = H + h[i].idx();
      }
    }
    const Index point = plan.point_of_face(f);
    if (point == kInvalidIndex) {
      // Corner triangle i: c_i, m_{i+1}, m_i; centre triangle m_0, m_1, m_2. Interior edge i
      // joins m_{i+1} and m_i; its side 0 lies in corner triangle i, side 1 in the centre.
      const Face centre(ff + 3);
      for (Index i = 0; i < 3; ++i) {
        const Index j = i == 2 ? 0 : i + 1;
        const Halfedge a = second_half(h[i]), b = first_half(h[j]), c = inner(i, 0), d = inner(i, 1);
        const Face t(ff + i);
        link_loop(out, t, {a, b, c});
        out.set_halfedge(t, a);
        out.set_vertex(c, Vertex(V + Mesh::edge(h[i]).idx()));
        out.set_vertex(d, Vertex(V + Mesh::edge(h[j]).idx()));
        out.set_face(d, centre);
        out.set_next(d, inner(j, 1));
        if (corner_props) {
          hmap[c.idx()] = H + h[i].idx();
          hmap[d.idx()] = H + h[j].idx();
        }
      }
      out.set_halfedge(centre, inner(2, 1));
      if (face_props)
        for (Index c = 0; c < 4; ++c) fmap[ff + c] = f;
    } else {
      // Quad i: c_i, m_{i+1}, face point, m_i. Interior edge k joins the face point and m_k;
      // its side 0 runs face point -> m_k.
      const Vertex fp(V + E + point);
      for (Index i = 0; i < n; ++i) {
        const Halfedge a = second_half(h[i]), b = first_half(h[(i + 1) % n]), c = inner(i + 1, 1), d = inner(i, 0);
        const Face t(ff + i);
        link_loop(out, t, {a, b, c, d});
        out.set_halfedge(t, a);
        out.set_vertex(d, Vertex(V + Mesh::edge(h[i]).idx()));
        out.set_vertex(inner(i, 1), fp);
        if (corner_props) {
          hmap[d.idx()] = H + h[i].idx();
          hmap[inner(i, 1).idx()] = centroid_slot + point;
        }
        if (face_props) fmap[ff + i] = f;
      }
      out.set_halfedge(fp, inner(0, 0));
    }
    if (edge_props)
      for (Index k = 0; k < (point == kInvalidIndex ? 3 : n); ++k) emap[ie + k] = E;  // interior edges: defaults
  };
  // selection_only: an edge left whole keeps one edge, 2e, made of side 0's first half and
  // side 1's second half; edge 2e + 1 and point V + e stay unlinked (drop_unlinked()).
  // first_piece(h) and last_piece(h): what leaves h's origin and what reaches its target.
  auto is_split = [&](Halfedge h) { return region.opens(Mesh::edge(h)); };
  auto whole = [](Halfedge h) { return (h.idx() & 1u) ? second_half(h) : first_half(h); };
  auto first_piece = [&](Halfedge h) { return is_split(h) ? first_half(h) : whole(h); };
  auto last_piece = [&](Halfedge h) { return is_split(h) ? second_half(h) : whole(h); };

  // A face with an edge left whole (subdivide.h's closures), or outside the selection. Its
  // rim: the pieces of its old half-edges in order, each ending at a corner or an edge point;
  // chords (interior edges ie, ie + 1, ...) cut it into the pieces plan_split() counted.
  auto close_face = [&](Index f, const Halfedge* h, Index n, Scratch& scratch) {
    std::vector<Rim>& rim = scratch.rim;
    std::vector<Halfedge>& loop = scratch.loop;
    const Index ff = plan.first_child(f), ie = 2 * E + plan.first_inner_edge(f);
    rim.clear();
    for (Index i = 0; i < n; ++i) {
      if (is_split(h[i])) rim.push_back({first_half(h[i]), Vertex(V + Mesh::edge(h[i]).idx()), H + h[i].idx()});
      rim.push_back({last_piece(h[i]), m.to_vertex(h[i]), h[i].idx()});
    }
    for (const Rim& r : rim) {
      out.set_vertex(r.h, r.to);
      if (corner_props) hmap[r.h.idx()] = r.slot;
    }
    const Index L = Index(rim.size()), k = L - n;
    auto at = [&](Index start, Index i) -> const Rim& { return rim[(start + i) % L]; };
    auto is_edge_point = [&](Index i) { return rim[i].to.idx() >= V; };
    // Chord c from a to b; returns its side 0, which runs a -> b.
    auto chord = [&](Index c, const Rim& a, const Rim& b) {
      const Halfedge ab(2 * (ie + c)), ba(2 * (ie + c) + 1);
      out.set_vertex(ab, b.to);
      out.set_vertex(ba, a.to);
      if (corner_props) {
        hmap[ab.idx()] = b.slot;
        hmap[ba.idx()] = a.slot;
      }
      if (edge_props) emap[ie + c] = E;  // interior edges: defaults
      return ab;
    };
    Index child = 0;
    auto piece = [&](std::span<const Halfedge> halfedges) {
      const Face t(ff + child++);
      link_loop(out, t, halfedges);
      out.set_halfedge(t, halfedges[0]);
      if (face_props) fmap[t.idx()] = f;
    };
    auto triangle = [&](Halfedge a, Halfedge b, Halfedge c) {
      const Halfedge halfedges[3] = {a, b, c};
      piece(halfedges);
    };
    const Index point = plan.point_of_face(f);
    if (k == 0) {
      loop.clear();
      for (const Rim& r : rim) loop.push_back(r.h);
      piece(loop);
    } else if (point == kInvalidIndex && k == 1) {
      // A triangle: the edge point (rim j) joined to the opposite corner.
      Index j = 0;
      while (!is_edge_point(j)) ++j;
      const Halfedge d = chord(0, at(j, 0), at(j, 2));
      triangle(at(j, 1).h, at(j, 2).h, Mesh::opposite(d));
      triangle(d, at(j, 3).h, at(j, 0).h);
    } else if (point == kInvalidIndex) {
      // A triangle c0 c1 c2 whose edge c0 -> c1 stays: rim w ends at c1, then m (on c1 c2),
      // c2, m' (on c2 c0), c0. The corner triangle at c2, and the quad c0 c1 m m' cut along
      // its shorter diagonal.
      Index w = 0;
      while (is_edge_point(w) || is_edge_point((w + L - 1) % L)) ++w;
      const Vec3d c0 = to_double(m.position(at(w, 4).to)), c1 = to_double(m.position(at(w, 0).to)),
                  c2 = to_double(m.position(at(w, 2).to));
      const bool from_c0 = sqrnorm(c0 - (c1 + c2) * 0.5) < sqrnorm(c1 - (c2 + c0) * 0.5);
      const Halfedge across = chord(0, at(w, 3), at(w, 1));  // m' -> m
      triangle(at(w, 2).h, at(w, 3).h, across);
      if (from_c0) {
        const Halfedge d = chord(1, at(w, 1), at(w, 4));  // m -> c0
        triangle(at(w, 0).h, at(w, 1).h, d);
        triangle(Mesh::opposite(d), Mesh::opposite(across), at(w, 4).h);
      } else {
        const Halfedge d = chord(1, at(w, 3), at(w, 0));  // m' -> c1
        triangle(at(w, 4).h, at(w, 0).h, Mesh::opposite(d));
        triangle(d, at(w, 1).h, Mesh::opposite(across));
      }
    } else {
      // A polygon around its face point: spokes to the edge points (and with only one, to the
      // corner half way round); piece s runs along the rim from spoke s to spoke s + 1.
      std::vector<Index>& spokes = scratch.spokes;
      spokes.clear();
      for (Index i = 0; i < L; ++i)
        if (is_edge_point(i)) spokes.push_back(i);
      if (spokes.size() == 1) {
        spokes.push_back((spokes[0] + 1 + (n - 1) / 2) % L);
        std::sort(spokes.begin(), spokes.end());
      }
      const Rim centre{Halfedge(), Vertex(V + E + point), centroid_slot + point};
      const Index S = Index(spokes.size());
      for (Index s = 0; s < S; ++s) chord(s, centre, rim[spokes[s]]);
      out.set_halfedge(centre.to, Halfedge(2 * ie));
      for (Index s = 0; s < S; ++s) {
        const Index next = s + 1 == S ? 0 : s + 1;
        loop.clear();
        for (Index i = spokes[s] + 1;; ++i) {
          loop.push_back(rim[i % L].h);
          if (i % L == spokes[next]) break;
        }
        loop.push_back(Halfedge(2 * (ie + next) + 1));  // to the face point
        loop.push_back(Halfedge(2 * (ie + s)));         // and out to spoke s
        piece(loop);
      }
    }
  };
  // Faces whose every edge is split take split_face(): with everything selected, the result
  // is the one without selection_only, bit for bit.
  auto refine_face = [&](Index f, const Halfedge* h, Index n, Scratch& scratch) {
    if (!region.all() && std::any_of(h, h + n, [&](Halfedge x) { return !is_split(x); }))
      close_face(f, h, n, scratch);
    else
      split_face(f, h, n);
  };
  parallel_for(F, threads, [&](std::size_t lo, std::size_t hi) {
    std::vector<Halfedge> loop;
    Scratch scratch;
    for (Index f = Index(lo); f < hi; ++f) {
      const Halfedge h0 = m.halfedge(Face(f)), h1 = m.next(h0), h2 = m.next(h1);
      if (m.next(h2) == h0) {
        const Halfedge h[3] = {h0, h1, h2};
        refine_face(f, h, 3, scratch);
      } else {
        loop.clear();
        for (Halfedge x : m.halfedges(Face(f))) loop.push_back(x);
        refine_face(f, loop.data(), Index(loop.size()), scratch);
      }
    }
  });
  progress.update(from + 0.3 * (to - from), "subdividing: connectivity");

  // Edges: boundary half-edges split in two along their hole; edge points' half-edges.
  parallel_for(E, threads, [&](std::size_t lo, std::size_t hi) {
    for (Index e = Index(lo); e < hi; ++e) {
      const Vertex mid(V + e);
      const bool split = region.opens(Edge(e));
      for (unsigned side = 0; side < 2; ++side) {
        const Halfedge h = Mesh::halfedge(Edge(e), side);
        if (!m.is_boundary(h)) continue;
        out.set_next(last_piece(h), first_piece(m.next(h)));
        if (!split) {
          out.set_vertex(whole(h), m.to_vertex(h));
          if (corner_props) hmap[whole(h).idx()] = h.idx();
          continue;
        }
        out.set_vertex(first_half(h), mid);
        out.set_vertex(second_half(h), m.to_vertex(h));
        out.set_next(first_half(h), second_half(h));
        if (corner_props) {
          hmap[first_half(h).idx()] = default_corner;
          hmap[second_half(h).idx()] = h.idx();
        }
      }
      const Halfedge h0 = Mesh::halfedge(Edge(e), 0), h1 = Mesh::halfedge(Edge(e), 1);
      if (split) out.set_halfedge(mid, second_half(m.is_boundary(h1) ? h1 : h0));
      if (edge_props) emap[2 * e] = emap[2 * e + 1] = e;
    }
  });
  for (Index v = 0; v < V; ++v) {
    const Halfedge h = m.halfedge(Vertex(v));
    out.set_halfedge(Vertex(v), h.is_valid() ? first_piece(h) : Halfedge());
  }

  // Stencils. Added vertices: edge points 0..E-1, then face points E..E+FP-1.
  VertexRule rule;
  rule.V = V;
  rule.added = E + FP;
  rule.phases = {{E, E + FP}, {0, E}};  // edge points of Catmull–Clark read face points
  const SplitStencils stencils{m, crease, plan, region, V, E};
  switch (scheme) {
    case SubdivisionScheme::loop:
      refine_split_vertices<loop_edge_point, loop_vertex>(stencils, out, rule, threads);
      break;
    case SubdivisionScheme::catmull_clark:
      refine_split_vertices<catmull_clark_edge_point, catmull_clark_vertex>(stencils, out, rule, threads);
      break;
    case SubdivisionScheme::midpoint:
      refine_split_vertices<midpoint_edge_point, midpoint_vertex>(stencils, out, rule, threads);
      break;
    case SubdivisionScheme::sqrt3:
      throw Error("subdivide: sqrt3 has a step of its own");
  }
  progress.update(from + 0.8 * (to - from), "subdividing: attributes");

  // Corners: a midpoint corner per old inner half-edge h (between h's and prev(h)'s corners),
  // then a centroid corner per face point.
  refine_corners(m, out, std::size_t(H) + FP, hmap, threads, [&](const std::vector<Target>& all, unsigned t) {
    parallel_for(H, t, [&](std::size_t lo, std::size_t hi) {
      for (Index h = Index(lo); h < hi; ++h) {
        if (m.is_boundary(Halfedge(h))) continue;
        const Index sources[2] = {m.prev(Halfedge(h)).idx(), h};
        const float half[2] = {0.5f, 0.5f};
        for (const Target& x : all) blend(x, H + h, sources, half);
      }
    });
    parallel_for(FP, t, [&](std::size_t lo, std::size_t hi) {
      std::vector<Index> sources;
      std::vector<float> w;
      for (Index k = Index(lo); k < hi; ++k) {
        sources.clear();
        for (Halfedge x : m.halfedges(Face(plan.face_of_point[k]))) sources.push_back(x.idx());
        w.assign(sources.size(), 1.0f / float(sources.size()));
        for (const Target& x : all) blend(x, centroid_slot + k, sources, w);
      }
    });
  });
  copy_parents(m.edge_properties(), out.edge_properties(), E, emap, E2);  // no properties: only sized
  copy_parents(m.face_properties(), out.face_properties(), F, fmap, F2);
  return std::move(out);  // a reference into step: moved, not copied
}

}  // namespace hedge::subdivision
