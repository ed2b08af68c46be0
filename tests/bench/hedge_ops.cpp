// hedge's side of hedge_bench: build(), circulators, vertex_normals(), heap.
#include <cmath>
#include <memory>
#include <string>

#include "bench.h"
#include "hedge/build.h"
#include "hedge/decimate.h"
#include "hedge/mesh.h"
#include "hedge/normals.h"
#include "hedge/remesh.h"
#include "hedge/smooth.h"
#include "hedge/subdivide.h"

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

// ---- whole operations (--ops) ----------------------------------------------------------
// Each runs twice in one call: the operation alone on a mesh built beforehand (the same
// scope as the peers' rows), and build + operation + extract from the soup (what a host
// pays). OpRun carries the first; the second goes under the library name "hedge+io".

template <class Operation>
OpRun run_hedge(Operation operation) {
  return time_operation([] { return std::make_unique<hedge::Mesh>(hedge::build(input().soup).mesh); }, operation,
                        [](const hedge::Mesh& mesh) { return hedge::extract(mesh); });
}

template <class Operation>
OpRun run_hedge_io(Operation operation) {
  OpRun run;
  Stopwatch watch;
  hedge::Mesh mesh = hedge::build(input().soup).mesh;
  operation(mesh);
  run.output = hedge::extract(mesh);
  watch.stop(run.wall_s, run.cpu_s);
  return run;
}

void decimate_op(hedge::Mesh& mesh) {
  hedge::DecimateOptions options;
  options.target_faces = static_cast<std::size_t>(std::llround(kDecimateRatio * static_cast<double>(mesh.n_faces())));
  hedge::decimate(mesh, options);
}

double g_target_length = 0;
void remesh_op(hedge::Mesh& mesh) {
  hedge::RemeshOptions options;  // the catalogue's defaults: features at 45 degrees, boundary kept
  options.target_edge_length = g_target_length;
  options.iterations = kRemeshIterations;
  hedge::remesh(mesh, options);
}

template <hedge::SubdivisionScheme scheme>
void subdivide_op(hedge::Mesh& mesh) {
  hedge::SubdivideOptions options;  // one step, no creases
  options.scheme = scheme;
  hedge::subdivide(mesh, options);
}
constexpr auto loop_op = subdivide_op<hedge::SubdivisionScheme::loop>;
constexpr auto catmull_op = subdivide_op<hedge::SubdivisionScheme::catmull_clark>;
constexpr auto sqrt3_op = subdivide_op<hedge::SubdivisionScheme::sqrt3>;

void smooth_op(hedge::Mesh& mesh) {
  hedge::SmoothOptions options;  // uniform weights, 1/2 of the way, boundary fixed
  options.iterations = kSmoothIterations;
  hedge::smooth(mesh, options);
}

//! The table's entry point: `with_io` selects build + operation + extract as the timed part.
template <void (*Op)(hedge::Mesh&), bool with_io>
OpRun run_op(double target) {
  g_target_length = target;
  return with_io ? run_hedge_io(Op) : run_hedge(Op);
}

}  // namespace

std::vector<OpEntry> hedge_operations() {
  const std::string alone = "the operation on a built Mesh";
  const std::string io = "build from the soup + operation + extract to a soup";
  return {{kOpDecimate, alone, run_op<decimate_op, false>}, {kOpDecimate, io, run_op<decimate_op, true>},
          {kOpRemesh, alone, run_op<remesh_op, false>},     {kOpRemesh, io, run_op<remesh_op, true>},
          {kOpLoop, alone, run_op<loop_op, false>},         {kOpLoop, io, run_op<loop_op, true>},
          {kOpCatmull, alone, run_op<catmull_op, false>},   {kOpCatmull, io, run_op<catmull_op, true>},
          {kOpSqrt3, alone, run_op<sqrt3_op, false>},       {kOpSqrt3, io, run_op<sqrt3_op, true>},
          {kOpSmooth, alone, run_op<smooth_op, false>},     {kOpSmooth, io, run_op<smooth_op, true>}};
}

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
