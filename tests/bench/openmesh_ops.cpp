// OpenMesh's side of hedge_bench: TriMesh_ArrayKernelT<> with default traits (float
// points, prev half-edges; no status or normals unless requested), filled with
// add_vertex + add_face, which drops the faces that would make an edge or vertex complex.
#include <OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh>
#include <OpenMesh/Core/System/omstream.hh>
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
  LibraryStats& s = stats("OpenMesh");
  for (auto _ : state) {
    HeapWindow heap;
    auto mesh = build_mesh(reserve);
    if (reserve) {
      s.reserved_live_bytes = heap.live();
    } else {
      s.vertices = mesh->n_vertices();
      s.faces = mesh->n_faces();
      s.live_bytes = heap.live();
      s.peak_bytes = heap.peak();
      s.malloc_bytes = heap.malloc_live();
    }
    state.counters["MB"] = static_cast<double>(heap.live()) / 1e6;
    state.counters["bytes_per_face"] = static_cast<double>(heap.live()) / static_cast<double>(mesh->n_faces());
    mesh.reset();
  }
}
void memory(benchmark::State& state) { memory_of(state, false); }
void memory_reserved(benchmark::State& state) { memory_of(state, true); }

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

}  // namespace bench
