// detail::sort_spatially: the mesh renumbered along a Morton order (spatial_order.h).
#include "spatial_order.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <mutex>
#include <vector>

#include "parallel.h"

namespace hedge::detail {

namespace {
// Each 10-bit number with its bits spread to every third bit: one load instead of ten
// shifts and masks, in the loops over every vertex.
constexpr std::array<std::uint32_t, 1024> kSpreadBits = [] {
  std::array<std::uint32_t, 1024> table{};
  for (std::uint32_t x = 0; x < table.size(); ++x)
    for (int bit = 0; bit < 10; ++bit) table[x] |= ((x >> bit) & 1u) << (3 * bit);
  return table;
}();

// Sorts (code << 32 | index) pairs by their codes of 3 * kBits bits, stably: a radix sort,
// kBits a pass, over the pairs themselves (no lookups of the codes through the indices).
void sort_by_code(std::vector<std::uint64_t>& items) {
  constexpr int kBits = 10;
  std::vector<std::uint64_t> scratch(items.size());
  std::vector<std::size_t> start((std::size_t(1) << kBits) + 1);
  for (int pass = 0; pass < 3; ++pass) {
    const int shift = 32 + pass * kBits;
    auto digit = [&](std::uint64_t x) { return std::size_t(x >> shift) & ((std::size_t(1) << kBits) - 1); };
    std::fill(start.begin(), start.end(), 0);
    for (std::uint64_t x : items) ++start[digit(x) + 1];
    for (std::size_t b = 1; b < start.size(); ++b) start[b] += start[b - 1];
    for (std::uint64_t x : items) scratch[start[digit(x)]++] = x;
    items.swap(scratch);
  }
}

// The items 0..n-1 that are live, ordered by bucket (below `buckets`), stably: a counting sort.
template <class IsLive, class Bucket>
std::vector<Index> order_by_bucket(std::size_t n, std::size_t live, std::size_t buckets, IsLive is_live,
                                   Bucket bucket) {
  std::vector<Index> key(n), start(buckets + 1, 0), out(live);
  for (std::size_t i = 0; i < n; ++i)
    if (is_live(Index(i))) ++start[(key[i] = bucket(Index(i))) + 1];
  for (std::size_t b = 1; b < start.size(); ++b) start[b] += start[b - 1];
  for (std::size_t i = 0; i < n; ++i)
    if (is_live(Index(i))) out[start[key[i]]++] = Index(i);
  return out;
}
// morton_cell(), inline in the loops over every vertex: called out of line, the loop read
// what its lambda captures again after each call, from the calling thread's stack, and two
// threads took longer than one.
[[gnu::always_inline]] inline std::uint32_t cell_code(const Vec3f& p, double offset, int bits) {
  const int last = (1 << bits) - 1;
  const double cells = double(1 << bits);
  std::uint32_t code = 0;
  for (int axis = 0; axis < 3; ++axis) {
    double x = double(p[axis]) + 0.5 + offset;
    if (!(std::abs(x) < 1e9)) x = 0;         // not finite, or far out of the frame: any cell serves
    x -= double(static_cast<long long>(x));  // wrapped into [0, 1) (towards zero, then up)
    if (x < 0) x += 1;
    code |= kSpreadBits[std::size_t(std::clamp(int(x * cells), 0, last))] << axis;
  }
  return code;
}

}  // namespace

std::uint32_t morton_cell(const Vec3f& p, double offset, int bits) { return cell_code(p, offset, bits); }

Frame normalized_frame(const Mesh& m, unsigned threads) {
  // The box in floats, each thread over a range of vertices, then joined: min and max are
  // exact, so the box is the same whatever the split (zeros made +0, the one difference).
  constexpr float inf = std::numeric_limits<float>::infinity();
  Vec3f lo{{inf, inf, inf}}, hi{{-inf, -inf, -inf}};
  std::mutex joining;
  parallel_for(m.vertices_size(), threads, [&](std::size_t begin, std::size_t end) {
    Vec3f part_lo{{inf, inf, inf}}, part_hi{{-inf, -inf, -inf}};
    for (std::size_t i = begin; i < end; ++i) {
      const Vertex v(static_cast<Index>(i));
      if (m.is_deleted(v)) continue;
      const Vec3f& p = m.position(v);
      for (int k = 0; k < 3; ++k) part_lo[k] = std::min(part_lo[k], p[k]), part_hi[k] = std::max(part_hi[k], p[k]);
    }
    const std::lock_guard lock(joining);
    for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], part_lo[k]), hi[k] = std::max(hi[k], part_hi[k]);
  });
  for (int k = 0; k < 3; ++k) lo[k] += 0.0f, hi[k] += 0.0f;
  const Vec3d lo_d = to_double(lo), hi_d = to_double(hi);
  Frame frame{(lo_d + hi_d) * 0.5, distance(lo_d, hi_d)};
  if (!(frame.scale > 0) || !std::isfinite(frame.scale)) frame.scale = 1;
  return frame;
}

