// hedge_bench: hedge against OpenMesh and CGAL Surface_mesh on one big mesh, in one process:
// building from an indexed soup, one-ring circulation, vertex normals, heap held by the
// built mesh. Google Benchmark does the timing; a summary table of minima and ratios follows.
//
//   hedge_bench [--meshes DIR] [--mesh FILE] [--reps N] [--benchmark_filter=REGEX] ...
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "bench.h"
#include "hedge/error.h"
#include "hedge/io.h"
#include "hedge/threads.h"

namespace bench {

LibraryStats& stats(const std::string& library) {
  static std::map<std::string, LibraryStats> all;
  return all[library];
}

// ---- the input ----------------------------------------------------------------------
namespace {
Input g_input;
}

const Input& input() { return g_input; }

void load_input(const std::string& path) {
  g_input.path = path;
  g_input.soup = hedge::read_mesh(path);
  std::vector<std::uint64_t> keys;
  keys.reserve(g_input.soup.n_corners());
  const auto offsets = g_input.soup.face_offsets();
  for (std::size_t f = 0; f < g_input.soup.n_faces(); ++f) {
    const std::size_t begin = offsets[f], n = g_input.soup.face_sizes[f];
    for (std::size_t i = 0; i < n; ++i) {
      std::uint64_t a = g_input.soup.corners[begin + i], b = g_input.soup.corners[begin + (i + 1) % n];
      if (a > b) std::swap(a, b);
      keys.push_back(a << 32 | b);
    }
  }
  std::sort(keys.begin(), keys.end());
  g_input.unique_edges = static_cast<std::size_t>(std::unique(keys.begin(), keys.end()) - keys.begin());
}

// ---- collecting results ----------------------------------------------------------------
namespace {

struct Timing {
  double min_ms = NAN, median_ms = NAN;  //!< wall clock
  double cpu_min_ms = NAN;               //!< this process's CPU time
  std::string error;
};
std::map<std::string, Timing> g_timings;  // "op/library"
std::vector<std::string> g_ops;           // table rows, in order

double min_of(const std::vector<double>& v) { return v.empty() ? 0.0 : *std::min_element(v.begin(), v.end()); }

//! Forwards everything to the usual display reporter and keeps the minima and medians.
class CollectingReporter : public benchmark::BenchmarkReporter {
 public:
  explicit CollectingReporter(benchmark::BenchmarkReporter* display) : display_(display) {}
  bool ReportContext(const Context& context) override { return display_->ReportContext(context); }
  void ReportRuns(const std::vector<Run>& runs) override {
    for (const Run& run : runs) {
      Timing& t = g_timings[run.run_name.function_name];
      if (run.error_occurred) t.error = run.error_message;
      if (run.run_type == Run::RT_Iteration && run.repetitions <= 1) {
        t.min_ms = t.median_ms = to_ms(run.GetAdjustedRealTime(), run.time_unit);
        t.cpu_min_ms = to_ms(run.GetAdjustedCPUTime(), run.time_unit);
      } else if (run.run_type == Run::RT_Aggregate && run.aggregate_name == "min") {
        t.min_ms = to_ms(run.GetAdjustedRealTime(), run.time_unit);
        t.cpu_min_ms = to_ms(run.GetAdjustedCPUTime(), run.time_unit);
      } else if (run.run_type == Run::RT_Aggregate && run.aggregate_name == "median") {
        t.median_ms = to_ms(run.GetAdjustedRealTime(), run.time_unit);
      }
    }
    display_->ReportRuns(runs);
  }
  void Finalize() override { display_->Finalize(); }

