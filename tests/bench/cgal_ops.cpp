// CGAL's side of hedge_bench: Surface_mesh over Epick points (double precision, CGAL's
// usual kernel), filled with add_vertex + add_face, which refuses (returns null_face())
// faces that would make an edge or vertex non-manifold.
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/compute_normal.h>
#include <CGAL/Polygon_mesh_processing/remesh.h>
#include <CGAL/Subdivision_method_3/subdivision_methods_3.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/Surface_mesh_simplification/Policies/Edge_collapse/GarlandHeckbert_plane_policies.h>
#include <CGAL/Surface_mesh_simplification/edge_collapse.h>

#include <cmath>
#include <memory>
#include <vector>

#include "bench.h"

namespace bench {

namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using SMesh = CGAL::Surface_mesh<Kernel::Point_3>;
using VI = SMesh::Vertex_index;

std::unique_ptr<SMesh> build_mesh(bool reserve) {
  const hedge::Soup& soup = input().soup;
  auto mesh = std::make_unique<SMesh>();
  if (reserve)
    mesh->reserve(static_cast<SMesh::size_type>(soup.n_vertices()), static_cast<SMesh::size_type>(input().unique_edges),
                  static_cast<SMesh::size_type>(soup.n_faces()));
  for (const hedge::Point& p : soup.positions) mesh->add_vertex(Kernel::Point_3(p[0], p[1], p[2]));
  std::vector<VI> polygon;
  std::size_t offset = 0;
  const std::uint32_t* c = soup.corners.data();
  for (std::uint32_t n : soup.face_sizes) {
    if (repeats_vertex(c + offset, n)) {
      offset += n;
      continue;
    }
    if (n == 3) {
      mesh->add_face(VI(c[offset]), VI(c[offset + 1]), VI(c[offset + 2]));
    } else {
      polygon.clear();
      for (std::uint32_t i = 0; i < n; ++i) polygon.emplace_back(c[offset + i]);
      mesh->add_face(polygon);
    }
    offset += n;
  }
  return mesh;
}

std::unique_ptr<SMesh>& cache_slot() {
  static std::unique_ptr<SMesh> mesh;
  return mesh;
}

SMesh& cached() {
  std::unique_ptr<SMesh>& mesh = cache_slot();
  if (!mesh) {
    mesh = build_mesh(false);
    stats("CGAL").vertices = mesh->number_of_vertices();
    stats("CGAL").faces = mesh->number_of_faces();
  }
  return *mesh;
}

void build_with(benchmark::State& state, bool reserve) {
  for (auto _ : state) {
    auto mesh = build_mesh(reserve);
    benchmark::DoNotOptimize(mesh.get());
    state.PauseTiming();
    if (!reserve) {
      stats("CGAL").vertices = mesh->number_of_vertices();
      stats("CGAL").faces = mesh->number_of_faces();
    }
    mesh.reset();
    state.ResumeTiming();
  }
}
void build(benchmark::State& state) { build_with(state, false); }
void build_reserved(benchmark::State& state) { build_with(state, true); }

void circulate(benchmark::State& state) {
  const SMesh& mesh = cached();
  std::uint64_t sum = 0;
  for (auto _ : state) {
    sum = 0;
    for (VI v : mesh.vertices())
      for (VI w : CGAL::vertices_around_target(v, mesh)) sum += static_cast<std::uint32_t>(w.idx());
    benchmark::DoNotOptimize(sum);
  }
  stats("CGAL").circulation_sum = sum;
}

//! CGAL's API: per vertex, the "most visible" normal of the incident faces, falling back to
//! a weighted sum (see Polygon_mesh_processing/compute_normal.h).
void normals(benchmark::State& state) {
  SMesh& mesh = cached();
  auto vnormals = mesh.add_property_map<VI, Kernel::Vector_3>("v:bench_normal", CGAL::NULL_VECTOR).first;
  for (auto _ : state) {
    CGAL::Polygon_mesh_processing::compute_vertex_normals(mesh, vnormals);
    benchmark::DoNotOptimize(&vnormals[VI(0)]);
  }
  mesh.remove_property_map(vnormals);
}

//! The loop hedge's vertex_normals() runs (area-weighted scatter over faces), on CGAL.
void normals_loop(benchmark::State& state) {
  const SMesh& mesh = cached();
  std::vector<Kernel::Vector_3> out(mesh.number_of_vertices());
  for (auto _ : state) {
    std::fill(out.begin(), out.end(), CGAL::NULL_VECTOR);
    for (SMesh::Face_index f : mesh.faces()) {
      const auto h0 = mesh.halfedge(f);
      const auto h1 = mesh.next(h0);
      const auto h2 = mesh.next(h1);
      const VI a = mesh.target(h0), b = mesh.target(h1), c = mesh.target(h2);
      const Kernel::Point_3& pa = mesh.point(a);
      const Kernel::Vector_3 n = CGAL::cross_product(mesh.point(b) - pa, mesh.point(c) - pa);
      out[a.idx()] = out[a.idx()] + n;
      out[b.idx()] = out[b.idx()] + n;
      out[c.idx()] = out[c.idx()] + n;
    }
    for (Kernel::Vector_3& n : out) {
      const double length = std::sqrt(n.squared_length());
      if (length > 0) n = n / length;
    }
    benchmark::DoNotOptimize(out.data());
  }
}

void memory_of(benchmark::State& state, bool reserve) {
  measure_memory(state, "CGAL", reserve, build_mesh, [](const SMesh& mesh) {
    return std::pair<std::size_t, std::size_t>(mesh.number_of_vertices(), mesh.number_of_faces());
  });
}
void memory(benchmark::State& state) { memory_of(state, false); }
void memory_reserved(benchmark::State& state) { memory_of(state, true); }

// ---- whole operations (--ops) ----------------------------------------------------------

//! The mesh as a soup (live elements only), for the error measurements.
hedge::Soup to_soup(const SMesh& mesh) {
  hedge::Soup soup;
  std::vector<std::uint32_t> index(mesh.num_vertices(), 0);
  for (VI v : mesh.vertices()) {
    index[v.idx()] = static_cast<std::uint32_t>(soup.positions.size());
    const Kernel::Point_3& p = mesh.point(v);
    soup.positions.push_back({static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z())});
  }
  for (auto f : mesh.faces()) {
    std::uint32_t n = 0;
    for (VI v : vertices_around_face(mesh.halfedge(f), mesh)) {
      soup.corners.push_back(index[v.idx()]);
      ++n;
    }
    soup.face_sizes.push_back(n);
  }
  return soup;
}

