// libFuzzer target: a small mesh (fixed shapes or a few fuzz-chosen faces, with faces glued
// on to make non-manifold edges and vertices and duplicate faces), then a fuzz-driven
// sequence of Euler operations, each guarded by its is_*_ok test, and catalogue operations
// with in-range parameters. After every step: validate(), and extract() given the soup the
// mesh was built from must keep the rule "no mesh comes back worse" (DefectRule).
#include <fuzzer/FuzzedDataProvider.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "fuzz_common.h"
#include "hedge/build.h"
#include "hedge/catalogue.h"
#include "hedge/mesh.h"
#include "hedge/provenance.h"
#include "hedge/report.h"

namespace {

using hedge::Edge;
using hedge::Face;
using hedge::Halfedge;
using hedge::Mesh;
using hedge::Vertex;
using hedge::test::DefectCounts;

constexpr std::size_t max_faces = 160;  // keeps every run well under a millisecond or two

hedge::Soup grid(int n, bool triangles) {
  hedge::Soup s;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) s.positions.push_back({float(i), float(j), float((i * 7 + j * 3) % 5) * 0.1f});
  auto id = [n](int i, int j) { return std::uint32_t(j * (n + 1) + i); };
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      if (triangles) {
        s.add_face({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
        s.add_face({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
      } else {
        s.add_face({id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)});
      }
    }
  return s;
}

hedge::Soup icosahedron() {
  hedge::Soup s;
  const float t = 1.618034f;
  float v[12][3] = {{-1, t, 0},  {1, t, 0},  {-1, -t, 0}, {1, -t, 0}, {0, -1, t},  {0, 1, t},
                    {0, -1, -t}, {0, 1, -t}, {t, 0, -1},  {t, 0, 1},  {-t, 0, -1}, {-t, 0, 1}};
  for (auto& p : v) s.positions.push_back({p[0], p[1], p[2]});
  std::uint32_t f[20][3] = {{0, 11, 5},  {0, 5, 1},  {0, 1, 7},  {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                            {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
                            {3, 8, 9},   {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
  for (auto& t3 : f) s.add_face({t3[0], t3[1], t3[2]});
  return s;
}

hedge::Soup cube() {
  hedge::Soup s;
  for (int i = 0; i < 8; ++i) s.positions.push_back({float(i & 1), float((i >> 1) & 1), float((i >> 2) & 1)});
  s.add_face({0, 2, 3, 1});
  s.add_face({4, 5, 7, 6});
  s.add_face({0, 1, 5, 4});
  s.add_face({2, 6, 7, 3});
  s.add_face({0, 4, 6, 2});
  s.add_face({1, 3, 7, 5});
  return s;
}

hedge::Soup random_faces(FuzzedDataProvider& in) {
  hedge::Soup s;
  int nv = in.ConsumeIntegralInRange<int>(3, 10);
  for (int i = 0; i < nv; ++i)
    s.positions.push_back({float(in.ConsumeIntegralInRange<int>(-3, 3)), float(in.ConsumeIntegralInRange<int>(-3, 3)),
                           float(in.ConsumeIntegralInRange<int>(-3, 3))});
  int nf = in.ConsumeIntegralInRange<int>(1, 12);
  for (int f = 0; f < nf; ++f) {
    std::vector<std::uint32_t> face(in.ConsumeIntegralInRange<int>(3, 5));
    for (auto& c : face) c = in.ConsumeIntegralInRange<std::uint32_t>(0, nv - 1);
    s.add_face(face);
  }
  return s;
}

//! Glues `n` faces onto the soup where they make defects, so that build() makes copies for
//! extract() to weld back: a fin on a face's side (a third face on an edge), a triangle at a
//! corner on new vertices (a bow-tie vertex), a face listed again (reversed or turned), a
//! triangle over a side and another vertex of the soup.
void add_defects(FuzzedDataProvider& in, hedge::Soup& s, int n) {
  for (int k = 0; k < n && s.n_faces() > 0; ++k) {
    const std::vector<std::size_t> offsets = s.face_offsets();
    const std::size_t f = in.ConsumeIntegralInRange<std::size_t>(0, s.n_faces() - 1);
    std::vector<std::uint32_t> face(s.corners.begin() + offsets[f], s.corners.begin() + offsets[f + 1]);
    const std::size_t i = in.ConsumeIntegralInRange<std::size_t>(0, face.size() - 1);
    const std::uint32_t u = face[i], v = face[(i + 1) % face.size()];
    auto new_vertex = [&](std::uint32_t near) {
      const hedge::Point p = s.positions[near];
      s.positions.push_back({p[0] + 0.5f * float(in.ConsumeIntegralInRange<int>(-2, 2)),
                             p[1] + 0.5f * float(in.ConsumeIntegralInRange<int>(-2, 2)), p[2] + 0.5f});
      return std::uint32_t(s.positions.size() - 1);
    };
    switch (in.ConsumeIntegralInRange<int>(0, 3)) {
      case 0: {  // fin
        const std::uint32_t p = new_vertex(u);
        if (in.ConsumeBool())
          s.add_face({u, v, p});
        else
          s.add_face({v, u, p});
        break;
      }
      case 1: {  // bow-tie
        const std::uint32_t p = new_vertex(u), q = new_vertex(u);
        s.add_face({u, p, q});
        break;
      }
      case 2: {  // duplicate
        if (in.ConsumeBool()) std::reverse(face.begin(), face.end());
        std::rotate(face.begin(), face.begin() + std::ptrdiff_t(i), face.end());
        s.add_face(face);
        break;
      }
      default: {  // bridge to any vertex
        const auto w = in.ConsumeIntegralInRange<std::uint32_t>(0, std::uint32_t(s.positions.size() - 1));
        s.add_face({v, u, w});
        break;
      }
    }
  }
}

void validated(const Mesh& mesh, const std::string& after) {
  hedge::Validation v = hedge::validate(mesh);
  if (!v) hedge_fuzz::fail("validate after " + after + ": " + v.message);
}

//! "No mesh comes back worse" (docs/architecture.md), held after every catalogue operation
//! and every run of Euler operations (before the next catalogue operation, and at the end;
//! the states between are the end states of shorter inputs): extract() given the soup the
//! mesh was built from has no more of each defect (defect_counts.h) than is allowed, which
//! starts as the first soup's own counts. A catalogue operation runs as a host runs it
//! (run_operation()): on a mesh built afresh from the soup the host holds by then, which
//! becomes the soup to compare with; subdivision may multiply the counts by its own rule,
//! step by step. Euler operations are edits, not operations: the faces they make over the
//! vertex set of another once copies are welded (no weld avoids those duplicates; in the mesh
//! itself, such as a hole of three edges filled next to a triangle, or across copies, such as
//! a flip whose triangle covers a quad visiting one vertex twice), counted per welded vertex
//! set and per set of the mesh's own vertices within it, are allowed on top, and so are the defects
//! of every face over two copies of one host vertex, whether an edit spanned it or the input
//! held it (an edit that splits one changes how the weld resolves it): welded back, it would
//! visit that vertex twice, so extract() keeps copies apart, and whichever it keeps, the face shares its
//! edges with the copies' own faces (a repeated vertex, or non-manifold edges and vertices around
//! it; at most one repeated face, one duplicate and one non-manifold edge and vertex per
//! corner). HEDGE_FUZZ_RULE=every
//! checks after every Euler operation too (slower), =0 not at all; HEDGE_FUZZ_TRACE=1 checks
//! after every step and prints the counts.
class DefectRule {
 public:
  explicit DefectRule(hedge::Soup soup)
      : soup_(std::move(soup)),
        input_(hedge::test::count_defects(soup_)),
        trace_(std::getenv("HEDGE_FUZZ_TRACE") != nullptr),
        off_(setting() == "0"),
        every_(trace_ || setting() == "every") {
    for (int k = 0; k < 4; ++k) allowed_[k] = input_.at(k);
    if (trace_) std::fprintf(stderr, "[rule] input: %s\n", hedge_fuzz::describe(input_).c_str());
  }
  void built(Mesh& mesh) {
    if (!off_) since_ = EditMade::mark(mesh);
  }

  void euler(const Mesh& mesh, const std::string& what) {
    host_fresh_ = false;
    if (off_) return;
    edits_ += (edits_.empty() ? "" : ", ") + what;
    if (every_) check(mesh, what);
  }
  //! At the end of the input: the last run of Euler operations.
  void finish(const Mesh& mesh) {
    if (!off_ && !edits_.empty()) check(mesh, edits_);
  }

  //! Before a catalogue operation: what the Euler edits since the last one made is allowed
  //! from now on, and the mesh is built again from the soup a host would hold.
  void before_catalogue(Mesh& mesh) {
    if (!off_) {
      if (!edits_.empty() && !every_) check(mesh, edits_);
      edits_.clear();
      const EditMade::Gained made = EditMade::of(mesh).minus(since_);
      for (int k = 0; k < 4; ++k) allowed_[k] += made.allows(k);
    }
    if (!host_fresh_) {
      hedge::ExtractOptions options;
      options.input = &soup_;
      host_ = hedge::extract(mesh, options);
    }
    soup_ = std::move(host_);
    host_fresh_ = false;
    try {
      mesh = std::move(hedge::build(soup_).mesh);
    } catch (const hedge::Error& e) {
      hedge_fuzz::fail(std::string("extract()'s soup does not build again: ") + e.what());
    }
    validated(mesh, "build of the host's soup");
    if (!off_) since_ = EditMade::mark(mesh);
  }

  void catalogue(Mesh& mesh, const hedge::Operation& op, const hedge::ParamValues& params) {
    if (off_) return;
    if (op.id == "subdivide")
      for (std::int64_t i = 0; i < params.get_int("iterations"); ++i, ++subdivisions_) {
        allowed_[0] = 2 * allowed_[0] + 3 * allowed_[2];
        allowed_[2] *= 4;
      }
    since_ = EditMade::mark(mesh);
    std::string what = op.id + "(";
    for (const auto& [id, value] : params.all())
      what += (what.back() == '(' ? "" : ", ") + id + " = " + hedge::value_text(value);
    check(mesh, what + ")");
  }

 private:
  static std::string setting() {
    const char* value = std::getenv("HEDGE_FUZZ_RULE");
    return value ? value : "";
  }
  //! What Euler edits make in the mesh itself that extract() cannot weld without a defect:
  //! faces over the vertex set of another once copies are welded (no weld avoids the
  //! duplicate), and faces over two copies of one host vertex, with their corners.
  struct EditMade {
    //! A vertex as the weld sees it: its host vertex; else, for a vertex the mesh held when
    //! last marked, its mark (which garbage collection carries, unlike its index; its place
    //! would not do, as two vertices may share one); else, for one an edit made, its index.
    using Key = std::array<std::uint32_t, 2>;
    static constexpr char kMark[] = "hedge:fuzz_mark";  // internal: extract() leaves it out

    //! Marks every vertex with its index, then counts.
    static EditMade mark(Mesh& mesh) {
      auto marks = mesh.vertex_property<std::uint32_t>(kMark, hedge::kInvalidIndex);
      for (std::size_t i = 0; i < marks.vector().size(); ++i) marks.vector()[i] = std::uint32_t(i);
      return of(mesh);
    }
    //! Per welded vertex set: how many faces share it, and how many of those repeat the mesh
    //! vertices of another (duplicates in the mesh itself, which no weld avoids).
    struct SetCount {
      std::size_t faces = 0, same_vertices = 0;
    };
    std::map<std::vector<Key>, SetCount> sets;
    std::size_t self_welding = 0, self_welding_corners = 0;

    static EditMade of(const Mesh& mesh) {
      const auto* source = mesh.vertex_properties().get<std::uint32_t>(hedge::provenance::kVertexSource);
      const auto* marks = mesh.vertex_properties().get<std::uint32_t>(kMark);
      EditMade made;
      std::vector<Key> set, own;
      std::set<std::vector<Key>> seen;  // the faces' own vertex sets
      for (Face f : mesh.faces()) {
        set.clear();
        own.clear();
        for (Vertex v : mesh.vertices(f)) {
          const std::uint32_t s = source ? source->vector()[v.idx()] : hedge::kInvalidIndex;
          const std::uint32_t m = marks ? marks->vector()[v.idx()] : hedge::kInvalidIndex;
          const Key itself = m != hedge::kInvalidIndex ? Key{1, m} : Key{2, v.idx()};
          set.push_back(s != hedge::kInvalidIndex ? Key{0, s} : itself);
          own.push_back(itself);
        }
        std::sort(set.begin(), set.end());
        std::sort(own.begin(), own.end());
        const std::size_t corners = set.size();
        const auto copies = [](const Key& a, const Key& b) { return a[0] == 0 && a == b; };
        if (std::adjacent_find(set.begin(), set.end(), copies) != set.end()) {
          ++made.self_welding;  // two corners on copies of one host vertex
          made.self_welding_corners += corners;
        }
        set.erase(std::unique(set.begin(), set.end()), set.end());
        SetCount& count = made.sets[set];
        ++count.faces;
        if (!seen.insert(own).second) ++count.same_vertices;
      }
      return made;
    }
    //! What was made since `before`: per welded vertex set, the duplicates it gained (an edit
    //! may remove one duplicate and make another; counts alone would miss that), and every
    //! face over copies the mesh holds now, not only new ones: an edit that splits one (such
    //! as a triangulated quad visiting a host vertex twice) changes how the weld resolves it,
    //! trading the input's repeated vertex for non-manifold edges.
    struct Gained {
      std::size_t duplicates = 0, self_welding = 0, self_welding_corners = 0;
      //! How many more of defect k (DefectCounts order) the weld of what was made may cost.
      std::size_t allows(int k) const {
        return k == 2 ? duplicates + self_welding : k == 3 ? self_welding : self_welding_corners;
      }
    };
    Gained minus(const EditMade& before) const {
      auto gained = [](std::size_t now, std::size_t then) { return now > then ? now - then : 0; };
      Gained g{0, self_welding, self_welding_corners};
      // Either way: more faces on a welded set, or as many, but more of them on one and the
      // same vertices (an edit deleted a face over copies and filled a hole over the other's).
      for (const auto& [set, count] : sets) {
        const auto then = before.sets.find(set);
        const SetCount was = then == before.sets.end() ? SetCount{} : then->second;
        g.duplicates += std::max(gained(count.faces, std::max<std::size_t>(was.faces, 1)),
                                 gained(count.same_vertices, was.same_vertices));
      }
      return g;
    }
  };

  void check(const Mesh& mesh, const std::string& what) {
    hedge::ExtractOptions options;
    options.input = &soup_;
    hedge::ExtractReport report;
    host_ = hedge::extract(mesh, options, &report);
    host_fresh_ = true;
    const hedge::Soup& welded = host_;
    const DefectCounts out = hedge::test::count_defects(welded);
    if (trace_)
      std::fprintf(stderr, "[rule] %s: %s (allowed %zu/%zu/%zu/%zu, %zu copies kept apart)\n", what.c_str(),
                   hedge_fuzz::describe(out).c_str(), allowed_[0], allowed_[1], allowed_[2], allowed_[3],
                   report.copies_kept_apart);
    std::optional<EditMade::Gained> made;
    for (int k = 0; k < 4; ++k) {
      if (out.at(k) <= allowed_[k]) continue;
      // Only then: what the edits made in the mesh itself (counting it costs as much again).
      if (!made) made = EditMade::of(mesh).minus(since_);
      const std::size_t edits = made->allows(k);
      if (out.at(k) <= allowed_[k] + edits) continue;
      if (trace_) {
        hedge::ExtractOptions own;
        own.restore_source = false;
        std::fprintf(stderr, "[rule] soup faces:%s\n[rule] output faces:%s\n[rule] unwelded faces:%s\n",
                     faces(soup_).c_str(), faces(welded).c_str(), faces(hedge::extract(mesh, own)).c_str());
      }
      hedge_fuzz::fail("extract(mesh, input = soup) after " + what + " has " + std::to_string(out.at(k)) + " " +
                       DefectCounts::kNames[k] + ", more than the " + std::to_string(allowed_[k] + edits) +
                       " allowed; input: " + hedge_fuzz::describe(input_) + "; output: " + hedge_fuzz::describe(out) +
                       "; " + std::to_string(subdivisions_) + " subdivision steps, " + std::to_string(edits) +
                       " more allowed for what Euler edits made in the mesh itself, " +
                       std::to_string(report.copies_kept_apart) + " copies kept apart");
    }
  }

  static std::string faces(const hedge::Soup& s) {
    std::string text;
    const std::vector<std::size_t> offsets = s.face_offsets();
    for (std::size_t f = 0; f < s.n_faces(); ++f) {
      text += " {";
      for (std::size_t c = offsets[f]; c < offsets[f + 1]; ++c)
        text += (c > offsets[f] ? " " : "") + std::to_string(s.corners[c]);
      text += "}";
    }
    return text;
  }

  hedge::Soup soup_;  //!< what the mesh was built from: the input, then the host's soup
  hedge::Soup host_;  //!< the last extract(mesh, input = soup_), while `host_fresh_`
  bool host_fresh_ = false;
  const DefectCounts input_;
  const bool trace_, off_, every_;
  std::string edits_;  //!< the Euler operations since the last catalogue operation
  std::size_t allowed_[4] = {};
  EditMade since_;  //!< what the mesh itself held after the last catalogue operation
  std::size_t subdivisions_ = 0;
};

// Same arrays: sizes, connectivity and positions.
bool same_elements(const Mesh& a, const Mesh& b) {
  if (a.vertices_size() != b.vertices_size() || a.edges_size() != b.edges_size() || a.faces_size() != b.faces_size())
    return false;
  for (hedge::Vertex v : a.vertices())
    if (a.halfedge(v) != b.halfedge(v) || a.position(v) != b.position(v)) return false;
  for (hedge::Face f : a.faces())
    if (a.halfedge(f) != b.halfedge(f)) return false;
  for (hedge::Halfedge h : a.halfedges())
    if (a.to_vertex(h) != b.to_vertex(h) || a.face(h) != b.face(h) || a.next(h) != b.next(h) || a.prev(h) != b.prev(h))
      return false;
  return true;
}

void check(DefectRule& rule, const Mesh& mesh, const char* after) {
  validated(mesh, after);
  rule.euler(mesh, after);
}

template <class H>
bool pick(FuzzedDataProvider& in, const Mesh& mesh, std::size_t size, H& out) {
  if (size == 0) return false;
  out = H(static_cast<std::uint32_t>(in.ConsumeIntegralInRange<std::size_t>(0, size - 1)));
  return !mesh.is_deleted(out);
}

hedge::Point midpoint(const Mesh& mesh, Edge e) {
  hedge::Point a = mesh.position(mesh.vertex(e, 0)), b = mesh.position(mesh.vertex(e, 1));
  return {(a[0] + b[0]) * 0.5f, (a[1] + b[1]) * 0.5f, (a[2] + b[2]) * 0.5f};
}

hedge::Point centroid(const Mesh& mesh, Face f) {
  double x = 0, y = 0, z = 0;
  std::size_t n = 0;
  for (Vertex v : mesh.vertices(f)) {
    auto p = mesh.position(v);
    x += p[0], y += p[1], z += p[2], ++n;
  }
  return {float(x / n), float(y / n), float(z / n)};
}

//! delete_face keeps vertices manifold unless a corner is a boundary vertex whose gap is
//! not next to f (mesh.h: two gaps in one fan are the caller's problem).
bool is_delete_face_ok(const Mesh& mesh, Face f) {
  Halfedge h0 = mesh.halfedge(f), h = h0;
  do {
    Vertex v = mesh.to_vertex(h);
    if (mesh.is_boundary(v) && !mesh.is_boundary(Mesh::opposite(h)) && !mesh.is_boundary(Mesh::opposite(mesh.next(h))))
      return false;
    h = mesh.next(h);
  } while (h != h0);
  return true;
}

hedge::ParamValues draw_params(FuzzedDataProvider& in, const hedge::Operation& op) {
  std::map<std::string, hedge::Value> given;
  for (const auto& p : op.params) {
    if (in.ConsumeBool()) continue;  // default
    switch (p.type) {
      case hedge::ParamType::boolean:
        given[p.id] = in.ConsumeBool();
        break;
      case hedge::ParamType::choice:
        given[p.id] = p.choices[in.ConsumeIntegralInRange<std::size_t>(0, p.choices.size() - 1)];
        break;
      case hedge::ParamType::vertex_channel:
        // The fuzzed meshes carry no attributes: a name exercises the refusal.
        given[p.id] = std::string(in.ConsumeBool() ? "" : "no_such_attribute");
        break;
      case hedge::ParamType::integer: {
        // Small values only: iteration counts and sizes multiply the work.
        auto lo = static_cast<std::int64_t>(p.range.min);
        auto hi = lo + (p.id == "iterations" ? 1 : 64);
        if (p.range.max) hi = std::min<std::int64_t>(static_cast<std::int64_t>(*p.range.max), hi);
        given[p.id] = in.ConsumeIntegralInRange<std::int64_t>(lo, hi);
        break;
      }
      case hedge::ParamType::real: {
        // Unbounded ones are lengths and distances: the meshes are a few units wide.
        const bool unbounded = !p.range.max;
        double hi = unbounded ? 4.0 : *p.range.max;
        double lo = unbounded ? std::max(p.range.min, 0.25) : p.range.min;
        if (unbounded && in.ConsumeBool()) lo = p.range.min, hi = p.range.min;  // 0 = automatic
        given[p.id] = lo + (hi - lo) * in.ConsumeProbability<double>();
        break;
      }
    }
  }
  return hedge::resolve_params(op, given);
}

//! Triangles remesh would aim at: the area over equilateral triangles of the finest edge it
//! may ask for (adaptive sizing goes down to a quarter of the target), as remesh forecasts.
double remesh_forecast(const Mesh& mesh, const hedge::ParamValues& params) {
  const hedge::MeshStatistics stats = hedge::mesh_statistics(mesh);
  double length = params.get_real("target_edge_length");
  if (length == 0) length = stats.edge_length_mean;
  if (params.get_bool("adaptive")) length *= 0.25;
  return length > 0 ? stats.area / (std::sqrt(3.0) / 4 * length * length) : 0;
}

void run_catalogue(FuzzedDataProvider& in, Mesh& mesh, DefectRule& rule) {
  const auto& ops = hedge::catalogue();
  const hedge::Operation& op = ops[in.ConsumeIntegralInRange<std::size_t>(0, ops.size() - 1)];
  hedge::ParamValues params = draw_params(in, op);
  rule.before_catalogue(mesh);
  if (op.id == "subdivide" && mesh.n_faces() * 16 > 4 * max_faces) return;
  // Remeshing makes as many triangles as the target asks for, whatever the input's size: an
  // adaptive remesh of a spiky 20-triangle mesh made 64,000 (3 s, 50 s under ASan).
  if (op.id == "remesh" && remesh_forecast(mesh, params) > 40.0 * max_faces) return;
  Mesh before = mesh;
  try {
    op.run(mesh, params, hedge::Progress::none());
  } catch (const hedge::Error&) {
    mesh = before;  // operations may throw on meshes they do not take; their input is copied
    return;
  }
  validated(mesh, op.id);
  rule.catalogue(mesh, op, params);
  // Subdivision's own welds (split-edge points) follow its rule and are exempt from the
  // guard; a host holds the welded soup after it, never those welds, so edit what it holds.
  if (op.id == "subdivide") rule.before_catalogue(mesh);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  FuzzedDataProvider in(data, size);
  hedge::Soup soup;
  // The second byte from the end: how many faces to glue on. (Inputs made before it existed
  // replay as they did with a zero byte inserted before their last.)
  const int shape = in.ConsumeIntegralInRange<int>(0, 4), glue = in.ConsumeIntegralInRange<int>(0, 7);
  switch (shape) {
    case 0:
      soup = grid(3, true);
      break;
    case 1:
      soup = grid(3, false);
      break;
    case 2:
      soup = icosahedron();
      break;
    case 3:
      soup = cube();
      break;
    default:
      soup = random_faces(in);
      break;
  }
  add_defects(in, soup, glue);
  hedge::BuildResult built;
  try {
    built = hedge::build(soup);
  } catch (const hedge::Error&) {
    return 0;
  }
  validated(built.mesh, "build");
  hedge_fuzz::check_extract_with_input(built, soup, hedge_fuzz::expected_round_trip(soup, built.maps.skipped_faces));
  Mesh mesh = std::move(built.mesh);
  DefectRule rule(std::move(soup));
  rule.built(mesh);

  for (int step = 0; step < 24 && in.remaining_bytes() > 0; ++step) {
    bool small = mesh.n_faces() < max_faces;
    Edge e;
    Face f;
    Vertex v;
    switch (in.ConsumeIntegralInRange<int>(0, 13)) {
      case 0:
        if (pick(in, mesh, mesh.edges_size(), e) && mesh.is_flip_ok(e)) mesh.flip(e), check(rule, mesh, "flip");
        break;
      case 1:
        if (small && pick(in, mesh, mesh.edges_size(), e)) {
          mesh.split_edge(e, mesh.add_vertex(midpoint(mesh, e)));
          check(rule, mesh, "split_edge");
        }
        break;
      case 2:
        if (small && pick(in, mesh, mesh.edges_size(), e)) {
          Vertex nv = mesh.add_vertex(midpoint(mesh, e));
          try {
            mesh.split_edge_triangles(e, nv);
          } catch (const hedge::Error&) {
            check(rule, mesh, "refused split_edge_triangles");
            mesh.remove_isolated_vertex(nv);
          }
          check(rule, mesh, "split_edge_triangles");
        }
        break;
      case 3:
        if (small && pick(in, mesh, mesh.faces_size(), f)) {
          mesh.split_face(f, mesh.add_vertex(centroid(mesh, f)));
          check(rule, mesh, "split_face");
        }
        break;
      case 4: {
        Halfedge h0, h1;
        if (pick(in, mesh, mesh.halfedges_size(), h0) && pick(in, mesh, mesh.halfedges_size(), h1) &&
            mesh.is_insert_ok(h0, h1)) {
          mesh.insert_edge(h0, h1);
          check(rule, mesh, "insert_edge");
        }
        break;
      }
      case 5:
        if (pick(in, mesh, mesh.edges_size(), e) && mesh.is_removal_ok(e))
          mesh.remove_edge(e), check(rule, mesh, "remove_edge");
        break;
      case 6: {
        Halfedge h;
        if (pick(in, mesh, mesh.halfedges_size(), h) && mesh.is_collapse_ok(h))
          mesh.collapse(h), check(rule, mesh, "collapse");
        break;
      }
      case 7: {
        Halfedge h;
        if (pick(in, mesh, mesh.halfedges_size(), h) && mesh.is_boundary(h)) {
          // A loop of two edges or through a vertex twice is refused with an Error that
          // changes nothing.
          std::size_t faces = mesh.n_faces();
          try {
            mesh.fill_hole(h);
          } catch (const hedge::Error&) {
            if (mesh.n_faces() != faces) hedge_fuzz::fail("refused fill_hole changed the face count");
          }
          check(rule, mesh, "fill_hole");
        }
        break;
      }
      case 8:
        if (pick(in, mesh, mesh.faces_size(), f) && is_delete_face_ok(mesh, f)) {
          mesh.delete_face(f);
          check(rule, mesh, "delete_face");
        }
        break;
      case 9:
        if (pick(in, mesh, mesh.faces_size(), f)) {
          try {
            mesh.triangulate(f);
          } catch (const hedge::Error&) {
          }
          check(rule, mesh, "triangulate(face)");
        }
        break;
      case 10: {
        // add_face over arbitrary vertices: either legal or an Error that changes nothing.
        std::vector<Vertex> vs(in.ConsumeIntegralInRange<int>(3, 5));
        bool ok = true;
        for (auto& x : vs) ok = ok && pick(in, mesh, mesh.vertices_size(), x);
        if (!ok) break;
        std::size_t faces = mesh.n_faces();
        try {
          mesh.add_face(vs);
        } catch (const hedge::Error&) {
          if (mesh.n_faces() != faces) hedge_fuzz::fail("refused add_face changed the face count");
        }
        check(rule, mesh, "add_face");
        break;
      }
      case 11:
        if (pick(in, mesh, mesh.vertices_size(), v) && mesh.is_isolated(v)) {
          mesh.remove_isolated_vertex(v);
          check(rule, mesh, "remove_isolated_vertex");
        }
        break;
      case 12: {
        // compact() must leave what garbage_collect() leaves.
        Mesh compacted = mesh;
        compacted.compact();
        mesh.garbage_collect();
        check(rule, mesh, "garbage_collect");
        if (!same_elements(mesh, compacted)) hedge_fuzz::fail("compact() and garbage_collect() disagree");
        break;
      }
      default:
        if (mesh.n_faces() <= max_faces) run_catalogue(in, mesh, rule);
        break;
    }
  }
  rule.finish(mesh);
  // Whatever the sequence made must extract and build again.
  mesh.garbage_collect();
  hedge::Soup out = hedge::extract(mesh);
  hedge_fuzz::check_build_round_trip(out, /*with_input=*/true);
  return 0;
}