 private:
  static double to_ms(double value, benchmark::TimeUnit unit) {
    switch (unit) {
      case benchmark::kNanosecond:
        return value * 1e-6;
      case benchmark::kMicrosecond:
        return value * 1e-3;
      case benchmark::kMillisecond:
        return value;
      case benchmark::kSecond:
        return value * 1e3;
    }
    return value;
  }
  benchmark::BenchmarkReporter* display_;
};

// ---- the summary ---------------------------------------------------------------------
const char* const kLibraries[] = {"hedge", "OpenMesh", "CGAL"};

std::string row_title(const std::string& op) {
  if (op == kBuild) return "build from soup";
  if (op == kBuildReserved) return "build, peers reserve() exactly";
  if (op == kCirculate) return "one-ring circulation";
  if (op == kNormals) return "vertex normals (library API)";
  if (op == kNormalsLoop) return "vertex normals (same loop)";
  return op;
}

double ms_of(const std::string& key, bool cpu) {
  auto it = g_timings.find(key);
  if (it == g_timings.end() || !it->second.error.empty()) return NAN;
  return cpu ? it->second.cpu_min_ms : it->second.min_ms;
}

std::string cell_ms(const std::string& key, bool cpu) {
  auto it = g_timings.find(key);
  if (it == g_timings.end()) return "-";
  if (!it->second.error.empty()) return "n/a";
  char buf[32];
  const double ms = ms_of(key, cpu);
  std::snprintf(buf, sizeof buf, ms < 10 ? "%.2f" : "%.1f", ms);
  return buf;
}

std::string ratio(double num, double den) {
  if (!(num > 0) || !(den > 0)) return "-";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.2fx", num / den);
  return buf;
}

std::string mb(std::int64_t bytes) {
  if (bytes < 0) return "-";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1f", static_cast<double>(bytes) / 1e6);
  return buf;
}

std::string per_face(std::int64_t bytes, std::size_t faces) {
  if (bytes < 0 || faces == 0) return "-";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1f", static_cast<double>(bytes) / static_cast<double>(faces));
  return buf;
}

void print_summary() {
  const Input& in = input();
  std::printf("\n== hedge_bench summary: %s (%zu vertices, %zu faces in the soup) ==\n",
              std::filesystem::path(in.path).filename().c_str(), in.soup.n_vertices(), in.soup.n_faces());
  for (bool cpu : {false, true}) {
    std::printf(
        cpu ? "\nthe same, CPU time of the process, all its threads (less sensitive to other load on the machine)\n"
            : "times: minimum over repetitions, wall clock, ms; ratios are peer/hedge (>1: hedge faster)\n");
    std::printf("%-32s %10s %10s %10s %14s %12s\n", "operation", "hedge", "OpenMesh", "CGAL", "OpenMesh/hedge",
                "CGAL/hedge");
    for (const std::string& op : g_ops) {
      if (op == kMemory || op == kMemoryReserved) continue;
      bool any = false;
      for (const char* lib : kLibraries) any |= g_timings.count(op + "/" + lib) > 0;
      if (!any) continue;
      // hedge has one build and one normals function; the peers' variants compare against them.
      std::string hedge_op = op == kBuildReserved ? kBuild : op == kNormalsLoop ? kNormals : op;
      const double h = ms_of(hedge_op + "/hedge", cpu), o = ms_of(op + "/OpenMesh", cpu), c = ms_of(op + "/CGAL", cpu);
      std::printf("%-32s %10s %10s %10s %14s %12s\n", row_title(op).c_str(), cell_ms(hedge_op + "/hedge", cpu).c_str(),
                  cell_ms(op + "/OpenMesh", cpu).c_str(), cell_ms(op + "/CGAL", cpu).c_str(), ratio(o, h).c_str(),
                  ratio(c, h).c_str());
    }
  }

  const LibraryStats &hs = stats("hedge"), &os = stats("OpenMesh"), &cs = stats("CGAL");
  for (const auto& [key, t] : g_timings) {
    if (t.error.empty() && t.cpu_min_ms > 1.2 * t.min_ms)
      std::printf("note: %s ran on more than one thread (CPU time %.1f ms over %.1f ms of wall clock)\n", key.c_str(),
                  t.cpu_min_ms, t.min_ms);
  }

  std::printf(
      "\nheap held by the built mesh (live bytes after build minus before, MB = 10^6 bytes; bytes per face "
      "kept)\n");
  std::printf("%-32s %10s %10s %10s %14s %12s\n", "", "hedge", "OpenMesh", "CGAL", "hedge/OpenMesh", "hedge/CGAL");
  auto mem_row = [&](const char* title, std::int64_t h, std::int64_t o, std::int64_t c, bool per) {
    if (h < 0 && o < 0 && c < 0) return;
    if (per) {
      std::printf("%-32s %10s %10s %10s %14s %12s\n", title, per_face(h, hs.faces).c_str(),
                  per_face(o, os.faces).c_str(), per_face(c, cs.faces).c_str(),
                  ratio(static_cast<double>(h), static_cast<double>(o)).c_str(),
                  ratio(static_cast<double>(h), static_cast<double>(c)).c_str());
    } else {
      std::printf("%-32s %10s %10s %10s %14s %12s\n", title, mb(h).c_str(), mb(o).c_str(), mb(c).c_str(),
                  ratio(static_cast<double>(h), static_cast<double>(o)).c_str(),
                  ratio(static_cast<double>(h), static_cast<double>(c)).c_str());
    }
  };
  mem_row("live after build (MB)", hs.live_bytes, os.live_bytes, cs.live_bytes, false);
  mem_row("  bytes per face", hs.live_bytes, os.live_bytes, cs.live_bytes, true);
  mem_row("  same, mallinfo2 (MB)", hs.malloc_bytes, os.malloc_bytes, cs.malloc_bytes, false);
  mem_row("peak during build (MB)", hs.peak_bytes, os.peak_bytes, cs.peak_bytes, false);
  mem_row("live, peers reserve() (MB)", hs.live_bytes, os.reserved_live_bytes, cs.reserved_live_bytes, false);
  mem_row("  bytes per face", hs.live_bytes, os.reserved_live_bytes, cs.reserved_live_bytes, true);
  if (hs.self_reported >= 0) std::printf("%-32s %10s\n", "hedge Mesh::heap_bytes() (MB)", mb(hs.self_reported).c_str());

  std::printf("\nwhat each library built\n");
  for (const char* lib : kLibraries) {
    const LibraryStats& s = stats(lib);
    if (s.faces == 0 && s.notes.empty()) continue;
    std::printf("  %-9s %zu vertices, %zu faces", lib, s.vertices, s.faces);
    if (s.faces == in.soup.n_faces()) {
      std::printf(" (every face of the soup)");
    } else if (s.faces < in.soup.n_faces()) {
      std::printf(" (%zu soup faces not built)", in.soup.n_faces() - s.faces);
    } else if (s.faces) {
      std::printf(" (%zu faces more than the soup)", s.faces - in.soup.n_faces());
    }
    if (s.circulation_sum) std::printf(", one-ring checksum %llu", static_cast<unsigned long long>(s.circulation_sum));
    std::printf("\n");
    for (const std::string& note : s.notes) std::printf("            %s\n", note.c_str());
  }

  const auto hn = hedge_area_normals_by_soup_vertex(), on = openmesh_area_normals_by_soup_vertex();
  if (!hn.empty() && hn.size() == on.size()) {
    std::size_t same = 0, compared = 0;
    for (std::size_t i = 0; i < hn.size(); ++i) {
      if (hedge::sqrnorm(hn[i]) == 0 || hedge::sqrnorm(on[i]) == 0) continue;
      ++compared;
      same += hedge::dot(hn[i], on[i]) > 0.9999f;
    }
    std::printf(
        "\nnormals cross-check: hedge and the same loop on OpenMesh agree (within 0.8 degrees) on %zu of %zu "
        "vertices both gave a normal\n",
        same, compared);
  }
}

}  // namespace

}  // namespace bench

