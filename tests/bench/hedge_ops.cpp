// hedge's side of hedge_bench: build(), circulators, vertex_normals(), heap.
#include <memory>
#include <string>

#include "bench.h"
#include "hedge/build.h"
#include "hedge/mesh.h"
#include "hedge/normals.h"

namespace bench {

namespace {

//! The mesh the query benchmarks use, built once.
std::unique_ptr<hedge::BuildResult>& cache_slot() {
  static std::unique_ptr<hedge::BuildResult> result;
  return result;
}

hedge::BuildResult& cached() {
  std::unique_ptr<hedge::BuildResult>& result = cache_slot();
  if (!result) {
    result = std::make_unique<hedge::BuildResult>(hedge::build(input().soup));
    LibraryStats& s = stats("hedge");
    s.vertices = result->mesh.n_vertices();
    s.faces = result->mesh.n_faces();
    const hedge::BuildReport& r = result->report;
    s.notes.push_back("build report: " + std::to_string(r.non_manifold_edges) + " non-manifold edges, " +
                      std::to_string(r.non_manifold_vertices) + " non-manifold vertices (" +
                      std::to_string(r.vertex_copies) + " copies), " + std::to_string(r.flipped_faces) + " flipped, " +
                      std::to_string(r.skipped_faces) + " skipped faces");
  }
  return *result;
}

void build(benchmark::State& state) {
  const hedge::Soup& soup = input().soup;
  for (auto _ : state) {
    auto result = std::make_unique<hedge::BuildResult>(hedge::build(soup));
    benchmark::DoNotOptimize(result.get());
    state.PauseTiming();
    result.reset();
    state.ResumeTiming();
  }
}

void circulate(benchmark::State& state) {
  const hedge::Mesh& mesh = cached().mesh;
  std::uint64_t sum = 0;
  for (auto _ : state) {
    sum = 0;
    for (hedge::Vertex v : mesh.vertices())
      for (hedge::Vertex w : mesh.vertices(v)) sum += w.idx();
    benchmark::DoNotOptimize(sum);
  }
  stats("hedge").circulation_sum = sum;
}

void normals(benchmark::State& state) {
  const hedge::Mesh& mesh = cached().mesh;
  std::vector<hedge::Vec3f> out(mesh.vertices_size());
  for (auto _ : state) {
    hedge::vertex_normals(mesh, out);
    benchmark::DoNotOptimize(out.data());
  }
}

void memory(benchmark::State& state) {
  LibraryStats& s = stats("hedge");
  for (auto _ : state) {
    HeapWindow heap;
    hedge::Mesh mesh;
    {
      hedge::BuildResult result = hedge::build(input().soup);
      s.peak_bytes = heap.peak();
      const std::int64_t with_maps = heap.live();
      mesh = std::move(result.mesh);
      s.notes.push_back("BuildResult (mesh + report + maps) held " +
                        std::to_string(with_maps / 100000 / 10.0).substr(0, 5) + " MB");
    }
    // The mesh alone: what stays after the caller drops the report and the maps.
    s.live_bytes = heap.live();
    s.malloc_bytes = heap.malloc_live();
    s.self_reported = static_cast<std::int64_t>(mesh.heap_bytes());
    s.vertices = mesh.n_vertices();
    s.faces = mesh.n_faces();
    std::string props;
    auto list = [&](const char* kind, const hedge::PropertyContainer& c) {
      for (std::size_t i = 0; i < c.count(); ++i)
        props +=
            std::string(" ") + kind + ":" + c.at(i).name() + "=" + std::to_string(c.at(i).heap_bytes() >> 10) + "KB";
    };
    list("v", mesh.vertex_properties());
    list("h", mesh.halfedge_properties());
    list("e", mesh.edge_properties());
    list("f", mesh.face_properties());
    if (!props.empty()) s.notes.push_back("mesh properties after build:" + props);
  }
  state.counters["MB"] = static_cast<double>(s.live_bytes) / 1e6;
  state.counters["bytes_per_face"] = static_cast<double>(s.live_bytes) / static_cast<double>(s.faces);
}

}  // namespace

std::vector<hedge::Vec3f> hedge_area_normals_by_soup_vertex() {
  if (!cache_slot()) return {};
  const hedge::BuildResult& r = *cache_slot();
  const auto normals = hedge::vertex_normals(r.mesh);
  std::vector<hedge::Vec3f> by_source(input().soup.n_vertices());
  std::vector<bool> seen(by_source.size());
  for (std::size_t v = 0; v < normals.size(); ++v) {
    const std::uint32_t source = r.maps.vertex_source.empty() ? static_cast<std::uint32_t>(v) : r.maps.vertex_source[v];
    if (source >= by_source.size()) continue;
    // A vertex split into copies has no single normal to compare; leave it out.
    by_source[source] = seen[source] ? hedge::Vec3f{} : normals[v];
    seen[source] = true;
  }
  return by_source;
}

std::vector<Entry> hedge_benchmarks() {
  // hedge has one build and one normals function: the table compares the peers' variants
  // (reserve(), hand-written loop) against these same numbers.
  return {{kBuild, build}, {kCirculate, circulate}, {kNormals, normals}, {kMemory, memory}};
}

}  // namespace bench
