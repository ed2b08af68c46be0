// make_delaunay (delaunay.h): Lawson's edge flips from a stack, with the checks that keep a
// surface mesh's features, seams and orientation intact.
#include "hedge/delaunay.h"

#include <cmath>
#include <cstring>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

#include "binding.h"
#include "hedge/error.h"
#include "hedge/normals.h"
#include "hedge/provenance.h"
#include "selection.h"
#include "welded_copies.h"

namespace hedge {
namespace {

//! The two triangles of interior edge e: h0 runs u -> w in face (u, w, c), h1 runs w -> u in
//! face (w, u, d). Counter-clockwise, the quad is u, d, w, c.
struct Quad {
  Halfedge h0, h1;
  Vec3d u, w, c, d;
};

Quad quad_of(const Mesh& m, Edge e) {
  Quad q;
  q.h0 = Mesh::halfedge(e, 0);
  q.h1 = Mesh::halfedge(e, 1);
  q.u = to_double(m.position(m.to_vertex(q.h1)));
  q.w = to_double(m.position(m.to_vertex(q.h0)));
  q.c = to_double(m.position(m.to_vertex(m.next(q.h0))));
  q.d = to_double(m.position(m.to_vertex(m.next(q.h1))));
  return q;
}

Vec3d normal(const Vec3d& a, const Vec3d& b, const Vec3d& c) { return cross(b - a, c - a); }

//! Angle between two normals in degrees; 0 when either is zero (a degenerate triangle bends
//! nothing, and flipping it away is what Delaunay flips are for).
double degrees_between(const Vec3d& n0, const Vec3d& n1) { return angle_between(n0, n1) * 180.0 / std::numbers::pi; }

bool is_triangle(const Mesh& m, Halfedge h) { return m.next(m.next(m.next(h))) == h; }

//! Attributes that make an edge a seam: the corner channels at its two end vertices, the face
//! channels, and build()'s record of faces it turned over (flipping across such an edge would
//! give the host triangles of both orientations).
struct Seams {
  std::vector<const ChannelArray*> corners, faces;
  const TypedArray<bool>* flipped = nullptr;

  explicit Seams(const Mesh& m) {
    for (std::size_t i = 0; i < m.halfedge_properties().count(); ++i)
      if (auto* c = m.halfedge_properties().get_channel(m.halfedge_properties().at(i).name())) corners.push_back(c);
    // Face channels label regions (materials, selections, colours), except measured values
    // that differ between any two faces of a curved surface.
    for (std::size_t i = 0; i < m.face_properties().count(); ++i) {
      const std::string& name = m.face_properties().at(i).name();
      if (name == "normal" || name == "quality") continue;
      if (auto* c = m.face_properties().get_channel(name)) faces.push_back(c);
    }
    flipped = m.face_properties().get<bool>(provenance::kFlipped);
  }

  bool differ(const ChannelArray* c, Index a, Index b) const { return !c->same(a, b); }

  bool at(const Mesh& m, const Quad& q) const {
    const Face f0 = m.face(q.h0), f1 = m.face(q.h1);
    // Corners at w: h0 in f0, prev(h1) in f1; at u: prev(h0) in f0, h1 in f1.
    for (const ChannelArray* c : corners)
      if (differ(c, q.h0.idx(), m.prev(q.h1).idx()) || differ(c, m.prev(q.h0).idx(), q.h1.idx())) return true;
    for (const ChannelArray* c : faces)
      if (differ(c, f0.idx(), f1.idx())) return true;
    return flipped && flipped->vector()[f0.idx()] != flipped->vector()[f1.idx()];
  }
};

enum class Verdict { delaunay, flip, unselected, feature, seam, blocked, fold };

//! What judge() reads besides the mesh and the options, made once per run: flips change
//! neither the channels the seams compare, nor the vertices, nor which faces are selected.
struct Context {
  Seams seams;
  detail::WeldedCopies copies;
  std::vector<std::uint8_t> selected;  //!< per face, with selection_only; empty otherwise

