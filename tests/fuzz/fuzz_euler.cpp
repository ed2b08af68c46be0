// libFuzzer target: a small mesh (fixed shapes or a few fuzz-chosen faces), then a
// fuzz-driven sequence of Euler operations, each guarded by its is_*_ok test, and catalogue
// operations with in-range parameters; validate() after every step.
#include <fuzzer/FuzzedDataProvider.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "fuzz_common.h"
#include "hedge/catalogue.h"
#include "hedge/mesh.h"
#include "hedge/report.h"

namespace {

using hedge::Edge;
using hedge::Face;
using hedge::Halfedge;
using hedge::Mesh;
using hedge::Vertex;

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
  float v[12][3] = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0}, {0, -1, t}, {0, 1, t},
                    {0, -1, -t}, {0, 1, -t}, {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
  for (auto& p : v) s.positions.push_back({p[0], p[1], p[2]});
  std::uint32_t f[20][3] = {{0, 11, 5}, {0, 5, 1}, {0, 1, 7}, {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                            {11, 10, 2}, {10, 7, 6}, {7, 1, 8}, {3, 9, 4}, {3, 4, 2}, {3, 2, 6}, {3, 6, 8},
                            {3, 8, 9}, {4, 9, 5}, {2, 4, 11}, {6, 2, 10}, {8, 6, 7}, {9, 8, 1}};
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

void check(const Mesh& mesh, const char* after) {
  hedge::Validation v = hedge::validate(mesh);
  if (!v) hedge_fuzz::fail(std::string("validate after ") + after + ": " + v.message);
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
    if (mesh.is_boundary(v) && !mesh.is_boundary(Mesh::opposite(h)) &&
        !mesh.is_boundary(Mesh::opposite(mesh.next(h))))
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
      case hedge::ParamType::boolean: given[p.id] = in.ConsumeBool(); break;
      case hedge::ParamType::choice:
        given[p.id] = p.choices[in.ConsumeIntegralInRange<std::size_t>(0, p.choices.size() - 1)];
        break;
      case hedge::ParamType::integer: {
        // Small values only: iteration counts and sizes multiply the work.
        auto lo = static_cast<std::int64_t>(p.min);
        auto hi = std::min<std::int64_t>(static_cast<std::int64_t>(p.max), lo + (p.id == "iterations" ? 1 : 64));
        given[p.id] = in.ConsumeIntegralInRange<std::int64_t>(lo, hi);
        break;
      }
      case hedge::ParamType::real: {
        double hi = p.max > 1e3 ? 4.0 : p.max;  // lengths and distances: the meshes are a few units wide
        double lo = p.max > 1e3 ? std::max(p.min, 0.25) : p.min;
        if (p.max > 1e3 && in.ConsumeBool()) lo = p.min, hi = p.min;  // 0 = automatic
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

void run_catalogue(FuzzedDataProvider& in, Mesh& mesh) {
  const auto& ops = hedge::catalogue();
  const hedge::Operation& op = ops[in.ConsumeIntegralInRange<std::size_t>(0, ops.size() - 1)];
  hedge::ParamValues params = draw_params(in, op);
  if (op.id == "subdivide" && mesh.n_faces() * 16 > 4 * max_faces) return;
  // Remeshing makes as many triangles as the target asks for, whatever the input's size: an
  // adaptive remesh of a spiky 20-triangle mesh made 64,000 (3 s, 50 s under ASan).
  if (op.id == "remesh" && remesh_forecast(mesh, params) > 40.0 * max_faces) return;
  mesh.garbage_collect();
  Mesh before = mesh;
  try {
    op.run(mesh, params, hedge::Progress::none());
  } catch (const hedge::Error&) {
    mesh = before;  // operations may throw on meshes they do not take; their input is copied
    return;
  }
  check(mesh, op.id.c_str());
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  FuzzedDataProvider in(data, size);
  hedge::Soup soup;
  switch (in.ConsumeIntegralInRange<int>(0, 4)) {
    case 0: soup = grid(3, true); break;
    case 1: soup = grid(3, false); break;
    case 2: soup = icosahedron(); break;
    case 3: soup = cube(); break;
    default: soup = random_faces(in); break;
  }
  Mesh mesh;
  try {
    mesh = std::move(hedge::build(soup).mesh);
  } catch (const hedge::Error&) {
    return 0;
  }
  check(mesh, "build");

  for (int step = 0; step < 24 && in.remaining_bytes() > 0; ++step) {
    bool small = mesh.n_faces() < max_faces;
    Edge e;
    Face f;
    Vertex v;
    switch (in.ConsumeIntegralInRange<int>(0, 13)) {
      case 0:
        if (pick(in, mesh, mesh.edges_size(), e) && mesh.is_flip_ok(e)) mesh.flip(e), check(mesh, "flip");
        break;
      case 1:
        if (small && pick(in, mesh, mesh.edges_size(), e)) {
          mesh.split_edge(e, mesh.add_vertex(midpoint(mesh, e)));
          check(mesh, "split_edge");
        }
        break;
      case 2:
        if (small && pick(in, mesh, mesh.edges_size(), e)) {
          Vertex nv = mesh.add_vertex(midpoint(mesh, e));
          try {
            mesh.split_edge_triangles(e, nv);
          } catch (const hedge::Error&) {
            check(mesh, "refused split_edge_triangles");
            mesh.remove_isolated_vertex(nv);
          }
          check(mesh, "split_edge_triangles");
        }
        break;
      case 3:
        if (small && pick(in, mesh, mesh.faces_size(), f)) {
          mesh.split_face(f, mesh.add_vertex(centroid(mesh, f)));
          check(mesh, "split_face");
        }
        break;
      case 4: {
        Halfedge h0, h1;
        if (pick(in, mesh, mesh.halfedges_size(), h0) && pick(in, mesh, mesh.halfedges_size(), h1) &&
            mesh.is_insert_ok(h0, h1)) {
          mesh.insert_edge(h0, h1);
          check(mesh, "insert_edge");
        }
        break;
      }
      case 5:
        if (pick(in, mesh, mesh.edges_size(), e) && mesh.is_removal_ok(e)) mesh.remove_edge(e), check(mesh, "remove_edge");
        break;
      case 6: {
        Halfedge h;
        if (pick(in, mesh, mesh.halfedges_size(), h) && mesh.is_collapse_ok(h)) mesh.collapse(h), check(mesh, "collapse");
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
          check(mesh, "fill_hole");
        }
        break;
      }
      case 8:
        if (pick(in, mesh, mesh.faces_size(), f) && is_delete_face_ok(mesh, f)) {
          mesh.delete_face(f);
          check(mesh, "delete_face");
        }
        break;
      case 9:
        if (pick(in, mesh, mesh.faces_size(), f)) {
          try {
            mesh.triangulate(f);
          } catch (const hedge::Error&) {
          }
          check(mesh, "triangulate(face)");
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
        check(mesh, "add_face");
        break;
      }
      case 11:
        if (pick(in, mesh, mesh.vertices_size(), v) && mesh.is_isolated(v)) {
          mesh.remove_isolated_vertex(v);
          check(mesh, "remove_isolated_vertex");
        }
        break;
      case 12:
        mesh.garbage_collect();
        check(mesh, "garbage_collect");
        break;
      default:
        if (mesh.n_faces() <= max_faces) run_catalogue(in, mesh);
        break;
    }
  }
  // Whatever the sequence made must extract and build again.
  mesh.garbage_collect();
  hedge::Soup out = hedge::extract(mesh);
  hedge_fuzz::check_build_round_trip(out);
  return 0;
}
