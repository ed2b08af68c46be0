// Subdivision surfaces (subdivide.h). Every step writes the refined mesh into fresh arrays:
// each child half-edge, edge and face has an index computed from its parent's, so building
// the connectivity needs no search and no Euler operation, and the stencils run on two threads.
// The steps are in subdivide_split.cpp (Loop, Catmull–Clark, midpoint) and subdivide_sqrt3.cpp,
// what they share in subdivide_refine.h; here: the checks before a run, the run and the binding.
#include "hedge/subdivide.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <optional>
#include <string>
#include <tuple>
#include <vector>

#include "binding.h"
#include "hedge/error.h"
#include "hedge/limits.h"
#include "hedge/normals.h"
#include "hedge/provenance.h"
#include "hedge/topology.h"
#include "selection.h"
#include "subdivide_refine.h"

namespace hedge {
namespace {

using subdivision::detect_creases;
using subdivision::drop_unlinked;
using subdivision::face_size;
using subdivision::Region;
using subdivision::split_creases;
using subdivision::split_step;
using subdivision::sqrt3_step;

//! On non-manifold input, build() split edges into copies of one input edge. Each copy gets
//! its own edge point (vertex V + e of a split step); giving them one new source lets
//! extract() weld them, so the host's surface keeps the input's edge and gets no crack
//! (the welded point takes the first copy's position). New sources are numbered after the
//! largest one in use, in the order of the welded edges they sit on.
void weld_split_edge_points(const Mesh& before, Mesh& after) {
  const auto* old_source = before.vertex_properties().get<std::uint32_t>(provenance::kVertexSource);
  auto* source = after.vertex_properties().get<std::uint32_t>(provenance::kVertexSource);
  if (!old_source || !source) return;
  const Index V = Index(before.vertices_size());
  std::uint64_t next = 0;
  for (std::uint32_t s : old_source->vector())
    if (s != kInvalidIndex) next = std::max<std::uint64_t>(next, std::uint64_t(s) + 1);
  auto welded = [&](Vertex v) -> std::uint64_t {
    const std::uint32_t s = old_source->vector()[v.idx()];
    return s != kInvalidIndex ? s : (std::uint64_t(1) << 32) + v.idx();  // unique when it has none
  };
  std::vector<std::tuple<std::uint64_t, std::uint64_t, Index>> edges;  // (welded ends, edge)
  for (Edge e : before.edges()) {
    const std::uint64_t a = welded(before.vertex(e, 0)), b = welded(before.vertex(e, 1));
    edges.emplace_back(std::min(a, b), std::max(a, b), e.idx());
  }
  std::sort(edges.begin(), edges.end());
  auto same = [&](std::size_t i, std::size_t j) {
    return std::get<0>(edges[i]) == std::get<0>(edges[j]) && std::get<1>(edges[i]) == std::get<1>(edges[j]);
  };
  for (std::size_t i = 0; i < edges.size();) {
    std::size_t j = i + 1;
    while (j < edges.size() && same(i, j)) ++j;
    // Copies on one face (a face that visits both ends twice) keep their points apart:
    // welded, they would make that face's pieces one face twice over.
    std::vector<std::vector<Index>> classes;
    for (std::size_t k = i; k < j && j - i > 1; ++k) {
      const Edge e(std::get<2>(edges[k]));
      auto shares_face = [&](Index other) {
        for (unsigned a = 0; a < 2; ++a)
          for (unsigned b = 0; b < 2; ++b)
            if (Face f = before.face(e, a); f.is_valid() && f == before.face(Edge(other), b)) return true;
        return false;
      };
      auto fits = std::find_if(classes.begin(), classes.end(),
                               [&](const auto& c) { return std::none_of(c.begin(), c.end(), shares_face); });
      if (fits == classes.end()) fits = classes.insert(classes.end(), std::vector<Index>{});
      fits->push_back(e.idx());
    }
    for (const auto& c : classes) {
      if (c.size() < 2) continue;
      if (next >= kInvalidIndex) return;  // out of numbers: leave the rest unwelded
      for (Index e : c) source->vector()[V + e] = std::uint32_t(next);
      ++next;
    }
    i = j;
  }
}

//! Faces by kind, in one pass: what the refusals and the size forecast need.
struct FaceCensus {
  std::size_t faces = 0, triangles = 0, corners = 0;  //!< of the faces refined
  std::size_t kept = 0;                               //!< with selection_only: faces left as they are
  //! What a trisecting sqrt3 step cuts (count_sqrt3_cuts): boundary edges but seams, creases.
  std::size_t boundary_edges = 0, crease_edges = 0;
};

//! `selected`: per face, empty for all (selection_only off).
FaceCensus face_census(const Mesh& mesh, const std::vector<std::uint8_t>& selected = {}) {
  FaceCensus c;
  for (Face f : mesh.faces()) {
    if (!selected.empty() && !selected[f.idx()]) {
      ++c.kept;
      continue;
    }
    const Index n = face_size(mesh, f);
    ++c.faces;
    c.triangles += n == 3;
    c.corners += n;
  }
  return c;
}

//! Fills in what sqrt3 cuts on its even steps (sqrt3_step): boundary edges other than the seams
//! of split non-manifold edges, and the creases (`crease`, per edge, empty for none); with
//! selection_only (`region` not all()) only those it opens. Others need no such count.
void count_sqrt3_cuts(const Mesh& mesh, const SubdivideOptions& options, const std::vector<bool>& crease,
                      const Region& region, FaceCensus& c) {
  if (options.scheme != SubdivisionScheme::sqrt3 || options.iterations < 2) return;
  std::vector<bool> seam;
  bool seams_found = false;
  for (Edge e : mesh.edges()) {
    if (!region.opens(e)) continue;
    c.crease_edges += !crease.empty() && crease[e.idx()];
    if (!mesh.is_boundary(e)) continue;
    if (!seams_found) seam = split_seam_edges(mesh), seams_found = true;
    c.boundary_edges += seam.empty() || !seam[e.idx()];
  }
}

//! Corner normals were blended inside each face (hard edges stay hard): back to unit length.
void normalize_corner_normals(Mesh& mesh) {
  ChannelArray* c = mesh.halfedge_properties().get_channel("normal");
  if (!c || c->scalar() != ScalarType::f32 || c->components() != 3) return;
  for (std::size_t i = 0; i < c->size(); ++i) {
    Vec3f n;
    std::memcpy(&n, c->element(i), sizeof n);
    n = normalize(n);
    std::memcpy(c->element(i), &n, sizeof n);
  }
}

//! Faces that the refined faces of the census become (with selection_only an upper bound: as
//! if every edge of theirs were split; a closure makes fewer).
std::size_t forecast_refined(const FaceCensus& c, const SubdivideOptions& options) {
  if (options.iterations <= 0 || c.faces == 0) return c.faces;
  // Doubles, so that absurd requests compare as huge instead of wrapping around.
  double first = 0;
  switch (options.scheme) {
    case SubdivisionScheme::loop:
      first = 4.0 * double(c.faces);
      break;
    case SubdivisionScheme::sqrt3:
      first = 3.0 * double(c.faces);
      break;
    case SubdivisionScheme::catmull_clark:
      first = double(c.corners);
      break;
    case SubdivisionScheme::midpoint:
      first = 4.0 * double(c.triangles) + double(c.corners - 3 * c.triangles);
      break;
  }
  if (options.scheme == SubdivisionScheme::sqrt3 && (c.boundary_edges || c.crease_edges)) {
    // Every second step cuts each boundary edge in three, adding two triangles for each, and
    // each crease, adding two on either side.
    double faces = double(c.faces), boundary = double(c.boundary_edges), creases = double(c.crease_edges);
    for (int it = 0; it < options.iterations && faces < 1e18; ++it) {
      faces *= 3;
      if (it % 2 == 1) {
        faces += 2 * boundary + 4 * creases;
        boundary *= 3;
        creases *= 3;
      }
    }
    return faces >= 1e18 ? std::size_t(1e18) : std::size_t(faces);
  }
  const double factor = options.scheme == SubdivisionScheme::sqrt3 ? 3.0 : 4.0;
  const double total = first * std::pow(factor, options.iterations - 1);
  return total >= 1e18 ? std::size_t(1e18) : std::size_t(total);
}

std::size_t forecast_faces(const FaceCensus& c, const SubdivideOptions& options) {
  return std::min(forecast_refined(c, options), std::size_t(1e18) - c.kept) + c.kept;
}

//! Refuses, before starting, subdivisions whose vertices, half-edges or faces would not fit
//! the 32-bit indices (whatever max_faces allows): the counts of every step, in doubles so
//! that nothing wraps. Each step of loop, midpoint and catmull_clark splits every edge and
//! adds an edge per corner inside each face; sqrt3 keeps the edges and adds 3 per triangle,
//! and every second step cuts boundary edges and creases in three (sqrt3_step).
void check_index_limits(const Mesh& mesh, const FaceCensus& census, const SubdivideOptions& options, const char* name) {
  double v = double(mesh.n_vertices()), e = double(mesh.n_edges()), f = double(census.faces);
  double t = double(census.triangles), c = double(census.corners);
  double boundary = double(census.boundary_edges), creases = double(census.crease_edges);
  for (int it = 1; it <= options.iterations; ++it) {
    switch (options.scheme) {
      case SubdivisionScheme::loop:
      case SubdivisionScheme::midpoint:
      case SubdivisionScheme::catmull_clark: {
        const bool quads = options.scheme == SubdivisionScheme::catmull_clark;
        const double polygons = f - t;
        v += e + (quads ? f : polygons);
        e = 2 * e + c;
        const double new_triangles = quads ? 0 : 4 * t;
        f = quads ? c : new_triangles + (c - 3 * t);
        c = quads ? 4 * c : 3 * new_triangles + 4 * (c - 3 * t);
        t = new_triangles;
        break;
      }
      case SubdivisionScheme::sqrt3:
        v += f;
        e += 3 * f;
        f *= 3;
        if (it % 2 == 0) {
          v += 2 * (boundary + creases);
          e += 4 * boundary + 6 * creases;
          f += 2 * boundary + 4 * creases;
          boundary *= 3;
          creases *= 3;
        }
        t = f;
        c = 3 * f;
        break;
    }
    const char* what = nullptr;
    double count = 0, limit = 0;
    if (2 * e > double(kMaxHalfedges)) {
      what = "half-edges", count = 2 * e, limit = double(kMaxHalfedges);
    } else if (v > double(kMaxElements)) {
      what = "vertices", count = v, limit = double(kMaxElements);
    } else if (f > double(kMaxElements)) {
      what = "faces", count = f, limit = double(kMaxElements);
    }
    if (what)
      throw Error("subdivide: " + std::to_string(options.iterations) + " iterations of " + name + " would need " +
                  with_commas(count >= 1e19 ? std::uint64_t(1e19) : std::uint64_t(count)) + " " + what + " at step " +
                  std::to_string(it) + ", but hedge's 32-bit indices hold at most " +
                  with_commas(std::uint64_t(limit)) + " " + what + "; " +
                  (it == 1 ? std::string("this mesh is too large to subdivide with this scheme")
                           : "use at most " + std::to_string(it - 1) + (it == 2 ? " iteration" : " iterations")));
  }
}

}  // namespace

const char* subdivision_scheme_name(SubdivisionScheme scheme) {
  switch (scheme) {
    case SubdivisionScheme::loop:
      return "loop";
    case SubdivisionScheme::catmull_clark:
      return "catmull_clark";
    case SubdivisionScheme::sqrt3:
      return "sqrt3";
    case SubdivisionScheme::midpoint:
      return "midpoint";
  }
  return "unknown";
}

std::size_t subdivided_face_count(const Mesh& mesh, const SubdivideOptions& options) {
  FaceCensus census =
      face_census(mesh, options.selection_only ? detail::selected_faces(mesh) : std::vector<std::uint8_t>());
  if (options.scheme == SubdivisionScheme::sqrt3 && options.iterations >= 2) {
    std::vector<bool> crease;
    if (options.crease_angle < 180) crease = detect_creases(mesh, options.crease_angle);
    count_sqrt3_cuts(mesh, options, crease, options.selection_only ? subdivision::selected_region(mesh) : Region(),
                     census);
  }
  return forecast_faces(census, options);
}

SubdivideReport subdivide(Mesh& mesh, const SubdivideOptions& options, Progress& progress) {
  const char* name = subdivision_scheme_name(options.scheme);
  if (options.iterations < 1) throw Error("subdivide: iterations must be 1 or more");
  if (!(options.crease_angle >= 0 && options.crease_angle <= 180))
    throw Error("subdivide: crease_angle must be from 0 to 180 degrees");
  const bool triangles_only = options.scheme == SubdivisionScheme::loop || options.scheme == SubdivisionScheme::sqrt3;
  // With selection_only, what is refined: the selected faces (only they must be triangles).
  const FaceCensus faces =
      face_census(mesh, options.selection_only ? detail::selected_faces(mesh) : std::vector<std::uint8_t>());
  const std::size_t faces_before = mesh.n_faces();
  if (options.selection_only && faces.faces == 0) {
    // Nothing selected: nothing changes (the binding says so); no step was made.
    SubdivideReport report;
    report.faces_before = report.faces = faces_before;
    report.vertices = mesh.n_vertices();
    report.edges = mesh.n_edges();
    return report;
  }
  if (triangles_only) {
    if (std::size_t polygons = faces.faces - faces.triangles)
      throw Error(std::string("subdivide: the ") + name + " scheme works on triangle meshes, and " +
                  std::to_string(polygons) + (options.selection_only ? " selected" : "") +
                  (polygons == 1 ? " face has" : " faces have") +
                  " more than 3 corners; triangulate first, or use catmull_clark or midpoint");
  }

  // The steps read `current` and write a fresh mesh; the input is replaced only at the end,
  // so an error or a cancellation leaves it as it was.
  Mesh compacted;
  const Mesh* current = &mesh;
  if (mesh.has_garbage()) {
    compacted = mesh;
    compacted.compact();
    current = &compacted;
  }
  // Creases are found once, on the input; later steps carry them to the pieces of their edges.
  // (midpoint's rules are linear before they look at creases: found only for the report.)
  std::vector<bool> crease;
  std::size_t crease_edges = 0;
  if (options.crease_angle < 180) {
    crease = detect_creases(*current, options.crease_angle);
    crease_edges = std::size_t(std::count(crease.begin(), crease.end(), true));
    if (crease_edges == 0) crease.clear();
  }
  // A step allocates for every edge and face (drop_unlinked() then removes what a selection
  // left unused), so the index limits count the whole mesh; the forecast what is refined.
  FaceCensus whole = options.selection_only ? face_census(*current) : faces;
  count_sqrt3_cuts(*current, options, crease, Region(), whole);
  check_index_limits(*current, whole, options, name);
  FaceCensus census = whole;
  if (options.selection_only) {
    census = faces;
    count_sqrt3_cuts(*current, options, crease, subdivision::selected_region(*current), census);
  }
  const std::size_t predicted = forecast_faces(census, options);
  if (predicted > options.max_faces)
    throw Error("subdivide: " + std::to_string(options.iterations) + " iterations of " + name + " would make " +
                std::to_string(predicted) + " faces, more than the limit of " + std::to_string(options.max_faces) +
                "; use fewer iterations");
  Mesh result;
  for (int it = 0; it < options.iterations; ++it) {
    const double from = double(it) / options.iterations, to = double(it + 1) / options.iterations;
    progress.update(from, "subdividing: step " + std::to_string(it + 1) + " of " + std::to_string(options.iterations));
    // The selection is read anew on each step: the children of a selected face are selected.
    const Region region = options.selection_only ? subdivision::selected_region(*current) : Region();
    Mesh next;
    if (options.scheme == SubdivisionScheme::sqrt3) {
      next = sqrt3_step(*current, it % 2 == 1, crease, region, options.threads, progress, from, to);
    } else {
      next = split_step(*current, options.scheme, crease, region, options.threads, progress, from, to);
      weld_split_edge_points(*current, next);
      if (!crease.empty()) crease = split_creases(crease, next.edges_size());
    }
    if (!region.all()) drop_unlinked(next, Index(current->vertices_size()), crease);
    result = std::move(next);
    current = &result;
  }
  mesh = std::move(result);
  refresh_normal_channels(mesh, true, true);
  normalize_corner_normals(mesh);

  SubdivideReport report;
  report.faces_before = faces_before;
  report.vertices = mesh.n_vertices();
  report.edges = mesh.n_edges();
  report.faces = mesh.n_faces();
  report.iterations = options.iterations;
  report.crease_edges = crease_edges;
  return report;
}

Operation subdivide_operation() {
  const char* help =
      "Refines the surface: every step replaces each face by smaller ones and moves the vertices toward a smooth "
      "limit surface. Schemes: loop (Loop 1987; triangles 1 to 4, smooth, for triangle meshes), catmull_clark "
      "(Catmull & Clark 1978; every n-gon becomes n quads, for any polygon mesh), sqrt3 (Kobbelt 2000; a vertex "
      "per triangle and the old edges flipped, the face count triples per step, for triangle meshes), midpoint "
      "(no smoothing: triangles 1 to 4 at the edge midpoints, other polygons into quads around their centroid). "
      "loop and sqrt3 refuse meshes with polygons: run Triangulate first. Boundaries: loop and catmull_clark "
      "refine boundary curves with the cubic B-spline rule; sqrt3 follows Kobbelt's rule, cutting boundary edges "
      "in three on every second iteration of a run (use an even number of iterations on open meshes). "
      "Creases: with a crease angle below 180, edges where the surface bends more sharply stay sharp under loop "
      "and catmull_clark (Hoppe et al. 1994; DeRose et al. 1998): they are refined as curves and the corners "
      "where three or more meet stay put; sqrt3 keeps them like boundaries (never flipped, cut in three on every "
      "second iteration); midpoint has no smoothing to undo. "
      "Attributes: vertex attributes are blended with the scheme's own weights, corner attributes (UVs) linearly "
      "inside each old face so seams stay seams, face attributes (materials) are copied to the child faces; normals "
      "are recomputed for the new shape. "
      "Results above 200 million faces are refused before starting.";
  using O = SubdivideOptions;
  using R = SubdivideReport;
  return Binding<O, R>("subdivide", "Subdivide", Category::remeshing, help, subdivide)
      .choice(&O::scheme, "scheme", "Scheme",
              {SubdivisionScheme::loop, SubdivisionScheme::catmull_clark, SubdivisionScheme::sqrt3,
               SubdivisionScheme::midpoint},
              subdivision_scheme_name,
              "loop and sqrt3 for triangle meshes, catmull_clark for any polygons (makes quads), "
              "midpoint to refine without smoothing")
      .option(&O::iterations, "iterations", "Iterations", between(1, 6),
              "refinement steps; each multiplies the face count by 4 (sqrt3: 3)")
      .option(&O::crease_angle, "crease_angle", "Crease angle", between(0, 180),
              "degrees: edges where the two faces' normals differ by more than this stay sharp (creases "
              "and corners, e.g. a cube's edges at 60); 180 smooths everything")
      .selection(&O::selection_only,
                 "Only the selected faces are refined; the faces outside the selection stay as they are, and so does "
                 "the border between the two: its edges are not split and its vertices do not move, and the selected "
                 "faces along it are closed without cracks.")
      .result(
          "scheme",
          [](const O& o, const R&) -> std::optional<Value> { return std::string(subdivision_scheme_name(o.scheme)); })
      .result(&R::iterations, "iterations")
      .result("crease_edges",
              [](const O& o, const R& r) -> std::optional<Value> {
                if (o.crease_angle >= 180) return std::nullopt;
                return field_value(r.crease_edges);
              })
      .result(&R::faces_before, "faces_before")
      .result(&R::vertices, "vertices")
      .result(&R::edges, "edges")
      .result(&R::faces, "faces");
}

}  // namespace hedge