  Context(const Mesh& m, const DelaunayOptions& o)
      : seams(m), copies(m), selected(o.selection_only ? detail::selected_faces(m) : std::vector<std::uint8_t>()) {}
};

Verdict judge(const Mesh& m, Edge e, const DelaunayOptions& o, const Context& context) {
  const Quad q = quad_of(m, e);
  if (angle_at(q.c, q.u, q.w) + angle_at(q.d, q.u, q.w) <= std::numbers::pi + o.angle_epsilon) return Verdict::delaunay;
  const std::vector<std::uint8_t>& selected = context.selected;
  if (!selected.empty() && !(selected[m.face(q.h0).idx()] && selected[m.face(q.h1).idx()])) return Verdict::unselected;
  const Seams& seams = context.seams;
  const detail::WeldedCopies& copies = context.copies;
  const Vec3d n0 = normal(q.u, q.w, q.c), n1 = normal(q.w, q.u, q.d);
  if (degrees_between(n0, n1) > o.feature_angle) return Verdict::feature;
  if (seams.at(m, q)) return Verdict::seam;
  if (!m.is_flip_ok(e)) return Verdict::blocked;
  if (copies.meets_flip(m, e)) return Verdict::blocked;
  // The new triangles (u, d, c) and (d, w, c) must not make a feature of the new edge, nor
  // face against the old pair, nor vanish.
  const Vec3d m0 = normal(q.u, q.d, q.c), m1 = normal(q.d, q.w, q.c);
  if (sqrnorm(m0) == 0 || sqrnorm(m1) == 0) return Verdict::fold;
  if (degrees_between(m0, m1) > o.feature_angle) return Verdict::fold;
  const Vec3d up = normalize(n0) + normalize(n1);
  if (dot(m0, up) <= 0 || dot(m1, up) <= 0) return Verdict::fold;
  return Verdict::flip;
}

bool is_interior_triangle_edge(const Mesh& m, Edge e) {
  return !m.is_boundary(e) && is_triangle(m, Mesh::halfedge(e, 0)) && is_triangle(m, Mesh::halfedge(e, 1));
}

}  // namespace

double opposite_angle_sum(const Mesh& mesh, Edge e) {
  const Quad q = quad_of(mesh, e);
  return angle_at(q.c, q.u, q.w) + angle_at(q.d, q.u, q.w);
}

double dihedral_angle_degrees(const Mesh& mesh, Edge e) {
  const Quad q = quad_of(mesh, e);
  return degrees_between(normal(q.u, q.w, q.c), normal(q.w, q.u, q.d));
}

namespace {
DelaunayCensus census(const Mesh& mesh, const DelaunayOptions& options, const Context& context) {
  DelaunayCensus c;
  for (Edge e : mesh.edges()) {
    if (!is_interior_triangle_edge(mesh, e)) continue;
    ++c.interior_edges;
    const Verdict v = judge(mesh, e, options, context);
    if (v == Verdict::delaunay) continue;
    ++c.non_delaunay;
    switch (v) {
      case Verdict::feature:
        ++c.features;
        break;
      case Verdict::seam:
        ++c.seams;
        break;
      case Verdict::blocked:
        ++c.blocked;
        break;
      case Verdict::fold:
        ++c.folds;
        break;
      case Verdict::unselected:
        ++c.unselected;
        break;
      default:
        ++c.flippable;
        break;
    }
  }
  return c;
}
}  // namespace

DelaunayCensus delaunay_census(const Mesh& mesh, const DelaunayOptions& options) {
  return census(mesh, options, Context(mesh, options));
}

DelaunayReport make_delaunay(Mesh& mesh, const DelaunayOptions& options, Progress& progress) {
  std::size_t polygons = 0;
  for (Face f : mesh.faces()) polygons += !is_triangle(mesh, mesh.halfedge(f));
  if (polygons)
    throw Error("make_delaunay: needs a triangle mesh, and " + std::to_string(polygons) +
                (polygons == 1 ? " face has" : " faces have") + " more than 3 corners; triangulate first");
  if (!(options.feature_angle >= 0 && options.feature_angle <= 180))
    throw Error("make_delaunay: feature_angle must be between 0 and 180 degrees");

  DelaunayReport report;
  progress.update(0.0, "checking edges");
  // Flips happen on a copy, so a cancellation leaves the input as it was.
  std::optional<Mesh> copy;
  Mesh& work = options.keep_input_on_failure ? copy.emplace(mesh) : mesh;
  const Context context(work, options);
  report.before = census(work, options, context);

  std::vector<Index> stack;
  std::vector<char> queued(work.edges_size(), 0);
  for (Edge e : work.edges())
    if (!work.is_boundary(e)) {
      stack.push_back(e.idx());
      queued[e.idx()] = 1;
    }
  const double budget = options.flip_budget_per_edge * double(work.n_edges());
  std::size_t pops = 0;
  while (!stack.empty()) {
    const Edge e(stack.back());
    stack.pop_back();
    queued[e.idx()] = 0;
    if ((++pops & 0xffff) == 0)
      progress.update(0.05 + 0.9 * double(pops) / double(pops + stack.size()), "flipping edges");
    if (judge(work, e, options, context) != Verdict::flip) continue;
    if (double(report.flips) >= budget) {
      report.budget_exhausted = true;
      break;
    }
    work.flip(e);
    ++report.flips;
    // The four edges around the new diagonal may have lost their Delaunay property.
    for (unsigned side = 0; side < 2; ++side) {
      const Halfedge h = Mesh::halfedge(e, side);
      for (Halfedge x : {work.next(h), work.prev(h)}) {
        const Edge n = Mesh::edge(x);
        if (!queued[n.idx()] && !work.is_boundary(n)) {
          queued[n.idx()] = 1;
          stack.push_back(n.idx());
        }
      }
    }
  }
  progress.update(0.95, "checking edges");
  report.after = census(work, options, context);
  if (copy) mesh = std::move(*copy);
  if (report.flips) refresh_normal_channels(mesh, false, true);  // flipped faces have new shapes
  return report;
}

Operation make_delaunay_operation() {
  const char* help =
      "Flips edges until every interior edge is locally Delaunay (its two opposite angles sum to at most 180 "
      "degrees), which removes needless slivers without moving any vertex: Lawson's flip algorithm, on the "
      "surface. Triangle meshes only (run Triangulate first). Never flipped: boundary edges; feature edges, whose "
      "two triangles meet at a dihedral angle above feature_angle (0 = only flat regions change, 180 = ignore "
      "features); flips whose new edge would itself be a feature or turn a triangle over; seams, where UVs or "
      "other corner attributes (hard-edge normals), or face attributes such as materials, differ across the edge; "
      "flips that would "
      "duplicate an existing edge. On curved surfaces flipping stops after 50 flips per edge and the report says "
      "so. Vertices, faces and their attributes are kept; corner attributes move with their corners. The report "
      "counts flips and the edges left non-Delaunay, by reason.";
  using O = DelaunayOptions;
  using R = DelaunayReport;
  auto after = [](std::size_t DelaunayCensus::*count) {
    return [count](const O&, const R& r) -> std::optional<Value> { return field_value(r.after.*count); };
  };
  return Binding<O, R>("make_delaunay", "Make Delaunay", Category::cleaning, help, make_delaunay)
      .fixed(&O::keep_input_on_failure, false)
      .option(&O::feature_angle, "feature_angle", "Feature angle", between(0, 180),
              "edges whose faces meet at a dihedral angle above this (degrees) are features and are never "
              "flipped")
      .selection(&O::selection_only, "only edges between two selected faces are flipped")
      .result(&R::flips, "flips")
      .result("interior_edges", after(&DelaunayCensus::interior_edges))
      .result("non_delaunay_before",
              [](const O&, const R& r) -> std::optional<Value> { return field_value(r.before.non_delaunay); })
      .result("non_delaunay_after", after(&DelaunayCensus::non_delaunay))
      .result("kept_features", after(&DelaunayCensus::features))
      .result("kept_seams", after(&DelaunayCensus::seams))
      .result("blocked_by_existing_edges", after(&DelaunayCensus::blocked))
      .result("blocked_by_folds", after(&DelaunayCensus::folds))
      .result("kept_outside_selection",
              [](const O& o, const R& r) -> std::optional<Value> {
                if (!o.selection_only) return std::nullopt;
                return field_value(r.after.unselected);
              })
      .result(&R::budget_exhausted, "budget_exhausted")
      .messages([](const O&, const R& r) {
        std::vector<std::string> out;
        if (r.budget_exhausted)
          out.push_back("stopped after " + std::to_string(r.flips) +
                        " flips (50 per edge): the surface did not settle; " + std::to_string(r.after.flippable) +
                        " edges could still be flipped");
        return out;
      });
}

}  // namespace hedge
