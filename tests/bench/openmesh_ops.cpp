// OpenMesh's side of hedge_bench: TriMesh_ArrayKernelT<> with default traits (float
// points, prev half-edges; no status or normals unless requested), filled with
// add_vertex + add_face, which drops the faces that would make an edge or vertex complex.
#include <OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh>
#include <OpenMesh/Core/System/omstream.hh>
#include <OpenMesh/Tools/Decimater/DecimaterT.hh>
#include <OpenMesh/Tools/Decimater/ModQuadricT.hh>
#include <OpenMesh/Tools/Smoother/JacobiLaplaceSmootherT.hh>
#include <OpenMesh/Tools/Subdivider/Uniform/LoopT.hh>
#include <OpenMesh/Tools/Subdivider/Uniform/Sqrt3T.hh>
#include <cmath>
#include <memory>
#include <vector>

#include "bench.h"

namespace bench {

namespace {

using OMesh = OpenMesh::TriMesh_ArrayKernelT<>;

//! Fills an OpenMesh mesh from the soup; `reserve` passes it the exact element counts first.
std::unique_ptr<OMesh> build_mesh(bool reserve) {
  const hedge::Soup& soup = input().soup;
  auto mesh = std::make_unique<OMesh>();
  if (reserve) mesh->reserve(soup.n_vertices(), input().unique_edges, soup.n_faces());
  for (const hedge::Point& p : soup.positions) mesh->add_vertex(OMesh::Point(p[0], p[1], p[2]));
  std::vector<OMesh::VertexHandle> polygon;
  std::size_t offset = 0;
  const std::uint32_t* c = soup.corners.data();
  for (std::uint32_t n : soup.face_sizes) {
    if (repeats_vertex(c + offset, n)) {
      offset += n;
      continue;
    }
    if (n == 3) {
      mesh->add_face(OMesh::VertexHandle(static_cast<int>(c[offset])),
                     OMesh::VertexHandle(static_cast<int>(c[offset + 1])),
                     OMesh::VertexHandle(static_cast<int>(c[offset + 2])));
    } else {
      polygon.clear();
      for (std::uint32_t i = 0; i < n; ++i) polygon.emplace_back(static_cast<int>(c[offset + i]));
      mesh->add_face(polygon);
    }
    offset += n;
  }
  return mesh;
}

std::unique_ptr<OMesh>& cache_slot() {
  static std::unique_ptr<OMesh> mesh;
  return mesh;
}

OMesh& cached() {
  std::unique_ptr<OMesh>& mesh = cache_slot();
  if (!mesh) {
    mesh = build_mesh(false);
    stats("OpenMesh").vertices = mesh->n_vertices();
    stats("OpenMesh").faces = mesh->n_faces();
  }
  return *mesh;
}

void build(benchmark::State& state) {
  for (auto _ : state) {
    auto mesh = build_mesh(false);
    benchmark::DoNotOptimize(mesh.get());
    state.PauseTiming();
    stats("OpenMesh").vertices = mesh->n_vertices();
    stats("OpenMesh").faces = mesh->n_faces();
    mesh.reset();
    state.ResumeTiming();
  }
}

void build_reserved(benchmark::State& state) {
  for (auto _ : state) {
    auto mesh = build_mesh(true);
    benchmark::DoNotOptimize(mesh.get());
    state.PauseTiming();
    mesh.reset();
    state.ResumeTiming();
  }
}

void circulate(benchmark::State& state) {
  const OMesh& mesh = cached();
  std::uint64_t sum = 0;
  for (auto _ : state) {
    sum = 0;
    for (OMesh::VertexHandle v : mesh.vertices())
      for (auto it = mesh.cvv_iter(v); it.is_valid(); ++it) sum += static_cast<std::uint32_t>(it->idx());
    benchmark::DoNotOptimize(sum);
  }
  stats("OpenMesh").circulation_sum = sum;
}

//! OpenMesh's own path: face normals (unit), then per vertex their normalized sum.
void normals(benchmark::State& state) {
  OMesh& mesh = cached();
  mesh.request_face_normals();
  mesh.request_vertex_normals();
  for (auto _ : state) {
    mesh.update_normals();
    benchmark::DoNotOptimize(mesh.vertex_normals());
  }
  mesh.release_vertex_normals();
  mesh.release_face_normals();
}

//! The loop hedge's vertex_normals() runs (area-weighted scatter over faces), on OpenMesh.
void area_normals(const OMesh& mesh, std::vector<OMesh::Normal>& out) {
  std::fill(out.begin(), out.end(), OMesh::Normal(0, 0, 0));
  for (OMesh::FaceHandle f : mesh.faces()) {
    const auto h0 = mesh.halfedge_handle(f);
    const auto h1 = mesh.next_halfedge_handle(h0);
    const auto h2 = mesh.next_halfedge_handle(h1);
    const auto a = mesh.to_vertex_handle(h0), b = mesh.to_vertex_handle(h1), c = mesh.to_vertex_handle(h2);
    const OMesh::Point& pa = mesh.point(a);
    const OMesh::Normal n = OpenMesh::cross(mesh.point(b) - pa, mesh.point(c) - pa);
    out[a.idx()] += n;
    out[b.idx()] += n;
    out[c.idx()] += n;
  }
  for (OMesh::Normal& n : out) {
    const float length = n.norm();
    if (length > 0) n /= length;
  }
}

void normals_loop(benchmark::State& state) {
  const OMesh& mesh = cached();
  std::vector<OMesh::Normal> out(mesh.n_vertices());
  for (auto _ : state) {
    area_normals(mesh, out);
    benchmark::DoNotOptimize(out.data());
  }
}

void memory_of(benchmark::State& state, bool reserve) {
  measure_memory(state, "OpenMesh", reserve, build_mesh, [](const OMesh& mesh) {
    return std::pair<std::size_t, std::size_t>(mesh.n_vertices(), mesh.n_faces());
  });
}
void memory(benchmark::State& state) { memory_of(state, false); }
void memory_reserved(benchmark::State& state) { memory_of(state, true); }

// ---- whole operations (--ops) ----------------------------------------------------------

//! The mesh as a soup (live elements only), for the error measurements.
hedge::Soup to_soup(const OMesh& mesh) {
  hedge::Soup soup;
  std::vector<std::uint32_t> index(mesh.n_vertices(), 0);
  for (auto v : mesh.vertices()) {
    index[static_cast<std::size_t>(v.idx())] = static_cast<std::uint32_t>(soup.positions.size());
    const OMesh::Point& p = mesh.point(v);
    soup.positions.push_back({p[0], p[1], p[2]});
  }
  for (auto f : mesh.faces()) {
    std::uint32_t n = 0;
    for (auto v : mesh.fv_range(f)) {
      soup.corners.push_back(index[static_cast<std::size_t>(v.idx())]);
      ++n;
    }
    soup.face_sizes.push_back(n);
  }
  return soup;
}

//! Decimater + ModQuadric (no error bound: the quadric only ranks), to 10 % of the faces.
OpRun decimate_run(double) {
  return time_operation([] { return build_mesh(false); },
                        [&](OMesh& mesh) {
                          {
                            mesh.request_vertex_status();
                            mesh.request_edge_status();
                            mesh.request_face_status();
                            OpenMesh::Decimater::DecimaterT<OMesh> decimater(mesh);
                            OpenMesh::Decimater::ModQuadricT<OMesh>::Handle quadric;
                            decimater.add(quadric);
                            decimater.module(quadric).unset_max_err();
                            decimater.initialize();
                            const auto target = static_cast<std::size_t>(
                                std::llround(kDecimateRatio * static_cast<double>(mesh.n_faces())));
                            decimater.decimate_to_faces(0, target);
                          }
                          mesh.garbage_collection();
                        },
                        [](const OMesh& mesh) { return to_soup(mesh); });
}

//! One step of a Subdivider::Uniform scheme (LoopT, Sqrt3T), with its default precision.
template <template <class> class Subdivider>
OpRun subdivide_run(double) {
  return time_operation([] { return build_mesh(false); },
                        [&](OMesh& mesh) {
                          {
                            Subdivider<OMesh> subdivider;
                            subdivider.attach(mesh);
                            subdivider(1);
                            subdivider.detach();
                          }
                        },
                        [](const OMesh& mesh) { return to_soup(mesh); });
}

//! Smoother::JacobiLaplaceSmootherT: uniform weights, tangential and normal, C0, 10 steps
//! (each moves a vertex half way to its neighbours' mean; boundary vertices stay).
OpRun smooth_run(double) {
  return time_operation([] { return build_mesh(false); },
                        [&](OMesh& mesh) {
                          {
                            OpenMesh::Smoother::JacobiLaplaceSmootherT<OMesh> smoother(mesh);
                            smoother.initialize(OpenMesh::Smoother::SmootherT<OMesh>::Tangential_and_Normal,
                                                OpenMesh::Smoother::SmootherT<OMesh>::C0);
                            smoother.smooth(kSmoothIterations);
                          }
                        },
                        [](const OMesh& mesh) { return to_soup(mesh); });
}

}  // namespace

std::vector<hedge::Vec3f> openmesh_area_normals_by_soup_vertex() {
  if (!cache_slot()) return {};
  const OMesh& mesh = *cache_slot();
  std::vector<OMesh::Normal> normals(mesh.n_vertices());
  area_normals(mesh, normals);
  std::vector<hedge::Vec3f> out(normals.size());
  for (std::size_t i = 0; i < out.size(); ++i) out[i] = {{normals[i][0], normals[i][1], normals[i][2]}};
  return out;
}

std::vector<Entry> openmesh_benchmarks() {
  // add_face reports every dropped face on omerr; thousands of lines would bury the results.
  omerr().disable();
  return {{kBuild, build},
          {kBuildReserved, build_reserved},
          {kCirculate, circulate},
          {kNormals, normals},
          {kNormalsLoop, normals_loop},
          {kMemory, memory},
          {kMemoryReserved, memory_reserved}};
}

std::vector<OpEntry> openmesh_operations() {
  return {{kOpDecimate, "DecimaterT + ModQuadricT: initialize, decimate_to_faces, garbage_collection", decimate_run},
          {kOpLoop, "Subdivider::Uniform::LoopT, 1 step", subdivide_run<OpenMesh::Subdivider::Uniform::LoopT>},
          {kOpSqrt3, "Subdivider::Uniform::Sqrt3T, 1 step", subdivide_run<OpenMesh::Subdivider::Uniform::Sqrt3T>},
          {kOpSmooth, "JacobiLaplaceSmootherT: constructor, initialize, smooth(10)", smooth_run}};
}

}  // namespace bench
