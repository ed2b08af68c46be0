// hedge_bench --scale: the whole pipeline on a mesh of more than 10 million triangles (the
// real dragon, Loop-subdivided twice by hedge), with each step's wall and CPU time, time per
// triangle and peak memory, and build and decimation cost per triangle from 100k to 14M
// triangles to show that they grow linearly.
#include <malloc.h>
#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <functional>
#include <string>
#include <vector>

#include "hedge/build.h"
#include "hedge/decimate.h"
#include "hedge/error.h"
#include "hedge/io.h"
#include "hedge/remesh.h"
#include "hedge/subdivide.h"
#include "hedge/threads.h"

namespace bench {
namespace {

//! VmRSS or VmHWM of this process in bytes (0 when /proc is missing).
std::size_t proc_status_bytes(const char* field) {
  std::ifstream in("/proc/self/status");
  std::string line;
  const std::string key = std::string(field) + ":";
  while (std::getline(in, line))
    if (line.rfind(key, 0) == 0) return std::stoull(line.substr(key.size())) * 1024;
  return 0;
}

//! Resets the peak RSS to the current RSS (Linux 4.0+: clear_refs 5), so that each step's
//! peak is its own. Returns false where that is not possible; peaks are then cumulative.
bool reset_peak() {
  malloc_trim(0);  // give freed memory back first, so the baseline is what is really in use
  std::ofstream out("/proc/self/clear_refs");
  out << "5";
  out.flush();
  return out.good();
}

double cpu_seconds() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return double(u.ru_utime.tv_sec + u.ru_stime.tv_sec) + 1e-6 * double(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

struct Measure {
  double wall = 0, cpu = 0;              // seconds
  std::size_t rss_before = 0, peak = 0;  // bytes
  bool peak_reset = false;
};

//! `step`'s times and, with `peak`, the memory it held (which trims the heap first).
Measure measure(const std::function<void()>& step, bool peak = true) {
  Measure m;
  if (peak) {
    m.peak_reset = reset_peak();
    m.rss_before = proc_status_bytes("VmRSS");
  }
  const double cpu0 = cpu_seconds();
  const auto t0 = std::chrono::steady_clock::now();
  step();
  m.wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  m.cpu = cpu_seconds() - cpu0;
  if (peak) m.peak = proc_status_bytes("VmHWM");
  return m;
}

double mib(std::size_t bytes) { return double(bytes) / (1024.0 * 1024.0); }

void print_step(const char* name, std::size_t triangles, const Measure& m, const std::string& note = {}) {
  std::printf("%-28s %11zu %9.2f %9.2f %10.1f %10.0f %10.0f %s\n", name, triangles, m.wall, m.cpu,
              1e9 * m.wall / double(std::max<std::size_t>(triangles, 1)), mib(m.rss_before), mib(m.peak), note.c_str());
  std::fflush(stdout);
}

void print_header() {
  std::printf("%-28s %11s %9s %9s %10s %10s %10s\n", "step", "triangles", "wall s", "CPU s", "ns/tri", "RSS MiB",
              "peak MiB");
}

hedge::Mesh subdivided_dragon(const hedge::Soup& dragon, int iterations) {
  hedge::Mesh mesh = hedge::build(dragon).mesh;
  if (iterations > 0) {
    hedge::SubdivideOptions o;
    o.scheme = hedge::SubdivisionScheme::loop;
    o.iterations = iterations;
    hedge::subdivide(mesh, o);
  }
  return mesh;
}

//! Fastest of `reps` runs of build() (wall and CPU seconds).
std::pair<double, double> time_build(const hedge::Soup& soup, int reps) {
  double wall = 1e30, cpu = 1e30;
  for (int r = 0; r < reps; ++r) {
    Measure m = measure([&] { hedge::build(soup); }, false);
    wall = std::min(wall, m.wall);
    cpu = std::min(cpu, m.cpu);
  }
  return {wall, cpu};
}

// Decimations of one soup to 1 %: the first, whose memory the process has not held at that
// size before, and the fastest of the others (wall and CPU each).
struct DecimateTimes {
  Measure first;
  double wall = 1e30, cpu = 1e30;
};
DecimateTimes time_decimate(const hedge::Soup& soup, int reps) {
  DecimateTimes times;
  for (int r = 0; r < reps; ++r) {
    hedge::Mesh mesh = hedge::build(soup).mesh;
    hedge::DecimateOptions o;
    o.target_ratio = 0.01;
    const Measure m = measure([&] { hedge::decimate(mesh, o); }, false);
    if (r == 0) {
      times.first = m;
      continue;
    }
    times.wall = std::min(times.wall, m.wall);
    times.cpu = std::min(times.cpu, m.cpu);
  }
  return times;
}

}  // namespace

int run_scale(const std::string& dragon_path, bool growth_only) {
  std::printf("scale run: %s, %u threads (hedge::thread_count(): --threads, or all cores)\n", dragon_path.c_str(),
              hedge::thread_count());
  const hedge::Soup dragon = hedge::read_mesh(dragon_path);
  std::printf("input: %zu vertices, %zu faces\n\n", dragon.n_vertices(), dragon.n_faces());

  if (!growth_only) {
    // ---- the pipeline at 10M+ triangles ----
    print_header();
    hedge::Soup big;
    {
      hedge::Mesh mesh;
      Measure m = measure([&] { mesh = subdivided_dragon(dragon, 2); });
      print_step("make: build + 2x Loop", mesh.n_faces(), m, "(from the dragon; per output triangle)");
      m = measure([&] { big = hedge::extract(mesh); });
      print_step("  extract to a soup", mesh.n_faces(), m);
    }
    const std::size_t n = big.n_faces();
    std::printf("the soup: %zu vertices, %zu triangles, %.0f MiB\n", big.n_vertices(), n,
                mib(big.positions.capacity() * sizeof(hedge::Point) + big.corners.capacity() * 4 +
                    big.face_sizes.capacity() * 4));
    {
      hedge::Mesh mesh;
      Measure m = measure([&] { mesh = hedge::build(big).mesh; });
      char note[160];
      std::snprintf(note, sizeof note, "mesh: %.1f bytes/triangle (%.0f MiB heap)",
                    double(mesh.heap_bytes()) / double(mesh.n_faces()), mib(mesh.heap_bytes()));
      print_step("build", n, m, note);
      hedge::Soup out;
      m = measure([&] { out = hedge::extract(mesh); });
      print_step("extract", n, m);
      out = {};
      hedge::DecimateOptions d;
      d.target_ratio = 0.01;
      std::size_t after = 0;
      m = measure([&] {
        hedge::decimate(mesh, d);
        after = mesh.n_faces();
      });
      print_step("decimate to 1 %", n, m, "-> " + std::to_string(after) + " triangles");
      m = measure([&] { out = hedge::extract(mesh); });
      print_step("  extract the result", after, m);
    }
    {
      hedge::Mesh mesh = hedge::build(big).mesh;
      hedge::RemeshOptions r;  // defaults: the mean edge length, 5 iterations
      hedge::RemeshReport report;
      Measure m = measure([&] { report = hedge::remesh(mesh, r); });
      char note[160];
      std::snprintf(note, sizeof note, "-> %zu triangles, target edge %.3g", mesh.n_faces(), report.target_edge_length);
      print_step("remesh (defaults)", n, m, note);
      hedge::Soup out;
      m = measure([&] { out = hedge::extract(mesh); });
      print_step("  extract the result", mesh.n_faces(), m);
    }
    std::printf("\n");
  }

  // ---- growth: build and decimation cost per triangle ----
  // glibc serves blocks above 32 MiB from fresh mappings it returns on free, smaller ones
  // from a heap it keeps: left so, a small mesh's repetitions would reuse their memory and a
  // big one's would fault in fresh pages every time. Every block from a heap that is never
  // trimmed treats all sizes alike: the first decimation at a size takes fresh pages, the
  // others reuse them. (This section comes last: the setting stays for the process.)
  mallopt(M_MMAP_MAX, 0);
  mallopt(M_TRIM_THRESHOLD, -1);
  std::printf(
      "growth (build: fastest of the repetitions; decimation to 1 %%: the first, in fresh memory, and\n"
      "the fastest of the others, in memory the process reuses):\n");
  std::printf("%-26s %11s %12s %13s %13s %13s\n", "mesh", "triangles", "build ns/tri", "first ns/tri", "reused ns/tri",
              "reused CPU");
  struct Size {
    const char* name;
    int loops;
    std::size_t decimate_to;
    int reps;
  };
  const Size sizes[] = {{"dragon decimated to 100k", 0, 100000, 5},
                        {"dragon", 0, 0, 3},
                        {"dragon, 1x Loop", 1, 0, 2},
                        {"dragon, 2x Loop", 2, 0, 2}};
  for (const Size& s : sizes) {
    hedge::Soup soup;
    {
      hedge::Mesh mesh = subdivided_dragon(dragon, s.loops);
      if (s.decimate_to) {
        hedge::DecimateOptions o;
        o.target_faces = s.decimate_to;
        hedge::decimate(mesh, o);
      }
      soup = hedge::extract(mesh);
    }
    const double n = double(soup.n_faces());
    const auto [bw, bc] = time_build(soup, s.reps + 2);
    malloc_trim(0);  // the first decimation in fresh memory
    const DecimateTimes d = time_decimate(soup, s.reps + 1);
    std::printf("%-26s %11zu %12.1f %13.0f %13.0f %13.0f   (build CPU %.1f ns/tri; first: CPU %.0f ns/tri)\n", s.name,
                soup.n_faces(), 1e9 * bw / n, 1e9 * d.first.wall / n, 1e9 * d.wall / n, 1e9 * d.cpu / n, 1e9 * bc / n,
                1e9 * d.first.cpu / n);
    std::fflush(stdout);
  }
  return 0;
}

}  // namespace bench
