// √3 subdivision (Kobbelt 2000; subdivide.h): one step adds a vertex per triangle and flips
// every interior old edge; every second step cuts boundary edges and creases in three.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "hedge/topology.h"
#include "parallel.h"
#include "subdivide_refine.h"
#include "welded_copies.h"

namespace hedge::subdivision {

// Kobbelt's boundary rule: every second step (`trisect`) cuts each boundary edge A -> B in
// three at Q1, Q2, and the boundary triangle's slot (A, B, P_f) becomes (A, Q1, P_f),
// (Q1, Q2, P_f), (Q2, B, P_f); positions follow the univariate ternary scheme, so two steps
// refine the boundary curve 1 -> 3 as the interior is refined 1 -> 9. A crease (`crease`, per
// edge of m, empty for none) is a boundary seen from both sides: it is never flipped, and on
// the same steps it is cut in three, each of its two triangles splitting like a boundary one.
//
// What a trisecting step adds: boundary edge k (in edge order) vertices V + F + 2k (Q1) and
// + 1 (Q2), edges E + 3F + 4k + {0: Q1-Q2, 1: Q2-B, 2: Q1-P_f, 3: Q2-P_f} (side 0 from the
// first named vertex) and faces 3F + 2k + {0, 1}; the old edge keeps A-Q1. Then crease c (in
// edge order), A -> B its side-0 half-edge: vertices V + F + 2B + 2c + {0: Q1, 1: Q2}, edges
// E + 3F + 4B + 6c + {0: Q1-Q2, 1: Q2-B} and, for its side s, + 2 + 2s (the spoke from the Q
// nearer that side's origin to its face point) and + 3 + 2s (from the other Q), and faces
// 3F + 2B + 4c + 2s + {0, 1}. On return `crease` is per edge of the result.
//
// With selection_only (`region`), an edge that the region does not open is held like a
// boundary seen from both sides, never flipped and never cut, and a face outside it keeps its
// half-edges as face 3f; its point V + f, spokes and faces 3f + 1, 3f + 2 stay unlinked
// (drop_unlinked()). Only the boundary edges and creases the region opens are cut.
Mesh sqrt3_step(const Mesh& m, bool trisect, std::vector<bool>& crease, const Region& region, unsigned threads,
                Progress& progress, double from, double to) {
  const Index V = Index(m.vertices_size()), E = Index(m.edges_size()), F = Index(m.faces_size());
  const Index H = 2 * E;
  const bool creases = !crease.empty();
  std::vector<Index> boundary_number;    // edge -> k for boundary edges that are cut
  std::vector<Halfedge> boundary_inner;  // k -> the edge's half-edge inside its face
  std::vector<Index> crease_number;      // edge -> c for creases (all are cut)
  std::vector<Edge> cut_creases;         // c -> the edge
  if (trisect) {
    // Seams of split non-manifold edges stay as they are: the input's surface goes on there,
    // and their two sides must stay alike to weld back.
    const std::vector<bool> seam = split_seam_edges(m);
    boundary_number.assign(E, kInvalidIndex);
    for (Index e = 0; e < E; ++e)
      for (unsigned side = 0; side < 2; ++side)
        if (m.is_boundary(Mesh::halfedge(Edge(e), side)) && (seam.empty() || !seam[e]) && region.opens(Edge(e))) {
          boundary_number[e] = Index(boundary_inner.size());
          boundary_inner.push_back(Mesh::halfedge(Edge(e), 1 - side));
        }
    if (creases) {
      crease_number.assign(E, kInvalidIndex);
      for (Index e = 0; e < E; ++e)
        if (crease[e] && region.opens(Edge(e))) {
          crease_number[e] = Index(cut_creases.size());
          cut_creases.push_back(Edge(e));
        }
    }
  }
  const std::size_t B = boundary_inner.size(), C = cut_creases.size();
  check_index_range(std::size_t(V) + F + 2 * B + 2 * C, std::size_t(E) + 3 * std::size_t(F) + 4 * B + 6 * C,
                    3 * std::size_t(F) + 2 * B + 4 * C);
  const Index V2 = Index(V + F + 2 * B + 2 * C), E2 = Index(E + 3 * F + 4 * B + 6 * C);
  const Index F2 = Index(3 * F + 2 * B + 4 * C);
  // Where the creases' additions start: vertices, edges, faces, corner slots.
  const Index crease_vertex0 = Index(V + F + 2 * B), crease_edge0 = Index(E + 3 * F + 4 * B);
  const Index crease_face0 = Index(3 * F + 2 * B), crease_slot0 = Index(H + F + 2 * B);
  auto extra_halfedge = [&](Index k, Index which, unsigned side) {
    return Halfedge(2 * (E + 3 * F + 4 * k + which) + side);
  };
  auto crease_halfedge = [&](Index c, Index which, unsigned side) {
    return Halfedge(2 * (crease_edge0 + 6 * c + which) + side);
  };
  auto is_crease = [&](Edge e) { return creases && crease[e.idx()]; };
  auto is_cut_crease = [&](Edge e) { return trisect && creases && crease_number[e.idx()] != kInvalidIndex; };
  // An interior edge that extract()'s weld makes one with another (a split non-manifold
  // edge) is not flipped either, nor cut: flipping one copy would leave the others' faces
  // on an edge that no longer exists, and its ends with fans that no longer meet.
  std::vector<bool> welded;
  if (const detail::WeldedCopies copies(m); copies.any()) {
    welded.assign(E, false);
    for (Edge e : m.edges())
      welded[e.idx()] = !m.is_boundary(e) && copies.edge_elsewhere(m, m.vertex(e, 0), m.vertex(e, 1), e);
  }
  auto is_welded = [&](Edge e) { return !welded.empty() && welded[e.idx()]; };
  // is_cut(g): g's edge is a boundary edge cut on this step. boundary_out(g), for a boundary
  // half-edge g: the half-edge that then leaves g's origin B along the boundary (B -> Q2), g
  // itself when its edge is not cut.
  auto is_cut = [&](Halfedge g) { return trisect && boundary_number[Mesh::edge(g).idx()] != kInvalidIndex; };
  auto boundary_out = [&](Halfedge g) {
    return is_cut(g) ? extra_halfedge(boundary_number[Mesh::edge(g).idx()], 1, 1) : g;
  };

  // Corner number of every inner half-edge in its triangle (halfedge(f) is corner 0).
  std::vector<std::uint8_t> corner(H, 0);
  parallel_for(F, threads, [&](std::size_t lo, std::size_t hi) {
    for (Index f = Index(lo); f < hi; ++f) {
      Halfedge h = m.halfedge(Face(f));
      for (std::uint8_t i = 0; i < 3; ++i, h = m.next(h)) corner[h.idx()] = i;
    }
  });

  StepOutput step(m, V2, E2, F2);
  Mesh& out = step.out;
  const bool corner_props = step.corner_props, edge_props = step.edge_props, face_props = step.face_props;
  std::vector<Index>&hmap = step.hmap, &emap = step.emap, &fmap = step.fmap;

  // Spoke (f, i) joins face point P_f and corner c_i; side 0 runs P_f -> c_i. The old inner
  // half-edge h = h_i of f (pointing to c_i) keeps its index: when its edge is interior it
  // becomes P_f -> P_g (g the face across), and triangle 3f + i is (c_i, P_f, P_g); on the
  // boundary or a crease it stays, and triangle 3f + i is (c_{i-1}, c_i, P_f).
  auto spoke = [&](Index f, Index i, unsigned side) { return Halfedge(2 * (E + 3 * f + i % 3) + side); };

  // The cut of the side of an edge A -> B that lies in face f (h its half-edge there, corner
  // i): `first`, `mid` and `last` run A -> near -> far -> B, x and y are the spokes near ->
  // P_f and far -> P_f, and triangle 3f + i becomes (A, near, P_f), t1 (near, far, P_f) and
  // t2 (far, B, P_f); the corner slots hold the corners at near and far.
  struct CutSide {
    Halfedge first, mid, last, x, y;
    Vertex near, far;
    Face t1, t2;
    Index near_slot, far_slot;
  };
  auto cut_side = [&](Index f, Index i, Halfedge h, const CutSide& c) {
    const Vertex pf(V + f);
    const Halfedge to_a = spoke(f, i + 2, 0), a = spoke(f, i, 1);  // P_f -> A, B -> P_f
    out.set_vertex(c.first, c.near);
    out.set_vertex(c.mid, c.far);
    out.set_vertex(c.last, m.to_vertex(h));
    out.set_vertex(c.x, pf);
    out.set_vertex(Mesh::opposite(c.x), c.near);
    out.set_vertex(c.y, pf);
    out.set_vertex(Mesh::opposite(c.y), c.far);
    const Halfedge loops[3][3] = {
        {c.first, c.x, to_a}, {c.mid, c.y, Mesh::opposite(c.x)}, {c.last, a, Mesh::opposite(c.y)}};
    const Face faces[3] = {Face(3 * f + i), c.t1, c.t2};
    for (int j = 0; j < 3; ++j) {
      link_loop(out, faces[j], {loops[j][0], loops[j][1], loops[j][2]});
      out.set_halfedge(faces[j], loops[j][0]);
      if (face_props) fmap[faces[j].idx()] = f;
    }
    if (corner_props) {
      hmap[c.first.idx()] = c.near_slot;
      hmap[c.x.idx()] = H + f;
      hmap[to_a.idx()] = m.prev(h).idx();
      hmap[c.mid.idx()] = c.far_slot;
      hmap[c.y.idx()] = H + f;
      hmap[Mesh::opposite(c.x).idx()] = c.near_slot;
      hmap[c.last.idx()] = h.idx();
      hmap[a.idx()] = H + f;
      hmap[Mesh::opposite(c.y).idx()] = c.far_slot;
    }
    if (edge_props) emap[Mesh::edge(c.x).idx()] = emap[Mesh::edge(c.y).idx()] = emap[E + 3 * f + i] = E;
  };

  parallel_for(F, threads, [&](std::size_t lo, std::size_t hi) {
    for (Index f = Index(lo); f < hi; ++f) {
      if (!region.refines(Face(f))) {
        // Outside the selection: the same loop, as face 3f.
        const Face t(3 * f);
        for (Halfedge h : m.halfedges(Face(f))) {
          out.set_vertex(h, m.to_vertex(h));
          out.set_next(h, m.next(h));
          out.set_face(h, t);
          if (corner_props) hmap[h.idx()] = h.idx();
        }
        out.set_halfedge(t, m.halfedge(Face(f)));
        if (face_props) fmap[t.idx()] = f;
        continue;
      }
      const Vertex pf(V + f);
      Halfedge h = m.halfedge(Face(f));
      for (Index i = 0; i < 3; ++i, h = m.next(h)) {
        const Face t(3 * f + i);
        out.set_vertex(spoke(f, i, 0), m.to_vertex(h));
        out.set_vertex(spoke(f, i, 1), pf);
        const Halfedge g = Mesh::opposite(h);
        const Edge e = Mesh::edge(h);
        const Halfedge a = spoke(f, i, 1);
        const bool boundary = m.is_boundary(g), sharp = boundary || is_crease(e) || is_welded(e) || !region.opens(e);
        if (boundary && is_cut(g)) {
          const Index k = boundary_number[e.idx()];
          const Vertex q1(V + F + 2 * k), q2(V + F + 2 * k + 1);
          const Halfedge s1 = extra_halfedge(k, 0, 0), s2 = extra_halfedge(k, 1, 0);
          const Index slot = H + F + 2 * k;
          cut_side(f, i, h,
                   {h, s1, s2, extra_halfedge(k, 2, 0), extra_halfedge(k, 3, 0), q1, q2, Face(3 * F + 2 * k),
                    Face(3 * F + 2 * k + 1), slot, slot + 1});
          // Along the boundary: B -> Q2 -> Q1 -> A (g keeps Q1 -> A; the edge loop links g on).
          out.set_vertex(Mesh::opposite(s1), q1);
          out.set_vertex(Mesh::opposite(s2), q2);
          out.set_next(Mesh::opposite(s2), Mesh::opposite(s1));
          out.set_next(Mesh::opposite(s1), g);
          out.set_halfedge(q1, g);
          out.set_halfedge(q2, Mesh::opposite(s1));
          if (corner_props) hmap[Mesh::opposite(s1).idx()] = hmap[Mesh::opposite(s2).idx()] = g.idx();  // defaults
          if (edge_props) emap[Mesh::edge(s1).idx()] = emap[Mesh::edge(s2).idx()] = e.idx();
          continue;
        }
        if (is_cut_crease(e)) {
          // A crease: its side 0 runs A -> Q1 -> Q2 -> B, side 1 B -> Q2 -> Q1 -> A.
          const Index c = crease_number[e.idx()];
          const unsigned side = h == Mesh::halfedge(e, 0) ? 0 : 1;
          const Vertex q1(crease_vertex0 + 2 * c), q2(crease_vertex0 + 2 * c + 1);
          const Halfedge x = crease_halfedge(c, 2 + 2 * side, 0), y = crease_halfedge(c, 3 + 2 * side, 0);
          const Face t1(crease_face0 + 4 * c + 2 * side), t2(crease_face0 + 4 * c + 2 * side + 1);
          const Index slot = crease_slot0 + 4 * c + 2 * side;
          if (side == 0) {
            cut_side(f, i, h,
                     {h, crease_halfedge(c, 0, 0), crease_halfedge(c, 1, 0), x, y, q1, q2, t1, t2, slot, slot + 1});
            // The elements both sides share, written once.
            out.set_halfedge(q1, x);
            out.set_halfedge(q2, y);
            if (edge_props) emap[crease_edge0 + 6 * c] = emap[crease_edge0 + 6 * c + 1] = e.idx();
          } else {
            cut_side(f, i, h,
                     {crease_halfedge(c, 1, 1), crease_halfedge(c, 0, 1), h, x, y, q2, q1, t1, t2, slot, slot + 1});
          }
          continue;
        }
        Halfedge b, c;
        if (sharp) {
          out.set_vertex(h, m.to_vertex(h));
          b = spoke(f, i + 2, 0);  // P_f -> c_{i-1}
          c = h;
          out.set_halfedge(t, h);
          if (corner_props) {
            hmap[h.idx()] = h.idx();
            hmap[b.idx()] = m.prev(h).idx();
          }
        } else {
          const Index fg = m.face(g).idx();
          out.set_vertex(h, Vertex(V + fg));
          b = h;
          c = spoke(fg, corner[m.prev(g).idx()], 0);  // P_g -> c_i
          out.set_halfedge(t, c);
          if (corner_props) {
            hmap[h.idx()] = H + fg;  // the centroid corner of g
            hmap[c.idx()] = h.idx();
          }
        }
        // a: c_i -> P_f, then b, then c back to a's origin.
        link_loop(out, t, {a, b, c});
        if (corner_props) hmap[a.idx()] = H + f;
        if (face_props) fmap[t.idx()] = f;
        if (edge_props) emap[E + 3 * f + i] = E;
      }
      out.set_halfedge(pf, spoke(f, 0, 0));
    }
  });
  progress.update(from + 0.3 * (to - from), "subdividing: connectivity");
  parallel_for(E, threads, [&](std::size_t lo, std::size_t hi) {
    for (Index e = Index(lo); e < hi; ++e) {
      for (unsigned side = 0; side < 2; ++side) {
        const Halfedge h = Mesh::halfedge(Edge(e), side);
        if (!m.is_boundary(h)) continue;
        out.set_vertex(h, m.to_vertex(h));
        out.set_next(h, boundary_out(m.next(h)));
        if (corner_props) hmap[h.idx()] = h.idx();
      }
      if (edge_props) emap[e] = e;
    }
  });
  // Old vertices: boundary ones keep their boundary half-edge; interior ones leave along a
  // spoke, since their old edges were flipped away (or along their old half-edge when its
  // face is outside the selection, where nothing changed).
  for (Index v = 0; v < V; ++v) {
    const Halfedge h = m.halfedge(Vertex(v));
    if (!h.is_valid() || m.is_boundary(h)) {
      out.set_halfedge(Vertex(v), h.is_valid() ? boundary_out(h) : h);
    } else if (!region.refines(m.face(h))) {
      out.set_halfedge(Vertex(v), h);
    } else {
      const Halfedge in = m.prev(h);  // points to v inside face(h)
      out.set_halfedge(Vertex(v), spoke(m.face(h).idx(), corner[in.idx()], 1));
    }
  }

  VertexRule rule;
  rule.V = V;
  rule.added = Index(F + 2 * B + 2 * C);
  rule.phases = {{0, rule.added}};
  auto added = [&](Index n, Stencil& s) {
    if (n < F) {
      for (Vertex c : m.vertices(Face(n))) s.add(c.idx(), 1.0f / 3.0f);
      return;
    }
    // The ternary rule: the point a third of the way from A to B is (10 B + 16 A + A') / 27,
    // A' being A's other neighbour along the boundary or crease.
    const bool on_boundary = n < F + 2 * B;
    const Index j = on_boundary ? n - F : n - F - Index(2 * B);
    const Halfedge h = on_boundary ? boundary_inner[j / 2] : Mesh::halfedge(cut_creases[j / 2], 0);
    const bool near_a = j % 2 == 0;
    const Vertex near = near_a ? m.from_vertex(h) : m.to_vertex(h), far = near_a ? m.to_vertex(h) : m.from_vertex(h);
    Vertex beyond;
    if (!creases) {
      const Halfedge g = Mesh::opposite(h);
      beyond = near_a ? m.to_vertex(m.next(g)) : m.from_vertex(m.prev(g));
    } else {
      const SharpEdges sharp = sharp_edges(m, crease, near);
      if (sharp.count != 2) {
        // A corner or a dart ends the curve there: the linear rule, as for a reflected A'.
        s.add(near.idx(), 2.0f / 3);
        s.add(far.idx(), 1.0f / 3);
        return;
      }
      beyond = m.to_vertex(sharp.out[Mesh::edge(sharp.out[0]) == Mesh::edge(h) ? 1 : 0]);
    }
    s.add(beyond.idx(), 1.0f / 27);
    s.add(near.idx(), 16.0f / 27);
    s.add(far.idx(), 10.0f / 27);
  };
  auto even = [&](Vertex v, Stencil& s) {
    if (!region.moves(v)) {
      s.add(v.idx(), 1.0f);  // on the border of the selection or outside it: stays
      return;
    }
    if (creases && m.halfedge(v).is_valid()) {
      // As for Loop: a corner (three or more sharp edges) stays, a vertex on two follows the
      // curve rule along them (here the boundary's), a dart (one) the smooth rule.
      const SharpEdges sharp = sharp_edges(m, crease, v);
      auto cut = [&](Halfedge h) { return is_cut(h) || is_cut_crease(Mesh::edge(h)); };
      if (sharp.count >= 3 || (sharp.count == 2 && (!cut(sharp.out[0]) || !cut(sharp.out[1])))) {
        s.add(v.idx(), 1.0f);
        return;
      }
      if (sharp.count == 2) {
        s.add(m.to_vertex(sharp.out[0]).idx(), 4.0f / 27);
        s.add(v.idx(), 19.0f / 27);
        s.add(m.to_vertex(sharp.out[1]).idx(), 4.0f / 27);
        return;
      }
    }
    if (m.is_boundary(v)) {
      const Halfedge out_h = m.halfedge(v);  // boundary: v -> next along the boundary
      // The boundary curve waits for the next step; isolated vertices and seams stay.
      if (!out_h.is_valid() || !is_cut(out_h) || !is_cut(m.prev(out_h))) {
        s.add(v.idx(), 1.0f);
        return;
      }
      s.add(m.from_vertex(m.prev(out_h)).idx(), 4.0f / 27);
      s.add(v.idx(), 19.0f / 27);
      s.add(m.to_vertex(out_h).idx(), 4.0f / 27);
      return;
    }
    // One walk around v gathers the ring; the weights depend on its size, set afterwards.
    s.add(v.idx(), 0.0f);
    for (Vertex w : m.vertices(v)) s.add(w.idx(), 0.0f);
    const std::size_t n = s.size() - 1;
    const double alpha = tabulated<sqrt3_alpha_formula>(n);
    s.weight(0) = float(1.0 - alpha);
    for (std::size_t i = 1; i <= n; ++i) s.weight(i) = float(alpha / double(n));
  };
  refine_vertices(m, out, rule, threads, added, even);
  progress.update(from + 0.8 * (to - from), "subdividing: attributes");

  refine_corners(m, out, F + 2 * B + 4 * C, hmap, threads, [&](const std::vector<Target>& all, unsigned t) {
    parallel_for(F, t, [&](std::size_t lo, std::size_t hi) {
      const float third[3] = {1.0f / 3, 1.0f / 3, 1.0f / 3};
      for (Index f = Index(lo); f < hi; ++f) {
        const Halfedge h = m.halfedge(Face(f));
        const Index sources[3] = {h.idx(), m.next(h).idx(), m.prev(h).idx()};
        for (const Target& x : all) blend(x, H + f, sources, third);
      }
    });
    // Corners at Q1 and Q2 lie on the edge A -> B of their face: a third and two thirds along.
    const float near_a[2] = {2.0f / 3, 1.0f / 3}, near_b[2] = {1.0f / 3, 2.0f / 3};
    auto blend_cut = [&](Halfedge h, std::size_t slot) {
      const Index sources[2] = {m.prev(h).idx(), h.idx()};  // the corners at A and B
      for (const Target& x : all) {
        blend(x, slot, sources, near_a);
        blend(x, slot + 1, sources, near_b);
      }
    };
    parallel_for(B, t, [&](std::size_t lo, std::size_t hi) {
      for (std::size_t k = lo; k < hi; ++k) blend_cut(boundary_inner[k], H + F + 2 * k);
    });
    parallel_for(C, t, [&](std::size_t lo, std::size_t hi) {
      for (std::size_t c = lo; c < hi; ++c)
        for (unsigned side = 0; side < 2; ++side)
          blend_cut(Mesh::halfedge(cut_creases[c], side), crease_slot0 + 4 * c + 2 * side);
    });
  });
  copy_parents(m.edge_properties(), out.edge_properties(), E, emap, E2);  // no properties: only sized
  copy_parents(m.face_properties(), out.face_properties(), F, fmap, F2);
  if (creases) {
    // The old edges keep their flags (interior ones were flipped only if smooth); a cut
    // crease's two new pieces are creases, the spokes are not.
    std::vector<bool> next(E2, false);
    for (Index e = 0; e < E; ++e) next[e] = crease[e];
    for (std::size_t c = 0; c < C; ++c) next[crease_edge0 + 6 * c] = next[crease_edge0 + 6 * c + 1] = true;
    crease = std::move(next);
  }
  return std::move(out);  // a reference into step: moved, not copied
}

}  // namespace hedge::subdivision