GarbageMaps sort_spatially(Mesh& m, unsigned threads) {
  // 1. The live vertices along the Morton order of their cells (10 bits per axis) in the
  // normalized frame; the codes on all threads.
  const Frame frame = normalized_frame(m, threads);
  constexpr int kBits = 10;
  std::vector<std::uint64_t> coded(m.vertices_size());
  parallel_for(m.vertices_size(), threads, [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
      const Vertex v(static_cast<Index>(i));
      const std::uint64_t code =
          m.is_deleted(v) ? 0 : cell_code(to_float((to_double(m.position(v)) - frame.center) / frame.scale), 0, kBits);
      coded[i] = code << 32 | i;
    }
  });
  std::erase_if(coded, [&](std::uint64_t x) { return m.is_deleted(Vertex(Index(x))); });
  sort_by_code(coded);
  std::vector<Index> vertices(coded.size()), place(m.vertices_size(), kInvalidIndex);
  for (std::size_t i = 0; i < coded.size(); ++i) {
    vertices[i] = Index(coded[i]);
    place[vertices[i]] = Index(i);
  }
  coded = {};

  // 2. Faces and edges by the first of their vertices in that order: a face's neighbours
  // share its vertices, so they land next to it.
  const std::size_t n_places = vertices.size();
  const std::vector<Index> faces = order_by_bucket(
      m.faces_size(), m.n_faces(), n_places, [&](Index i) { return !m.is_deleted(Face(i)); },
      [&](Index i) {
        Index first = kInvalidIndex;
        for (Vertex v : m.vertices(Face(i))) first = std::min(first, place[v.idx()]);
        return first;
      });
  const std::vector<Index> edges = order_by_bucket(
      m.edges_size(), m.n_edges(), n_places, [&](Index i) { return !m.is_deleted(Edge(i)); },
      [&](Index i) { return std::min(place[m.vertex(Edge(i), 0).idx()], place[m.vertex(Edge(i), 1).idx()]); });
  return m.reorder(vertices, edges, faces);
}

RegionPartitions::RegionPartitions(const Mesh& m, const Vec3d& center, double inv_scale, std::size_t regions,
                                   unsigned threads)
    : regions_(std::clamp<std::size_t>(regions, 1, kNone - 1)) {
  const std::size_t n = m.vertices_size();
  if (n == 0) return;
  const std::vector<Point>& positions = m.positions();
  // Cells: 64 per axis up to 2 million vertices, 128 above.
  const int bits = n <= (std::size_t(1) << 21) ? 6 : 7;
  const std::size_t n_cells = std::size_t(1) << (3 * bits);
  std::vector<std::uint32_t, UnsetAllocator<std::uint32_t>> cell(n);  // written whole on all threads
  std::vector<std::size_t> cell_start(n_cells + 1);
  std::vector<std::uint16_t> region_of_cell(n_cells);
  for (int grid = 0; grid < 2; ++grid) {
    const double offset = grid / 3.0;
    parallel_for(n, threads, [&](std::size_t begin, std::size_t end) {
      for (std::size_t i = begin; i < end; ++i)
        cell[i] = cell_code(to_float((to_double(positions[i]) - center) * inv_scale), offset, bits);
    });
    std::fill(cell_start.begin(), cell_start.end(), 0);
    for (std::size_t i = 0; i < n; ++i) ++cell_start[cell[i] + 1];
    for (std::size_t c = 0; c < n_cells; ++c) cell_start[c + 1] += cell_start[c];
    for (int shifted = 0; shifted < 2; ++shifted) {
      const std::size_t shift = shifted ? n / (2 * regions_) : 0;
      // Only the cells that hold vertices need a region (few do: the vertices lie on a
      // surface). The quotient is exact in double precision: its numerator is below 2^53.
      for (std::size_t c = 0; c < n_cells; ++c) {
        if (cell_start[c] == cell_start[c + 1]) continue;
        std::size_t r = std::size_t(double((cell_start[c] + shift) * regions_) / double(n));
        region_of_cell[c] = std::uint16_t(r >= regions_ ? r - regions_ : r);
      }
      auto& map = maps_[2 * grid + shifted];
      map.resize(n);
      parallel_for(n, threads, [&](std::size_t begin, std::size_t end) {
        for (std::size_t i = begin; i < end; ++i) map[i] = region_of_cell[cell[i]];
      });
    }
  }
}

}  // namespace hedge::detail
