// Shared pieces of hedge_bench: the input mesh, the heap counter, and what each library's
// benchmarks record for the summary table printed at the end.
#pragma once

#include <benchmark/benchmark.h>
#include <time.h>

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "hedge/soup.h"

namespace bench {

//! The indexed triangle soup every library builds from, read once before any timing.
struct Input {
  std::string path;
  hedge::Soup soup;
  std::size_t unique_edges = 0;  //!< undirected edges of the soup (for the peers' reserve())
};
const Input& input();
void load_input(const std::string& path);

//! True when a face visits a vertex twice. Such faces are not offered to the peers: the
//! Debian OpenMesh is built with assertions on and aborts on them (CGAL would refuse them).
inline bool repeats_vertex(const std::uint32_t* corners, std::uint32_t n) {
  if (n == 3) return corners[0] == corners[1] || corners[1] == corners[2] || corners[0] == corners[2];
  for (std::uint32_t i = 0; i < n; ++i)
    for (std::uint32_t j = 0; j < i; ++j)
      if (corners[i] == corners[j]) return true;
  return false;
}

//! Counts live heap bytes (malloc_usable_size of every malloc/free in the process, with
//! glibc's own mallinfo2 as a cross-check) between construction and destruction. One
//! window at a time.
class HeapWindow {
 public:
  HeapWindow();
  ~HeapWindow();
  HeapWindow(const HeapWindow&) = delete;
  HeapWindow& operator=(const HeapWindow&) = delete;
  std::int64_t live() const;         //!< bytes allocated and not freed since the start
  std::int64_t peak() const;         //!< the largest live() seen so far
  std::int64_t malloc_live() const;  //!< the same from mallinfo2 (all of malloc)

 private:
  std::int64_t malloc_start_;
};

//! What a library's benchmarks found, shown in the summary.
struct LibraryStats {
  std::size_t vertices = 0, faces = 0;    //!< in the built mesh (peers drop non-manifold faces)
  std::int64_t live_bytes = -1;           //!< heap held by the built mesh (default build)
  std::int64_t peak_bytes = -1;           //!< heap peak during that build
  std::int64_t malloc_bytes = -1;         //!< mallinfo2's view of live_bytes
  std::int64_t reserved_live_bytes = -1;  //!< heap held when built with exact reserve()
  std::int64_t self_reported = -1;        //!< the library's own count (hedge: Mesh::heap_bytes())
  std::uint64_t circulation_sum = 0;      //!< checksum of the one-ring benchmark
  std::vector<std::string> notes;
};
LibraryStats& stats(const std::string& library);

//! The memory benchmark of a peer: heap held by the mesh `build(reserve)` returns (a smart
//! pointer), recorded in stats(library) with the counts `count(mesh)` gives as a pair.
template <class Build, class Count>
void measure_memory(benchmark::State& state, const std::string& library, bool reserve, Build build, Count count) {
  LibraryStats& s = stats(library);
  for (auto _ : state) {
    HeapWindow heap;
    auto mesh = build(reserve);
    const auto [vertices, faces] = count(*mesh);
    if (reserve) {
      s.reserved_live_bytes = heap.live();
    } else {
      s.vertices = vertices;
      s.faces = faces;
      s.live_bytes = heap.live();
      s.peak_bytes = heap.peak();
      s.malloc_bytes = heap.malloc_live();
    }
    state.counters["MB"] = static_cast<double>(heap.live()) / 1e6;
    state.counters["bytes_per_face"] = static_cast<double>(heap.live()) / static_cast<double>(faces);
    mesh.reset();
  }
}

//! One benchmark of one library. `op` is the table row (and the first part of the
//! benchmark name, `op/library`).
struct Entry {
  std::string op;
  void (*run)(benchmark::State&);
};
std::vector<Entry> hedge_benchmarks();
std::vector<Entry> openmesh_benchmarks();
std::vector<Entry> cgal_benchmarks();

//! Vertex normals of the cached mesh of a library, indexed by soup vertex (for the
//! cross-check that all libraries computed the same thing); empty when not built.
std::vector<hedge::Vec3f> hedge_area_normals_by_soup_vertex();
std::vector<hedge::Vec3f> openmesh_area_normals_by_soup_vertex();

// Row names shared by the library files and the table.
inline constexpr const char* kBuild = "build";
inline constexpr const char* kBuildReserved = "build_reserved";
inline constexpr const char* kCirculate = "circulate";
inline constexpr const char* kNormals = "vertex_normals";
inline constexpr const char* kNormalsLoop = "vertex_normals_loop";
inline constexpr const char* kMemory = "memory";
inline constexpr const char* kMemoryReserved = "memory_reserved";

// ---- the operation table (hedge_bench --ops) ------------------------------------------
// Whole operations (decimate, remesh, subdivide, smooth), one run each, timed by the
// library file itself around the library's own call, on a mesh it built from the soup
// beforehand (not timed). The result comes back as a soup for the error measurements.

//! Wall-clock and process-CPU time of one stretch of code.
class Stopwatch {
 public:
  Stopwatch() { start(); }
  void start() {
    wall_ = std::chrono::steady_clock::now();
    cpu_ = cpu_now();
  }
  //! Seconds since start(): wall clock, and CPU time of all the process's threads.
  void stop(double& wall_s, double& cpu_s) const {
    wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_).count();
    cpu_s = cpu_now() - cpu_;
  }

