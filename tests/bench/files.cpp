// hedge_bench --files: reading and writing each file format, in memory (no disk), on the
// mesh Loop-subdivided once with a texture coordinate per corner, as a textured scan
// exported from a host would come.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <numbers>
#include <string>

#include "bench.h"
#include "hedge/build.h"
#include "hedge/io.h"
#include "hedge/subdivide.h"
#include "hedge/threads.h"

namespace bench {
namespace {

//! The fastest of `reps` runs, in seconds.
double fastest(int reps, const std::function<void()>& run) {
  double best = 1e30;
  for (int r = 0; r < reps; ++r) {
    const auto start = std::chrono::steady_clock::now();
    run();
    best = std::min(best, std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  }
  return best;
}

//! A texture coordinate per corner: the angle around the mesh's vertical axis and the height,
//! each triangle taking its first corner's side of the cut where the angle wraps (a seam).
void add_cylinder_uv(hedge::Soup& soup) {
  hedge::Vec3d centre{};
  for (const hedge::Point& p : soup.positions)
    for (int k = 0; k < 3; ++k) centre[k] += p[k] / double(soup.n_vertices());
  float low = 1e30f, high = -1e30f;
  for (const hedge::Point& p : soup.positions) low = std::min(low, p[1]), high = std::max(high, p[1]);
  hedge::Channel& uv = soup.add_channel("uv", hedge::Domain::corner, hedge::ScalarType::f32, 2);
  float* out = uv.as<float>();
  const std::vector<std::size_t> offsets = soup.face_offsets();
  for (std::size_t f = 0; f < soup.n_faces(); ++f) {
    float first = 0;
    for (std::size_t c = offsets[f]; c < offsets[f + 1]; ++c) {
      const hedge::Point& p = soup.positions[soup.corners[c]];
      float u = float(std::atan2(p[2] - centre[2], p[0] - centre[0]) / (2 * std::numbers::pi) + 0.5);
      if (c == offsets[f]) first = u;
      if (u - first > 0.5f) u -= 1;
      if (first - u > 0.5f) u += 1;
      out[2 * c] = u;
      out[2 * c + 1] = (p[1] - low) / (high - low);
    }
  }
}

}  // namespace

int run_files(const std::string& path, int reps) {
  hedge::Soup soup;
  {
    hedge::BuildResult built = hedge::build(hedge::read_mesh(path));
    hedge::subdivide(built.mesh, hedge::SubdivideOptions{});
    soup = hedge::extract(built.mesh);
  }
  add_cylinder_uv(soup);
  std::printf(
      "== hedge_bench --files: %s Loop-subdivided once (%zu vertices, %zu triangles, a uv per corner), "
      "%u threads, fastest of %d ==\n",
      path.c_str(), soup.n_vertices(), soup.n_faces(), hedge::resolve_thread_count(0), reps);
  std::printf("| format | size | write s | read s |\n|---|---:|---:|---:|\n");
  struct Format {
    const char* name;
    std::function<std::string(const hedge::Soup&)> write;
    std::function<hedge::Soup(std::string_view)> read;
  };
  const Format formats[] = {
      {"OBJ", [](const hedge::Soup& s) { return hedge::write_obj(s); },
       [](std::string_view b) { return hedge::read_obj(b, "bench.obj"); }},
      {"PLY, text", [](const hedge::Soup& s) { return hedge::write_ply(s, false); },
       [](std::string_view b) { return hedge::read_ply(b, "bench.ply"); }},
      {"PLY, binary", [](const hedge::Soup& s) { return hedge::write_ply(s, true); },
       [](std::string_view b) { return hedge::read_ply(b, "bench.ply"); }},
      {"OFF (no uv)", [](const hedge::Soup& s) { return hedge::write_off(s); },
       [](std::string_view b) { return hedge::read_off(b, "bench.off"); }},
      {"STL, text (no uv)", [](const hedge::Soup& s) { return hedge::write_stl(s, false); },
       [](std::string_view b) { return hedge::read_stl(b, "bench.stl"); }},
      {"STL, binary (no uv)", [](const hedge::Soup& s) { return hedge::write_stl(s, true); },
       [](std::string_view b) { return hedge::read_stl(b, "bench.stl"); }},
  };
  for (const Format& f : formats) {
    std::string bytes;
    const double write = fastest(reps, [&] { bytes = f.write(soup); });
    hedge::Soup back;
    const double read = fastest(reps, [&] { back = f.read(bytes); });
    std::printf("| %s | %.0f MB | %.3f | %.3f |\n", f.name, double(bytes.size()) / 1e6, write, read);
  }
  return 0;
}

}  // namespace bench