namespace {

void usage() {
  std::printf(
      "hedge_bench [--meshes DIR] [--mesh FILE] [--reps N] [benchmark flags]\n"
      "  --meshes DIR   directory of the fetched meshes (default build/meshes)\n"
      "  --mesh FILE    the mesh to use; a bare name is looked up in DIR (default dragon.ply)\n"
      "  --reps N       repetitions per benchmark; the table shows their minimum (default 10)\n"
      "  --ops          instead: the table of whole operations (decimate, remesh, subdivide, smooth)\n"
      "                 against OpenMesh and CGAL in this process (ops.cpp)\n"
      "  --hosts        with --ops: also MeshLab (meshlabserver) and Blender (blender -b); slow\n"
      "  --op-reps N    runs per library and operation in the --ops table (default 1)\n"
      "  --op NAME      with --ops: only this operation in the in-process table (decimate, remesh,\n"
      "                 loop, catmull, sqrt3, smooth); repeatable\n"
      "  --scale        instead: the pipeline on the mesh Loop-subdivided to 10M+ triangles, and\n"
      "                 build/decimate cost per triangle from 100k to 14M (--scale-growth: only that)\n"
      "  --files        instead: each file format written and read in memory (fastest of --op-reps),\n"
      "                 the mesh Loop-subdivided once with a uv per corner\n"
      "  --threads N    threads hedge may use (default: all cores); the peers run on one\n");
  benchmark::PrintDefaultHelp();
}

double min_statistic(const std::vector<double>& v) { return bench::min_of(v); }

}  // namespace