 private:
  static double cpu_now() {
    timespec t{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
  }
  std::chrono::steady_clock::time_point wall_;
  double cpu_ = 0;
};

//! The operations of the table, with the parameters every library is given.
inline constexpr const char* kOpDecimate = "decimate";  // to 10 % of the input's faces
inline constexpr const char* kOpRemesh = "remesh";      // isotropic, mean edge length, 3 iterations
inline constexpr const char* kOpLoop = "loop";          // Loop subdivision, 1 step
inline constexpr const char* kOpCatmull = "catmull";    // Catmull-Clark subdivision, 1 step
inline constexpr const char* kOpSqrt3 = "sqrt3";        // Kobbelt's sqrt3 subdivision, 1 step
inline constexpr const char* kOpSmooth = "smooth";      // uniform Laplace, Jacobi, 10 steps of 1/2
inline constexpr double kDecimateRatio = 0.1;
inline constexpr int kRemeshIterations = 3;
inline constexpr int kSmoothIterations = 10;

//! What one run of one operation gave.
struct OpRun {
  double wall_s = 0, cpu_s = 0;  //!< the timed part only
  hedge::Soup output;            //!< the result (for counts and distances; not timed)
};

//! Builds a library's mesh (not timed), times `op(mesh)`, and converts the result with
//! `to_soup` (not timed).
template <class Build, class Op, class ToSoup>
OpRun time_operation(Build build_mesh, Op op, ToSoup to_soup) {
  auto mesh = build_mesh();
  OpRun run;
  Stopwatch watch;
  op(*mesh);
  watch.stop(run.wall_s, run.cpu_s);
  run.output = to_soup(*mesh);
  return run;
}

//! One library's implementation of one operation. `run` times only the call named in
//! `scope`; the input is the shared soup and, for remesh, the target edge length.
struct OpEntry {
  std::string op;
  std::string scope;  //!< what the time includes, for the table's legend
  OpRun (*run)(double target_edge_length);
};
std::vector<OpEntry> hedge_operations();
std::vector<OpEntry> openmesh_operations();
std::vector<OpEntry> cgal_operations();
std::vector<OpEntry> meshopt_simplify_operations();  // meshopt_simplify
std::vector<OpEntry> meshopt_sloppy_operations();    // meshopt_simplifySloppy, the lower bound of time

//! Runs the operation table (and, with `hosts`, MeshLab and Blender as separate processes);
//! returns the process exit code.
//! `only`: the operation ids to run (kOpLoop, ...); empty for all.
int run_operation_table(int reps, bool hosts, const std::vector<std::string>& only = {});
//! --scale (scale.cpp): the pipeline on 10M+ triangles and cost per triangle by size;
//! growth_only skips the pipeline.
int run_scale(const std::string& dragon_path, bool growth_only);
//! --files (files.cpp): each format written and read in memory, fastest of `reps`.
int run_files(const std::string& path, int reps);

}  // namespace bench