//! Stops edge_collapse when the face count reaches the target (CGAL 5.5's stop predicates
//! count edges only).
struct FaceCountStop {
  const SMesh* mesh;
  std::size_t target;
  template <class Cost, class Profile>
  bool operator()(const Cost&, const Profile&, std::size_t, std::size_t) const {
    return mesh->number_of_faces() <= target;
  }
};

//! Surface_mesh_simplification::edge_collapse with the Garland-Heckbert plane policies
//! (classic quadrics, CGAL 5.5), to 10 % of the faces.
OpRun decimate_run(double) {
  namespace SMS = CGAL::Surface_mesh_simplification;
  return time_operation(
      [] { return build_mesh(false); },
      [&](SMesh& mesh) {
        {
          SMS::GarlandHeckbert_plane_policies<SMesh, Kernel> policies(mesh);
          FaceCountStop stop{&mesh, static_cast<std::size_t>(
                                        std::llround(kDecimateRatio * static_cast<double>(mesh.number_of_faces())))};
          SMS::edge_collapse(mesh, stop,
                             CGAL::parameters::get_cost(policies.get_cost()).get_placement(policies.get_placement()));
        }
      },
      [](const SMesh& mesh) { return to_soup(mesh); });
}

//! Polygon_mesh_processing::isotropic_remeshing of every face, at the shared target
//! length, 3 iterations, CGAL's defaults otherwise (1 relaxation step, projection on).
OpRun remesh_run(double target) {
  return time_operation([] { return build_mesh(false); },
                        [&](SMesh& mesh) {
                          CGAL::Polygon_mesh_processing::isotropic_remeshing(
                              faces(mesh), target, mesh, CGAL::parameters::number_of_iterations(kRemeshIterations));
                        },
                        [](const SMesh& mesh) { return to_soup(mesh); });
}

//! One step of a Subdivision_method_3 scheme.
enum class Scheme { loop, catmull_clark, sqrt3 };

template <Scheme scheme>
OpRun subdivide_run(double) {
  return time_operation([] { return build_mesh(false); },
                        [&](SMesh& mesh) {
                          namespace SM = CGAL::Subdivision_method_3;
                          const auto one_step = CGAL::parameters::number_of_iterations(1);
                          if constexpr (scheme == Scheme::loop) SM::Loop_subdivision(mesh, one_step);
                          if constexpr (scheme == Scheme::catmull_clark) SM::CatmullClark_subdivision(mesh, one_step);
                          if constexpr (scheme == Scheme::sqrt3) SM::Sqrt3_subdivision(mesh, one_step);
                        },
                        [](const SMesh& mesh) { return to_soup(mesh); });
}

}  // namespace

std::vector<Entry> cgal_benchmarks() {
  return {{kBuild, build},
          {kBuildReserved, build_reserved},
          {kCirculate, circulate},
          {kNormals, normals},
          {kNormalsLoop, normals_loop},
          {kMemory, memory},
          {kMemoryReserved, memory_reserved}};
}

std::vector<OpEntry> cgal_operations() {
  return {{kOpDecimate, "SMS::edge_collapse, GarlandHeckbert_plane_policies (policy set-up included)", decimate_run},
          {kOpRemesh, "PMP::isotropic_remeshing(faces(mesh), L, mesh, number_of_iterations(3))", remesh_run},
          {kOpLoop, "Subdivision_method_3::Loop_subdivision, 1 step", subdivide_run<Scheme::loop>},
          {kOpCatmull, "Subdivision_method_3::CatmullClark_subdivision, 1 step", subdivide_run<Scheme::catmull_clark>},
          {kOpSqrt3, "Subdivision_method_3::Sqrt3_subdivision, 1 step", subdivide_run<Scheme::sqrt3>}};
}

}  // namespace bench