int main(int argc, char** argv) {
  std::string dir = "build/meshes", mesh = "dragon.ply";
  int reps = 10, op_reps = 1;
  bool ops = false, hosts = false, files = false;
  std::vector<std::string> only_ops;  // --op NAME, repeatable
  std::string scale;
  std::vector<char*> rest = {argv[0]};
  for (int i = 1; i < argc; ++i) {
    std::string a = argv[i];
    auto value = [&](const std::string& flag, std::string& out) {
      if (a == flag && i + 1 < argc) {
        out = argv[++i];
        return true;
      }
      if (a.rfind(flag + "=", 0) == 0) {
        out = a.substr(flag.size() + 1);
        return true;
      }
      return false;
    };
    std::string reps_text;
    if (value("--meshes", dir) || value("--mesh", mesh)) continue;
    if (value("--reps", reps_text)) {
      reps = std::max(1, std::atoi(reps_text.c_str()));
      continue;
    }
    if (a == "--ops" || a == "--hosts") {
      ops = true;
      hosts |= a == "--hosts";
      continue;
    }
    std::string op_name;
    if (value("--op", op_name)) {
      only_ops.push_back(op_name);
      ops = true;
      continue;
    }
    if (value("--op-reps", reps_text)) {
      op_reps = std::max(1, std::atoi(reps_text.c_str()));
      continue;
    }
    if (value("--threads", reps_text)) {
      hedge::set_thread_count(static_cast<unsigned>(std::max(0, std::atoi(reps_text.c_str()))));
      continue;
    }
    if (a == "--files") {
      files = true;
      continue;
    }
    if (a == "--scale" || a == "--scale-growth") {
      scale = a;
      continue;
    }
    if (a == "--help" || a == "-h") {
      usage();
      return 0;
    }
    rest.push_back(argv[i]);
  }
  int bench_argc = static_cast<int>(rest.size());
  rest.push_back(nullptr);
  benchmark::Initialize(&bench_argc, rest.data(), usage);
  if (benchmark::ReportUnrecognizedArguments(bench_argc, rest.data())) return 2;

  std::string path = mesh;
  if (mesh.find('/') == std::string::npos) path = (std::filesystem::path(dir) / mesh).string();
  if (!scale.empty()) return bench::run_scale(path, scale == "--scale-growth");
  if (files) return bench::run_files(path, op_reps);

  // Operation-major order, so each row's libraries run back to back in the same conditions.
  std::vector<std::vector<bench::Entry>> libraries = {bench::hedge_benchmarks(), bench::openmesh_benchmarks(),
                                                      bench::cgal_benchmarks()};
  const char* const libnames[] = {"hedge", "OpenMesh", "CGAL"};
  for (const char* op : {bench::kBuild, bench::kBuildReserved, bench::kCirculate, bench::kNormals, bench::kNormalsLoop,
                         bench::kMemory, bench::kMemoryReserved}) {
    bench::g_ops.push_back(op);
    for (std::size_t l = 0; l < libraries.size(); ++l) {
      for (const bench::Entry& e : libraries[l]) {
        if (e.op != op) continue;
        auto* b = benchmark::RegisterBenchmark((e.op + "/" + libnames[l]).c_str(), e.run);
        b->Unit(benchmark::kMillisecond)->UseRealTime()->MeasureProcessCPUTime()->Iterations(1);
        if (e.op != bench::kMemory && e.op != bench::kMemoryReserved) {
          b->Repetitions(reps)->ComputeStatistics("min", min_statistic)->DisplayAggregatesOnly(true);
        }
      }
    }
  }

  try {
    const auto t0 = std::chrono::steady_clock::now();
    bench::load_input(path);
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::printf("input %s: %zu vertices, %zu faces, %zu edges (read in %.2f s, not timed)\n", path.c_str(),
                bench::input().soup.n_vertices(), bench::input().soup.n_faces(), bench::input().unique_edges, s);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "hedge_bench: cannot read %s: %s\n", path.c_str(), e.what());
    return 1;
  }
  std::fflush(stdout);
  if (ops) return bench::run_operation_table(op_reps, hosts, only_ops);

  bench::CollectingReporter reporter(benchmark::CreateDefaultDisplayReporter());
  benchmark::RunSpecifiedBenchmarks(&reporter);
  bench::print_summary();
  benchmark::Shutdown();
  return 0;
}
