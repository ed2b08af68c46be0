// build(): any soup -> a manifold half-edge mesh (splitting, orienting, recording where
// everything came from); extract(): mesh -> soup, undoing build()'s repairs.
//
// build() is a list of passes over one plain state (Build): classify the faces, then either
// the fast path (every decision local to a vertex's corners) or the general one (matching,
// orienting, gluing, cutting), both ending in the same wiring of faces and splitting of fans,
// then the attributes, provenance and report.
#include "hedge/build.h"

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <mutex>
#include <new>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "hedge/detail/memory.h"
#include "hedge/error.h"
#include "hedge/limits.h"
#include "hedge/provenance.h"
#include "hedge/threads.h"
#include "parallel.h"
#include "text.h"
#include "weld.h"

namespace hedge {
namespace {

constexpr std::uint32_t kInv = kInvalidIndex;
// Corner-edge ids carry their direction in the top bit inside the matching buckets, so
// a soup may hold at most 2^31 - 1 corners (far beyond what fits in memory anyway).
constexpr std::uint32_t kDirBit = 0x80000000u;

constexpr std::uint8_t kFaceOk = 0, kFaceRepeats = 1, kFaceSkipped = 2;

// parallel_for's grain for build(): below 2^16 elements a second thread costs more than it
// saves.
constexpr std::size_t kGrain = std::size_t(1) << 15;

// Runs fn(begin, end, part) over [0, n) through parallel_for, each range with a Part of its
// own, and returns the parts in the order of their ranges: per-range results (lists, counts)
// then combine the same way however the work was split.
template <class Part, class Fn>
std::vector<Part> parallel_parts(std::size_t n, unsigned threads, Fn&& fn) {
  std::mutex mutex;
  std::vector<std::pair<std::size_t, Part>> parts;
  parallel_for(
      n, threads,
      [&](std::size_t begin, std::size_t end) {
        Part part{};
        fn(begin, end, part);
        const std::lock_guard lock(mutex);
        parts.emplace_back(begin, std::move(part));
      },
      kGrain);
  std::sort(parts.begin(), parts.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  std::vector<Part> out;
  out.reserve(parts.size());
  for (auto& part : parts) out.push_back(std::move(part.second));
  return out;
}

// As above over items [0, n) of unequal cost, split where equal cost lies: offsets[i] is the
// cost before item i (ascending), offsets[n] the total; fn gets ranges of items.
template <class Part, class Fn>
std::vector<Part> parallel_parts(const std::vector<std::uint32_t>& offsets, unsigned threads, Fn&& fn) {
  const std::size_t n = offsets.size() - 1, total = offsets[n];
  auto item = [&](std::size_t cost) {  // the first item whose cost starts at or after `cost`
    return cost >= total ? n
                         : static_cast<std::size_t>(std::lower_bound(offsets.begin(), offsets.begin() + n, cost) -
                                                    offsets.begin());
  };
  return parallel_parts<Part>(total, threads, [&](std::size_t begin, std::size_t end, Part& part) {
    fn(begin == 0 ? 0 : item(begin), item(end), part);
  });
}

struct FreeScratch {
  void operator()(void* p) const { detail::free_array(p); }
};

//! An uninitialised array of n trivial T, for the big temporary arrays (written once, every
//! element before it is read); on huge pages where Linux offers them (detail/memory.h).
template <class T>
class Scratch {
  static_assert(std::is_trivially_copyable_v<T> && std::is_trivially_destructible_v<T>);

 public:
  Scratch() = default;
  explicit Scratch(std::size_t n) : memory_(detail::allocate_array(n * sizeof(T), alignof(T))), bytes_(n * sizeof(T)) {
    data_ = new (memory_.get()) T[n];
  }
  T& operator[](std::size_t i) { return data_[i]; }
  const T& operator[](std::size_t i) const { return data_[i]; }
  T* get() { return data_; }
  const T* get() const { return data_; }
  void reset() {
    memory_.reset();
    bytes_ = 0;
    data_ = nullptr;
  }

  //! Ends this array and reuses its memory for n U, saving the page faults of a new block.
  template <class U>
  Scratch<U> reuse_as(std::size_t n) && {
    if (n * sizeof(U) > bytes_) return Scratch<U>(n);
    Scratch<U> out;
    out.memory_ = std::move(memory_);
    out.bytes_ = bytes_;
    out.data_ = new (out.memory_.get()) U[n];
    data_ = nullptr;
    return out;
  }

 private:
  template <class>
  friend class Scratch;
  std::unique_ptr<void, FreeScratch> memory_;
  std::size_t bytes_ = 0;
  T* data_ = nullptr;
};

// Number of distinct values among v[0..n); small faces without allocating.
std::uint32_t distinct_count(const std::uint32_t* v, std::uint32_t n, std::vector<std::uint32_t>& buffer) {
  if (n == 3) return v[0] == v[1] ? (v[1] == v[2] ? 1 : 2) : (v[0] == v[2] || v[1] == v[2] ? 2 : 3);
  if (n <= 16) {
    std::uint32_t count = 0;
    for (std::uint32_t i = 0; i < n; ++i) {
      bool seen = false;
      for (std::uint32_t j = 0; j < i && !seen; ++j) seen = v[j] == v[i];
      count += !seen;
    }
    return count;
  }
  buffer.assign(v, v + n);
  std::sort(buffer.begin(), buffer.end());
  return static_cast<std::uint32_t>(std::unique(buffer.begin(), buffer.end()) - buffer.begin());
}

// One directed corner-edge in the bucket of its smaller end vertex: `other` is the larger
// end; `edge` the corner-edge id (the corner it points to) with kDirBit set when it runs
// from the smaller vertex to the larger.
struct BucketEntry {
  std::uint32_t other;
  std::uint32_t edge;
};

struct ComplexGroup {         // 3+ corner-edges on one vertex pair: a non-manifold edge
  std::uint32_t first, size;  // range in the bucket entries
};

using detail::plural;

// A corner in the list of its vertex, with the vertices before and after it in its face:
// the far ends of the edges entering and leaving it.
struct VertexCorner {
  std::uint32_t corner, prev, next;
};

// Links the k corners around vertex v: succ[i] = j when the edge leaving corner i is the
// edge entering corner j, so their faces glue there (kInv: a boundary edge). An edge with
// three or more faces (a non-manifold edge, counted in `non_manifold` at its smaller end)
// glues its first face of each direction, in face order, as the general path does; both
// ends of the edge see the same faces in the same order, so they agree without talking.
// Returns false when an edge has exactly two faces running the same way: gluing them needs
// a flip, which is the general path's job.
bool link_corners(const VertexCorner* e, std::uint32_t k, std::uint32_t v, std::uint32_t* succ,
                  std::size_t& non_manifold, std::vector<std::pair<std::uint32_t, std::uint32_t>>& by_next,
                  std::vector<std::pair<std::uint32_t, std::uint32_t>>& by_prev) {
  if (k <= 32) {
    // Branch-free and in registers: which pairs match is unpredictable.
    bool twice = false;
    for (std::uint32_t i = 1; i < k; ++i) {
      const std::uint32_t next = e[i].next, prev = e[i].prev;
      for (std::uint32_t j = 0; j < i; ++j) twice |= (e[j].next == next) | (e[j].prev == prev);
    }
    if (!twice) {
      for (std::uint32_t i = 0; i < k; ++i) {
        const std::uint32_t next = e[i].next;
        std::uint32_t s = kInv;
        for (std::uint32_t j = 0; j < k; ++j) s = e[j].prev == next ? j : s;
        succ[i] = s;
      }
      return true;
    }
  }
  // Some neighbour is reached by two edges (or a hub vertex): group the edges by neighbour.
  // Sorting (neighbour, corner) puts each group in face order, since the list is.
  by_next.clear();
  by_prev.clear();
  for (std::uint32_t i = 0; i < k; ++i) {
    by_next.emplace_back(e[i].next, i);
    by_prev.emplace_back(e[i].prev, i);
    succ[i] = kInv;
  }
  std::sort(by_next.begin(), by_next.end());
  std::sort(by_prev.begin(), by_prev.end());
  std::uint32_t a = 0, b = 0;
  while (a < k || b < k) {
    const std::uint32_t w = std::min(a < k ? by_next[a].first : kInv, b < k ? by_prev[b].first : kInv);
    std::uint32_t a_end = a, b_end = b;
    while (a_end < k && by_next[a_end].first == w) ++a_end;
    while (b_end < k && by_prev[b_end].first == w) ++b_end;
    const std::uint32_t out = a_end - a, in = b_end - b;
    if (out + in == 2 && (out == 2 || in == 2)) return false;
    if (out && in) succ[by_next[a].second] = by_prev[b].second;
    if (out + in >= 3 && w > v) ++non_manifold;
    a = a_end;
    b = b_end;
  }
  return true;
}

// True when the linked corners form one fan; then `first` is the corner whose entering
// edge is on the boundary (any corner of a closed fan) and `last` the one whose leaving
// edge is (kInv for a closed fan). One fan has k or k - 1 links; with k - 1 the one corner
// that no link enters is the xor of all corners and all link targets.
bool one_fan(const std::uint32_t* succ, std::uint32_t k, std::uint32_t& first, std::uint32_t& last) {
  std::uint32_t links = 0, unentered = 0;
  for (std::uint32_t i = 0; i < k; ++i) {
    const bool linked = succ[i] != kInv;
    links += linked;
    unentered ^= linked ? i ^ succ[i] : i;
  }
  if (links + 1 < k) return false;
  const bool closed = links == k;
  const std::uint32_t start = closed ? 0 : unentered;
  std::uint32_t count = 0, i = start, end = start;
  do {
    end = i;
    i = succ[i];
  } while (++count <= k && i != kInv && i != start);
  if (count != k) return false;
  first = start;
  last = closed ? kInv : end;
  return true;
}

// A fan that became its own vertex: its boundary halves leaving and entering it (`in`
// invalid for a closed fan).
struct Fan {
  std::uint32_t vertex;
  Halfedge out, in;
};

// One range of faces as classify_faces() counted it; build_local() fills its corner lists
// in the same ranges, each into its own part of every vertex's list.
struct FaceRange {
  std::size_t fbegin = 0, fend = 0;
  std::vector<std::uint32_t> skipped;
  std::size_t repeats = 0;
  std::vector<std::uint32_t> corners_at;  // per vertex: corners in this range's built faces
};

// The state every pass reads and writes.
struct Build {
  Build(const Soup& s, const BuildOptions& o)
      : soup(s), options(o), nv(s.n_vertices()), nf(s.n_faces()), nc(s.n_corners()), corner(s.corners.data()) {}

  const Soup& soup;
  const BuildOptions& options;
  const std::size_t nv, nf, nc;
  const std::uint32_t* corner;
  BuildResult result;

  std::vector<std::uint32_t> soff;   // soup face -> first corner
  std::vector<std::uint8_t> status;  // kFaceOk, kFaceRepeats or kFaceSkipped
  std::vector<FaceRange> face_ranges;
  bool has_repeats = false, has_skipped = false;

  // Mesh corners: the soup's corners minus skipped faces, flipped faces as c0, cn-1, ..., c1.
  bool identity = true;                       // mesh corners are the soup's; the arrays below stay empty
  std::vector<std::uint32_t> moff_storage;    // mesh face -> first mesh corner
  std::vector<std::uint32_t> msrc;            // mesh corner -> soup corner
  std::vector<std::uint32_t> face_source;     // mesh face -> soup face
  std::vector<std::uint8_t> flipped;          // per soup face; empty when nothing flipped
  Scratch<std::uint32_t> halfedge_of_corner;  // mesh corner -> half-edge pointing to it
  std::vector<std::uint32_t> copy_source;     // mesh vertex nv + i copies soup vertex copy_source[i]
  std::size_t n_repeat_cuts = 0, n_glued_by_flip = 0;

  const std::vector<std::uint32_t>& moff() const { return identity ? soff : moff_storage; }
  std::size_t n_mesh_faces() const { return nf - result.report.skipped_faces; }
};

// ---- classification -------------------------------------------------------------------------

// Offsets, the faces that repeat a vertex or are too degenerate to build, and the corners of
// each vertex in built faces, per range of faces so that the fast path can fill its corner
// lists in parallel. At most two ranges: each keeps a count for every vertex.
void classify_faces(Build& b) {
  b.soff.resize(b.nf + 1);
  std::uint32_t offset = 0;
  for (std::size_t f = 0; f < b.nf; ++f) {
    b.soff[f] = offset;
    offset += b.soup.face_sizes[f];
  }
  b.soff[b.nf] = offset;
  b.status.assign(b.nf, kFaceOk);
  b.face_ranges = parallel_parts<FaceRange>(
      b.soff, std::min(thread_count(), 2u), [&](std::size_t fbegin, std::size_t fend, FaceRange& range) {
        range.fbegin = fbegin;
        range.fend = fend;
        range.corners_at.assign(b.nv, 0);
        std::vector<std::uint32_t> buffer;
        for (std::size_t f = fbegin; f < fend; ++f) {
          const std::uint32_t size = b.soup.face_sizes[f], first = b.soff[f];
          const std::uint32_t distinct = distinct_count(b.corner + first, size, buffer);
          if (distinct < 3) {
            b.status[f] = kFaceSkipped;
            range.skipped.push_back(static_cast<std::uint32_t>(f));
            continue;
          }
          if (distinct < size) {
            b.status[f] = kFaceRepeats;
            ++range.repeats;
          }
          for (std::uint32_t c = first; c < first + size; ++c) ++range.corners_at[b.corner[c]];
        }
      });
  BuildReport& report = b.result.report;
  for (const FaceRange& range : b.face_ranges) {
    b.result.maps.skipped_faces.insert(b.result.maps.skipped_faces.end(), range.skipped.begin(), range.skipped.end());
    report.repeated_vertex_faces += range.repeats;
  }
  report.skipped_faces = b.result.maps.skipped_faces.size();
  b.has_repeats = report.repeated_vertex_faces > 0;
  b.has_skipped = report.skipped_faces > 0;
}

// ---- wiring, shared by both paths -------------------------------------------------------------

// Numbers the edges and wires every face: a glued pair of corner-edges shares one edge,
// numbered in the order of its first corner; every other corner-edge gets one whose outer
// half is on the boundary. `twin_into(prev, m)` is the corner-edge glued to the one entering
// mesh corner m (kInv: none), prev the corner before m in its face. Sets every field of the
// faces, of their half-edges and of the outer halves but their next and prev, which are
// the vertices' to set (link_local_fans or link_general_fans, and split_fans).
// `halfedge_of_corner` has room for every mesh corner.
template <class TwinInto>
void wire_faces(Build& b, Scratch<std::uint32_t> halfedge_of_corner, const std::uint32_t* mvert, TwinInto twin_into) {
  const std::vector<std::uint32_t>& moff = b.moff();
  const std::size_t nmf = b.n_mesh_faces();
  b.halfedge_of_corner = std::move(halfedge_of_corner);
  std::uint32_t* H = b.halfedge_of_corner.get();

  // Each range of faces numbers its own edges; a half-edge whose twin lies in an earlier
  // range is left for later (kInv). Branch-free where it can be: which case it is is a coin
  // toss.
  struct Numbered {
    std::size_t fbegin = 0, fend = 0;
    std::uint32_t edges = 0;
    std::vector<std::pair<std::uint32_t, std::uint32_t>> later;  // (corner, twin in an earlier range)
  };
  std::vector<Numbered> ranges =
      parallel_parts<Numbered>(moff, 0, [&](std::size_t fbegin, std::size_t fend, Numbered& range) {
        range.fbegin = fbegin;
        range.fend = fend;
        const std::uint32_t first = moff[fbegin];
        if (fbegin < fend) H[first] = 0;  // read (harmlessly) before it is written; a range may be empty
        std::uint32_t ne = 0;
        for (std::size_t f = fbegin; f < fend; ++f) {
          std::uint32_t prev = moff[f + 1] - 1;
          for (std::uint32_t m = moff[f]; m < moff[f + 1]; ++m) {
            // A new edge unless the twin came first (kInv, a boundary, is above every m).
            const std::uint32_t t = twin_into(prev, m);
            const bool fresh = t > m, elsewhere = !fresh && t < first;
            const std::uint32_t twin_half = H[fresh || elsewhere ? first : t] ^ 1u;
            H[m] = fresh ? 2 * ne : elsewhere ? kInv : twin_half;
            ne += fresh;
            if (elsewhere) range.later.emplace_back(m, t);
            prev = m;
          }
        }
        range.edges = ne;
      });
  // Then the later ranges shift their numbers by the edges before them, and fill in the
  // half-edges left for later once every range is shifted.
  std::uint32_t ne = 0;
  std::vector<std::uint32_t> shift(ranges.size());
  for (std::size_t r = 0; r < ranges.size(); ++r) {
    shift[r] = 2 * ne;
    ne += ranges[r].edges;
  }
  if (ranges.size() > 1) {
    auto each_later_range = [&](auto&& fn) {
      parallel_for(
          ranges.size() - 1, 0,
          [&](std::size_t begin, std::size_t end) {
            for (std::size_t r = begin + 1; r < end + 1; ++r) fn(r);
          },
          1);
    };
    each_later_range([&](std::size_t r) {
      for (std::uint32_t m = moff[ranges[r].fbegin]; m < moff[ranges[r].fend]; ++m)
        if (H[m] != kInv) H[m] += shift[r];
    });
    each_later_range([&](std::size_t r) {
      for (auto [m, t] : ranges[r].later) H[m] = H[t] ^ 1u;
    });
  }

  // The connectivity arrays are allocated unset and written here and by the vertices'
  // passes, every field exactly once, on several threads: their first touch is those writes.
  Mesh& mesh = b.result.mesh;
  mesh.positions().assign(b.soup.positions.begin(), b.soup.positions.end());
  mesh.resize_unset(b.nv, ne, nmf);
  parallel_for(
      nmf, 0,
      [&](std::size_t fbegin, std::size_t fend) {
        for (std::size_t fi = fbegin; fi < fend; ++fi) {
          const std::uint32_t first = moff[fi], end = moff[fi + 1];
          const Face f(static_cast<Index>(fi));
          mesh.set_halfedge(f, Halfedge(H[first]));
          std::uint32_t prev = end - 1;
          for (std::uint32_t m = first; m < end; ++m) {
            const Halfedge h(H[m]);
            mesh.set_vertex(h, Vertex(mvert[m]));
            mesh.set_face(h, f);
            mesh.set_next(Halfedge(H[prev]), h);
            if (twin_into(prev, m) == kInv) {  // a boundary: the outer half is this face's to set
              mesh.set_vertex(opposite(h), Vertex(mvert[prev]));
              mesh.set_face(opposite(h), Face());
            }
            prev = m;
          }
        }
      },
      kGrain);
}

// Appends the vertex copies and links the fans that became vertices.
void add_copies(Build& b, const std::vector<Fan>& fans) {
  Mesh& mesh = b.result.mesh;
  b.result.report.vertex_copies = b.copy_source.size();
  if (!b.copy_source.empty()) {
    mesh.resize(b.nv + b.copy_source.size(), mesh.edges_size(), mesh.faces_size());
    for (std::size_t i = 0; i < b.copy_source.size(); ++i)
      mesh.positions()[b.nv + i] = b.soup.positions[b.copy_source[i]];
  }
  for (const Fan& fan : fans) {
    mesh.set_halfedge(Vertex(fan.vertex), fan.out);
    if (fan.in.is_valid()) mesh.set_next(fan.in, fan.out);
  }
}

// One fan around the vertex that inner half-edge h0 points to, walked through the inner
// half-edges pointing to it: forward across next(h) to the neighbour face and, unless that
// comes back to h0, backward from h0; visit(h) sees each, and the walk stops after `limit`.
struct FanWalk {
  Halfedge first, last;  // the ends of an open fan
  bool cycle = false;    // a closed fan
  std::uint32_t count = 1;
};

template <class Visit>
FanWalk walk_fan(const Mesh& mesh, Halfedge h0, std::uint32_t limit, Visit&& visit) {
  FanWalk w{h0, h0};
  visit(h0);
  Halfedge h = h0;
  while (w.count <= limit) {
    const Halfedge t = opposite(mesh.next(h));
    if (!mesh.face(t).is_valid()) break;
    if (t == h0) {
      w.cycle = true;
      break;
    }
    h = t;
    visit(h);
    ++w.count;
  }
  w.last = h;
  if (!w.cycle) {
    for (h = h0; w.count <= limit;) {
      const Halfedge t = opposite(h);
      if (!mesh.face(t).is_valid()) break;
      h = mesh.prev(t);
      visit(h);
      ++w.count;
    }
    w.first = h;
  }
  return w;
}

// Vertices with several fans (touching at a vertex only): each fan after the first, in the
// order of their lowest corner, becomes a copy. `at` holds (vertex, inner half-edge pointing
// to it) of every corner of those vertices, by vertex and, within one, in corner order.
void split_fans(Build& b, const std::vector<std::pair<std::uint32_t, std::uint32_t>>& at) {
  if (at.empty()) return;
  Mesh& mesh = b.result.mesh;
  std::vector<std::uint8_t> visited(mesh.halfedges_size(), 0);
  std::vector<Fan> fans;
  std::vector<Halfedge> members;
  for (std::size_t i = 0; i < at.size();) {
    std::size_t j = i;
    while (j < at.size() && at[j].first == at[i].first) ++j;
    const std::uint32_t v = at[i].first;
    bool first_fan = true;
    for (std::size_t k = i; k < j; ++k) {
      const Halfedge h0(at[k].second);
      if (visited[h0.idx()]) continue;
      members.clear();
      const FanWalk w = walk_fan(mesh, h0, kInv, [&](Halfedge h) { members.push_back(h); });
      std::uint32_t id = v;
      if (!first_fan) {
        id = static_cast<std::uint32_t>(b.nv + b.copy_source.size());
        b.copy_source.push_back(v);
      }
      first_fan = false;
      for (Halfedge m : members) {
        visited[m.idx()] = 1;
        mesh.set_vertex(m, Vertex(id));
      }
      if (w.cycle) {
        fans.push_back({id, opposite(h0), Halfedge()});
      } else {
        const Halfedge in = opposite(mesh.next(w.last));
        mesh.set_vertex(in, Vertex(id));
        fans.push_back({id, opposite(w.first), in});
      }
    }
    ++b.result.report.non_manifold_vertices;
    i = j;
  }
  add_copies(b, fans);
}

// ---- the fast path ----------------------------------------------------------------------------

// What the fast path's passes hand on to each other.
struct Local {
  std::vector<std::uint32_t> vstart;  // vertex -> first entry of its corner list
  Scratch<VertexCorner> list;         // every vertex's corners, in corner order
  // out_twin[c] is the twin of the edge leaving corner c: the corner-edge (named by the
  // corner it points to) of the glued face.
  Scratch<std::uint32_t> out_twin;
  Scratch<std::uint32_t> vfirst, vlast;                          // one_fan()'s first and last corner (kInv: none)
  std::vector<std::pair<std::uint32_t, std::uint32_t>> several;  // split_fans()'s input
};

// Corners per vertex: a counting sort, each of classify_faces()'s ranges filling its own
// part of every vertex's list, so the lists come out in corner order.
void sort_corners_by_vertex(Build& b, Local& l) {
  const std::size_t nv = b.nv;
  l.vstart.resize(nv + 1);
  std::uint32_t sum = 0;
  for (std::size_t v = 0; v < nv; ++v) {
    l.vstart[v] = sum;
    for (FaceRange& range : b.face_ranges) {
      const std::uint32_t count = range.corners_at[v];
      range.corners_at[v] = sum;  // now the range's cursor
      sum += count;
    }
  }
  l.vstart[nv] = sum;
  l.list = Scratch<VertexCorner>(b.nc);
  parallel_for(
      b.face_ranges.size(), std::min(thread_count(), 2u),
      [&](std::size_t begin, std::size_t end) {
        for (std::size_t r = begin; r < end; ++r) {
          std::vector<std::uint32_t>& cursor = b.face_ranges[r].corners_at;
          for (std::size_t f = b.face_ranges[r].fbegin; f < b.face_ranges[r].fend; ++f) {
            const std::uint32_t first = b.soff[f], last = b.soff[f + 1];
            std::uint32_t prev = b.corner[last - 1], cur = b.corner[first];
            for (std::uint32_t c = first; c < last; ++c) {
              const std::uint32_t next = c + 1 < last ? b.corner[c + 1] : b.corner[first];
              l.list[cursor[cur]++] = {c, prev, next};
              prev = cur;
              cur = next;
            }
          }
        }
      },
      1);
  b.face_ranges = {};
}

// Links the corners around each vertex (link_corners) into out_twin and finds its one fan,
// or lists it for split_fans(). Returns false at the first edge of two faces running the
// same way.
bool link_corner_lists(Build& b, Local& l) {
  const std::size_t nv = b.nv;
  const std::vector<std::uint32_t>& vstart = l.vstart;
  l.out_twin = Scratch<std::uint32_t>(b.nc);
  l.vfirst = Scratch<std::uint32_t>(nv);
  l.vlast = Scratch<std::uint32_t>(nv);
  std::atomic<bool> unclean{false};
  struct Linked {
    std::vector<std::uint32_t> several;  // vertices with more than one fan
    std::size_t non_manifold = 0;        // non-manifold edges
  };
  const std::vector<Linked> linked =
      parallel_parts<Linked>(vstart, 0, [&](std::size_t vbegin, std::size_t vend, Linked& out) {
        std::vector<std::pair<std::uint32_t, std::uint32_t>> by_next, by_prev;
        std::vector<std::uint32_t> big;
        std::uint32_t small[32];
        for (std::size_t v = vbegin; v < vend; ++v) {
          const std::uint32_t k = vstart[v + 1] - vstart[v];
          l.vfirst[v] = l.vlast[v] = kInv;
          if (k == 0) continue;
          if ((v & 1023) == 0 && unclean.load(std::memory_order_relaxed)) return;
          std::uint32_t* succ = small;
          if (k > 32) {
            big.resize(k);
            succ = big.data();
          }
          const VertexCorner* e = l.list.get() + vstart[v];
          if (!link_corners(e, k, static_cast<std::uint32_t>(v), succ, out.non_manifold, by_next, by_prev)) {
            unclean.store(true, std::memory_order_relaxed);
            return;
          }
          for (std::uint32_t i = 0; i < k; ++i) l.out_twin[e[i].corner] = succ[i] == kInv ? kInv : e[succ[i]].corner;
          std::uint32_t first, last;
          if (one_fan(succ, k, first, last)) {
            l.vfirst[v] = e[first].corner;
            l.vlast[v] = last == kInv ? kInv : e[last].corner;
          } else {
            out.several.push_back(static_cast<std::uint32_t>(v));
          }
        }
      });
  if (unclean) return false;
  // (vertex, corner) of the vertices with several fans (few), kept before the lists' memory
  // becomes the corner -> half-edge map; the corners become half-edges once wired.
  for (const Linked& part : linked) {
    b.result.report.non_manifold_edges += part.non_manifold;
    for (std::uint32_t v : part.several)
      for (std::uint32_t i = vstart[v]; i < vstart[v + 1]; ++i) l.several.emplace_back(v, l.list[i].corner);
  }
  return true;
}

// halfedge(v) and the boundary loops of the one-fan vertices, from link_corner_lists():
// the outer half entering v continues with the one leaving it.
void link_local_fans(Build& b, Local& l) {
  const std::uint32_t* H = b.halfedge_of_corner.get();
  Mesh& mesh = b.result.mesh;
  parallel_for(
      b.nv, 0,
      [&](std::size_t vbegin, std::size_t vend) {
        for (std::size_t v = vbegin; v < vend; ++v) {
          if (l.vfirst[v] == kInv) {  // isolated, or several fans (split_fans)
            mesh.set_halfedge(Vertex(static_cast<Index>(v)), Halfedge());
            continue;
          }
          const Halfedge out(H[l.vfirst[v]] ^ 1u);
          mesh.set_halfedge(Vertex(static_cast<Index>(v)), out);
          if (l.vlast[v] != kInv) mesh.set_next(opposite(mesh.next(Halfedge(H[l.vlast[v]]))), out);
        }
      },
      kGrain);
  for (auto& [v, corner] : l.several) corner = H[corner];
}

// For soups that need no flip and no face skipped or split inside: any manifold surface, fans
// touching at a vertex, edges with three or more faces. Everything is decided in the corner
// list of each vertex. Returns false, having built nothing, when two faces on an edge run the
// same way (orientation is global).
bool build_local(Build& b) {
  Local l;
  sort_corners_by_vertex(b, l);
  if (!link_corner_lists(b, l)) return false;
  wire_faces(b, std::move(l.list).reuse_as<std::uint32_t>(b.nc), b.corner,
             [&](std::uint32_t prev, std::uint32_t) { return l.out_twin[prev]; });
  link_local_fans(b, l);
  split_fans(b, l.several);
  for (std::size_t v = 0; v < b.nv; ++v) b.result.report.isolated_vertices += l.vstart[v + 1] == l.vstart[v];
  return true;
}

// ---- the general path -------------------------------------------------------------------------

// What the general path's passes hand on to each other. A corner-edge is the directed edge of
// a face that points to a corner, named by that corner.
struct General {
  std::vector<std::uint32_t> soup_face_of;  // soup corner -> soup face, on the paths that need it
  std::vector<std::uint32_t> uses;          // corners per vertex in built faces
  Scratch<BucketEntry> entries;             // corner-edges in the buckets of their smaller vertex
  std::vector<std::uint32_t> twin;          // soup corner-edge -> the one glued to it (kInv: none)
  std::vector<std::pair<std::uint32_t, std::uint32_t>> same_direction;  // pairs glued only after a flip
  std::vector<ComplexGroup> complex_groups;                             // non-manifold edges
  std::vector<std::uint32_t> mvert_storage;  // mesh corner -> vertex, unless the corners are the soup's
  std::vector<std::uint32_t> mtwin;          // twin per mesh corner-edge
  const std::uint32_t* mvert = nullptr;
};

void need_soup_face_of(const Build& b, General& g) {
  if (!g.soup_face_of.empty() || b.nc == 0) return;
  g.soup_face_of.resize(b.nc);
  for (std::size_t f = 0; f < b.nf; ++f)
    std::fill(g.soup_face_of.begin() + b.soff[f], g.soup_face_of.begin() + b.soff[f + 1], f);
}

// Twins: buckets the corner-edges by their smaller vertex (a counting sort) and matches them
// inside each bucket. An edge of two opposite corner-edges is glued; two running the same way
// wait for orient(); three or more make a non-manifold edge for glue_non_manifold_edges().
void match_corner_edges(const Build& b, General& g) {
  const std::size_t nv = b.nv, nf = b.nf;
  const std::uint32_t* corner = b.corner;
  std::vector<std::uint32_t> bstart(nv + 1, 0);
  g.uses.assign(nv, 0);
  for (std::size_t f = 0; f < nf; ++f) {
    if (b.status[f] == kFaceSkipped) continue;
    std::uint32_t prev = corner[b.soff[f + 1] - 1];
    for (std::uint32_t c = b.soff[f]; c < b.soff[f + 1]; ++c) {
      const std::uint32_t cur = corner[c];
      ++g.uses[cur];
      if (cur != prev) ++bstart[std::min(prev, cur)];  // a self-loop edge never pairs
      prev = cur;
    }
  }
  {
    std::uint32_t sum = 0;
    for (std::size_t v = 0; v <= nv; ++v) {
      const std::uint32_t count = v < nv ? bstart[v] : 0;
      bstart[v] = sum;
      sum += count;
    }
  }
  g.entries = Scratch<BucketEntry>(bstart[nv]);
  BucketEntry* entries = g.entries.get();
  {
    std::vector<std::uint32_t> cursor(bstart.begin(), bstart.end() - 1);
    for (std::size_t f = 0; f < nf; ++f) {
      if (b.status[f] == kFaceSkipped) continue;
      std::uint32_t prev = corner[b.soff[f + 1] - 1];
      for (std::uint32_t c = b.soff[f]; c < b.soff[f + 1]; ++c) {
        const std::uint32_t cur = corner[c];
        if (cur < prev)
          entries[cursor[cur]++] = {prev, c};
        else if (cur > prev)
          entries[cursor[prev]++] = {cur, c | kDirBit};
        prev = cur;
      }
    }
  }

  g.twin.assign(b.nc, kInv);
  struct Found {
    std::vector<std::pair<std::uint32_t, std::uint32_t>> same;
    std::vector<ComplexGroup> groups;
  };
  const std::vector<Found> found =
      parallel_parts<Found>(bstart, 0, [&](std::size_t vbegin, std::size_t vend, Found& out) {
        for (std::size_t v = vbegin; v < vend; ++v) {
          const std::uint32_t first = bstart[v], end = bstart[v + 1];
          if (end - first < 2) continue;
          // Entries were filled in corner order; a stable sort by the other end keeps each
          // group in corner order, which is what makes the pairing deterministic.
          if (end - first <= 32) {
            for (std::uint32_t i = first + 1; i < end; ++i) {
              const BucketEntry x = entries[i];
              std::uint32_t j = i;
              for (; j > first && entries[j - 1].other > x.other; --j) entries[j] = entries[j - 1];
              entries[j] = x;
            }
          } else {  // a hub vertex: avoid the quadratic insertion sort
            std::stable_sort(entries + first, entries + end,
                             [](const BucketEntry& x, const BucketEntry& y) { return x.other < y.other; });
          }
          for (std::uint32_t i = first; i < end;) {
            std::uint32_t j = i + 1;
            while (j < end && entries[j].other == entries[i].other) ++j;
            if (j - i == 2) {
              const std::uint32_t c0 = entries[i].edge & ~kDirBit, c1 = entries[i + 1].edge & ~kDirBit;
              // Two sides of one face never glue to each other (the face would fold onto itself).
              if (!b.has_repeats || g.soup_face_of[c0] != g.soup_face_of[c1]) {
                if ((entries[i].edge ^ entries[i + 1].edge) & kDirBit) {
                  g.twin[c0] = c1;
                  g.twin[c1] = c0;
                } else {
                  out.same.emplace_back(c0, c1);
                }
              }
            } else if (j - i > 2) {
              out.groups.push_back({i, j - i});
            }
            i = j;
          }
        }
      });
  for (const Found& part : found) {
    g.same_direction.insert(g.same_direction.end(), part.same.begin(), part.same.end());
    g.complex_groups.insert(g.complex_groups.end(), part.groups.begin(), part.groups.end());
  }
}

// Orientation: a breadth-first walk over faces glued by two-face edges, flipping the minority
// of each component (on a tie, keeping the lowest face's). Without options.orient, edges of
// two faces running the same way stay two boundary edges.
void orient(Build& b, General& g) {
  BuildReport& report = b.result.report;
  if (g.same_direction.empty()) return;
  if (!b.options.orient) {
    report.non_manifold_edges += g.same_direction.size();  // left as two boundary edges
    return;
  }
  need_soup_face_of(b, g);
  std::vector<std::uint32_t>& twin = g.twin;
  std::vector<std::uint8_t> same(b.nc, 0);
  for (auto [x, y] : g.same_direction) {
    twin[x] = y;
    twin[y] = x;
    same[x] = same[y] = 1;
  }
  std::vector<std::uint8_t> parity(b.nf, 0), seen(b.nf, 0);
  std::vector<std::uint32_t> queue;
  std::size_t n_flipped = 0;
  for (std::size_t root = 0; root < b.nf; ++root) {
    if (seen[root] || b.status[root] == kFaceSkipped) continue;
    queue.clear();
    queue.push_back(static_cast<std::uint32_t>(root));
    seen[root] = 1;
    std::size_t component_flips = 0;
    for (std::size_t q = 0; q < queue.size(); ++q) {
      const std::uint32_t f = queue[q];
      component_flips += parity[f];
      for (std::uint32_t c = b.soff[f]; c < b.soff[f + 1]; ++c) {
        const std::uint32_t t = twin[c];
        if (t == kInv) continue;
        const std::uint32_t h = g.soup_face_of[t];
        const std::uint8_t want = parity[f] ^ same[c];
        if (!seen[h]) {
          seen[h] = 1;
          parity[h] = want;
          queue.push_back(h);
        } else if (parity[h] != want) {
          // A Möbius-like loop: no orientation satisfies both sides, so cut the edge.
          twin[c] = twin[t] = kInv;
          ++report.unorientable_edges;
        }
      }
    }
    const bool invert = 2 * component_flips > queue.size();
    for (std::uint32_t f : queue) parity[f] ^= static_cast<std::uint8_t>(invert);
    n_flipped += invert ? queue.size() - component_flips : component_flips;
  }
  for (auto [x, y] : g.same_direction)
    if (twin[x] != kInv) ++b.n_glued_by_flip;
  report.flipped_faces = n_flipped;
  if (n_flipped) b.flipped = std::move(parity);
}

// Non-manifold edges: glue the first pair of different faces running opposite ways (after
// the flips); the other faces keep their own edges, and split_fans() their own vertices.
void glue_non_manifold_edges(Build& b, General& g) {
  b.result.report.non_manifold_edges += g.complex_groups.size();
  if (!g.complex_groups.empty()) {
    need_soup_face_of(b, g);
    for (const ComplexGroup& group : g.complex_groups) {
      const BucketEntry* e = g.entries.get() + group.first;
      auto direction = [&](std::uint32_t i) {
        const std::uint32_t c = e[i].edge & ~kDirBit;
        const bool forward = e[i].edge & kDirBit;
        return forward != (!b.flipped.empty() && b.flipped[g.soup_face_of[c]]);
      };
      bool glued = false;
      for (std::uint32_t i = 0; i < group.size && !glued; ++i)
        for (std::uint32_t j = i + 1; j < group.size && !glued; ++j) {
          const std::uint32_t x = e[i].edge & ~kDirBit, y = e[j].edge & ~kDirBit;
          if (direction(i) != direction(j) && g.soup_face_of[x] != g.soup_face_of[y]) {
            g.twin[x] = y;
            g.twin[y] = x;
            glued = true;
          }
        }
    }
  }
  g.entries.reset();
}

// Mesh corners: the soup's in order minus skipped faces, flipped faces as c0, cn-1, ..., c1,
// with the twins carried over. When nothing is skipped or flipped they are the soup's own.
void lay_out_mesh_corners(Build& b, General& g) {
  const std::size_t nmf = b.n_mesh_faces(), nf = b.nf;
  b.identity = !b.has_skipped && b.flipped.empty();
  if (b.identity) {
    g.mtwin = std::move(g.twin);
    g.mvert = b.corner;
    return;
  }
  b.moff_storage.resize(nmf + 1);
  b.face_source.resize(nmf);
  std::size_t nmc = 0;
  for (std::size_t f = 0; f < nf; ++f)
    if (b.status[f] != kFaceSkipped) nmc += b.soup.face_sizes[f];
  b.msrc.resize(nmc);
  g.mvert_storage.resize(nmc);
  std::vector<std::uint32_t> edge_map(b.nc, kInv);  // soup corner-edge -> mesh corner-edge
  std::uint32_t m = 0, fi = 0;
  for (std::size_t f = 0; f < nf; ++f) {
    if (b.status[f] == kFaceSkipped) continue;
    const std::uint32_t size = b.soup.face_sizes[f], base = b.soff[f];
    const bool flip = !b.flipped.empty() && b.flipped[f];
    b.face_source[fi] = static_cast<std::uint32_t>(f);
    b.moff_storage[fi++] = m;
    for (std::uint32_t p = 0; p < size; ++p) {
      b.msrc[m + p] = base + (flip ? (size - p) % size : p);
      g.mvert_storage[m + p] = b.corner[b.msrc[m + p]];
      // The edge into soup corner k runs, reversed, into mesh corner (n - k + 1) % n.
      edge_map[base + p] = m + (flip ? (size - p + 1) % size : p);
    }
    m += size;
  }
  b.moff_storage[nmf] = m;
  g.mtwin.assign(nmc, kInv);
  for (std::size_t c = 0; c < b.nc; ++c)
    if (g.twin[c] != kInv) g.mtwin[edge_map[c]] = edge_map[g.twin[c]];
  g.twin = {};
  g.mvert = g.mvert_storage.data();
}

// Faces that visit a vertex twice: no fan may hold two corners of one face, or the face would
// meet itself at a vertex. Around each such vertex, the edges are cut greedily wherever a
// face comes up again (a closed fan is first opened before its first repeat).
void cut_repeated_corners(Build& b, General& g) {
  if (!b.has_repeats) return;
  const std::vector<std::uint32_t>& moff = b.moff();
  const std::size_t nmf = b.n_mesh_faces(), nmc = moff[nmf];
  const std::uint32_t* mvert = g.mvert;
  std::vector<std::uint32_t>& mtwin = g.mtwin;
  std::vector<std::uint32_t> mface_of(nmc);
  for (std::size_t fi = 0; fi < nmf; ++fi)
    std::fill(mface_of.begin() + moff[fi], mface_of.begin() + moff[fi + 1], static_cast<std::uint32_t>(fi));
  auto nxt = [&](std::uint32_t m) { return m + 1 == moff[mface_of[m] + 1] ? moff[mface_of[m]] : m + 1; };
  auto prv = [&](std::uint32_t m) { return m == moff[mface_of[m]] ? moff[mface_of[m] + 1] - 1 : m - 1; };
  // Walking around a vertex: the corner across the outgoing / incoming edge.
  auto succ = [&](std::uint32_t m) { return mtwin[nxt(m)]; };
  auto pred = [&](std::uint32_t m) {
    const std::uint32_t t = mtwin[m];
    return t == kInv ? kInv : prv(t);
  };
  auto cut_before = [&](std::uint32_t m) {  // unglue the edge between pred(m) and m
    const std::uint32_t t = mtwin[m];
    mtwin[t] = kInv;
    mtwin[m] = kInv;
    ++b.n_repeat_cuts;
  };
  std::vector<std::uint8_t> marked(b.nv, 0);
  for (std::size_t fi = 0; fi < nmf; ++fi)
    if (b.status[b.identity ? fi : b.face_source[fi]] == kFaceRepeats)
      for (std::uint32_t m = moff[fi]; m < moff[fi + 1]; ++m) marked[mvert[m]] = 1;
  std::vector<std::pair<std::uint32_t, std::uint32_t>> at;  // (vertex, corner) of marked vertices
  for (std::uint32_t m = 0; m < nmc; ++m)
    if (marked[mvert[m]]) at.emplace_back(mvert[m], m);
  std::stable_sort(at.begin(), at.end(), [](auto& x, auto& y) { return x.first < y.first; });
  std::vector<std::uint32_t> stamp(nmf, 0), fan;
  std::vector<std::uint8_t> done;
  std::uint32_t segment = 0;
  for (std::size_t i = 0; i < at.size();) {
    std::size_t j = i;
    while (j < at.size() && at[j].first == at[i].first) ++j;
    done.assign(j - i, 0);
    auto position = [&](std::uint32_t m) {
      return static_cast<std::size_t>(std::lower_bound(at.begin() + i, at.begin() + j, std::make_pair(at[i].first, m)) -
                                      (at.begin() + i));
    };
    for (std::size_t k = i; k < j; ++k) {
      if (done[k - i]) continue;
      const std::uint32_t x = at[k].second;
      std::uint32_t start = x;
      bool cycle = false;
      for (std::uint32_t p = pred(x); p != kInv; p = pred(p)) {
        if (p == x) {
          cycle = true;
          break;
        }
        start = p;
      }
      fan.clear();
      std::uint32_t y = start;
      do {
        fan.push_back(y);
        done[position(y)] = 1;
        y = succ(y);
      } while (y != kInv && y != start);
      if (cycle) {
        // Open the cycle right before the first corner whose face came up already.
        ++segment;
        std::size_t first_repeat = fan.size();
        for (std::size_t q = 0; q < fan.size() && first_repeat == fan.size(); ++q) {
          std::uint32_t& s = stamp[mface_of[fan[q]]];
          if (s == segment) first_repeat = q;
          s = segment;
        }
        if (first_repeat == fan.size()) continue;
        std::rotate(fan.begin(), fan.begin() + first_repeat, fan.end());
        cut_before(fan[0]);
      }
      // Greedy: a new segment (a cut) whenever a face shows up again.
      ++segment;
      for (std::size_t q = 0; q < fan.size(); ++q) {
        std::uint32_t& s = stamp[mface_of[fan[q]]];
        if (s == segment) {
          cut_before(fan[q]);
          ++segment;
        }
        stamp[mface_of[fan[q]]] = segment;
      }
    }
    i = j;
  }
}

// halfedge(v) and the boundary loops, by walking around each vertex in the wired mesh
// through inner half-edges pointing to it (across next(h) to the neighbour face; outer halves
// have no face). A vertex whose walk does not reach all its corners has several fans: they
// are returned as split_fans() wants them.
std::vector<std::pair<std::uint32_t, std::uint32_t>> link_general_fans(Build& b, const General& g) {
  Mesh& mesh = b.result.mesh;
  const std::vector<std::uint32_t>& moff = b.moff();
  const std::size_t nmf = b.n_mesh_faces(), nmc = moff[nmf];
  const std::uint32_t* H = b.halfedge_of_corner.get();
  const std::vector<std::uint32_t>& uses = g.uses;
  // The lowest corner's: halfedge(v) of a closed fan is its opposite, as in build_local().
  std::vector<std::uint32_t> incoming(b.nv, kInv);
  for (std::uint32_t m = static_cast<std::uint32_t>(nmc); m-- > 0;) incoming[g.mvert[m]] = H[m];
  const std::vector<std::vector<std::uint32_t>> split_parts = parallel_parts<std::vector<std::uint32_t>>(
      b.nv, 0, [&](std::size_t vbegin, std::size_t vend, std::vector<std::uint32_t>& split) {
        for (std::size_t vi = vbegin; vi < vend; ++vi) {
          const Vertex v(static_cast<Index>(vi));
          if (incoming[vi] == kInv) {  // isolated
            mesh.set_halfedge(v, Halfedge());
            continue;
          }
          const Halfedge h0(incoming[vi]);
          const FanWalk w = walk_fan(mesh, h0, uses[vi], [](Halfedge) {});
          if (w.count != uses[vi]) {
            split.push_back(static_cast<std::uint32_t>(vi));
            continue;
          }
          if (w.cycle) {
            mesh.set_halfedge(v, opposite(h0));
          } else {
            const Halfedge out = opposite(w.first), in = opposite(mesh.next(w.last));
            mesh.set_halfedge(v, out);
            mesh.set_next(in, out);
          }
        }
      });
  std::vector<std::uint8_t> marked(b.nv, 0);
  bool any = false;
  for (const auto& split : split_parts)
    for (std::uint32_t v : split) marked[v] = any = true;
  std::vector<std::pair<std::uint32_t, std::uint32_t>> at;  // (vertex, incoming inner half-edge)
  if (!any) return at;
  for (std::size_t fi = 0; fi < nmf; ++fi)
    for (Halfedge h : mesh.halfedges(Face(static_cast<Index>(fi))))
      if (marked[mesh.to_vertex(h).idx()]) at.emplace_back(mesh.to_vertex(h).idx(), h.idx());
  std::stable_sort(at.begin(), at.end(), [](auto& x, auto& y) { return x.first < y.first; });
  return at;
}

// Everything the fast path cannot decide locally: orientation, faces skipped or visiting a
// vertex twice, two faces on an edge that run the same way.
void build_general(Build& b) {
  b.face_ranges = {};
  General g;
  if (b.has_repeats) need_soup_face_of(b, g);
  match_corner_edges(b, g);
  orient(b, g);
  glue_non_manifold_edges(b, g);
  lay_out_mesh_corners(b, g);
  cut_repeated_corners(b, g);
  wire_faces(b, Scratch<std::uint32_t>(b.moff()[b.n_mesh_faces()]), g.mvert,
             [&](std::uint32_t, std::uint32_t m) { return g.mtwin[m]; });
  g.mtwin = {};
  split_fans(b, link_general_fans(b, g));
  for (std::size_t v = 0; v < b.nv; ++v) b.result.report.isolated_vertices += g.uses[v] == 0;
}

// ---- recording --------------------------------------------------------------------------------

// Where every mesh vertex and face came from, for the host (BuildMaps).
void record_maps(Build& b) {
  BuildMaps& maps = b.result.maps;
  maps.vertex_source.resize(b.nv + b.copy_source.size());
  for (std::size_t v = 0; v < b.nv; ++v) maps.vertex_source[v] = static_cast<std::uint32_t>(v);
  std::copy(b.copy_source.begin(), b.copy_source.end(), maps.vertex_source.begin() + b.nv);
  if (b.identity) {
    maps.face_source.resize(b.nf);
    for (std::size_t f = 0; f < b.nf; ++f) maps.face_source[f] = static_cast<std::uint32_t>(f);
  } else {
    maps.face_source = b.face_source;
  }
}

// The soup's channels onto the mesh: copies take their source vertex's values, corner data
// lives on the half-edge pointing to the corner (outer halves keep zeros).
void record_channels(Build& b) {
  Mesh& mesh = b.result.mesh;
  const std::size_t nmf = b.n_mesh_faces(), nmc = b.moff()[nmf], nv = b.nv;
  const std::uint32_t* H = b.halfedge_of_corner.get();
  for (const Channel& c : b.soup.channels) {
    const std::size_t stride = c.stride();
    const std::byte* data = c.data.data();
    switch (c.domain) {
      case Domain::vertex: {
        ChannelArray* a = mesh.vertex_properties().add_channel(c.name, c.scalar, c.components);
        if (nv) std::memcpy(a->element(0), data, nv * stride);
        for (std::size_t i = 0; i < b.copy_source.size(); ++i)
          std::memcpy(a->element(nv + i), data + b.copy_source[i] * stride, stride);
        break;
      }
      case Domain::face: {
        ChannelArray* a = mesh.face_properties().add_channel(c.name, c.scalar, c.components);
        if (b.identity) {
          if (b.nf) std::memcpy(a->element(0), data, b.nf * stride);
        } else {
          for (std::size_t fi = 0; fi < nmf; ++fi)
            std::memcpy(a->element(fi), data + b.face_source[fi] * stride, stride);
        }
        break;
      }
      case Domain::corner: {
        ChannelArray* a = mesh.halfedge_properties().add_channel(c.name, c.scalar, c.components);
        for (std::size_t m = 0; m < nmc; ++m)
          std::memcpy(a->element(H[m]), data + (b.identity ? m : b.msrc[m]) * stride, stride);
        break;
      }
    }
  }
  b.halfedge_of_corner.reset();
}

// Provenance (hedge/provenance.h), only where something changed: a clean build adds no arrays.
void record_provenance(Build& b) {
  Mesh& mesh = b.result.mesh;
  const std::size_t nmf = b.n_mesh_faces();
  auto soup_face = [&](std::size_t fi) { return b.identity ? fi : b.face_source[fi]; };
  if (!b.copy_source.empty()) {
    auto source = mesh.add_vertex_property<std::uint32_t>(provenance::kVertexSource, kInvalidIndex);
    source.vector() = b.result.maps.vertex_source;
  }
  if (!b.flipped.empty()) {
    auto flip = mesh.add_face_property<bool>(provenance::kFlipped, false);
    for (std::size_t fi = 0; fi < nmf; ++fi) flip.vector()[fi] = b.flipped[soup_face(fi)] != 0;
  }
  if (b.has_repeats) {  // these faces come back repeating their vertex (extract)
    auto repeats = mesh.add_face_property<bool>(provenance::kRepeats, false);
    for (std::size_t fi = 0; fi < nmf; ++fi) repeats.vector()[fi] = b.status[soup_face(fi)] == kFaceRepeats;
  }
  if (b.has_skipped) {
    auto source = mesh.add_face_property<std::uint32_t>(provenance::kFaceSource, kInvalidIndex);
    source.vector() = b.face_source;
  }
  // Appending the copies grew the vertex arrays with slack.
  if (!b.copy_source.empty()) mesh.shrink_to_fit();
}

// One line per kind of repair, for people.
void write_messages(Build& b) {
  BuildReport& report = b.result.report;
  auto say = [&](std::string line) { report.messages.push_back(std::move(line)); };
  if (report.skipped_faces)
    say("skipped " + plural(report.skipped_faces, "face", "faces") + " with fewer than 3 distinct vertices");
  if (report.repeated_vertex_faces)
    say(plural(report.repeated_vertex_faces, "face visits", "faces visit") +
        " a vertex more than once; their corners were given separate vertices" +
        (b.n_repeat_cuts ? " (" + plural(b.n_repeat_cuts, "edge", "edges") + " unglued)" : std::string()));
  if (report.flipped_faces)
    say("flipped " + plural(report.flipped_faces, "face", "faces") + " to orient consistently (" +
        plural(b.n_glued_by_flip, "edge", "edges") + " glued)");
  if (report.unorientable_edges)
    say("cut " + plural(report.unorientable_edges, "edge", "edges") + " where the surface cannot be oriented");
  if (report.non_manifold_edges)
    say("split " + plural(report.non_manifold_edges, "non-manifold edge", "non-manifold edges"));
  if (report.non_manifold_vertices)
    say("split " + plural(report.non_manifold_vertices, "non-manifold vertex", "non-manifold vertices") + " into " +
        plural(report.vertex_copies, "extra copy", "extra copies"));
  if (report.isolated_vertices)
    say("kept " + plural(report.isolated_vertices, "isolated vertex", "isolated vertices") + " no face uses");
}

}  // namespace

BuildResult build(const Soup& soup, const BuildOptions& options) {
  soup.check();
  for (const Channel& c : soup.channels)
    if (c.name.starts_with(provenance::kPrefix))
      throw Error("soup: " + std::string(domain_name(c.domain)) + " channel '" + c.name + "' uses the prefix '" +
                  provenance::kPrefix + "', which is reserved for the mesh's own bookkeeping");
  // Every corner is a half-edge, and its edge may need an outer one; each corner may
  // become a vertex copy.
  static_assert(kMaxCorners < kDirBit, "corner ids must leave the matching's direction bit free");
  check_limit("soup too large", soup.n_corners(), kMaxCorners, "corners");
  check_limit("soup too large", soup.n_faces(), kMaxElements, "faces");
  check_limit("soup too large", std::uint64_t{soup.n_vertices()} + soup.n_corners(), kMaxElements,
              "vertices with their possible copies (vertices plus corners)");
  Build b(soup, options);
  classify_faces(b);
  if (b.has_skipped || b.has_repeats || !build_local(b)) build_general(b);
  record_maps(b);
  record_channels(b);
  record_provenance(b);
  write_messages(b);
  return std::move(b.result);
}

namespace {

// An operation can bring two copies of one source vertex into one face (a hole filled
// across a split non-manifold vertex, a collapse next to a copy); welding them would make
// the face visit a vertex twice, which no host can hold. Faces whose input did so
// (provenance::kRepeats) weld as they came; in every other face such copies stay separate:
// in each face, of the corners that weld to one output vertex only one keeps welding (the
// group's representative `order[out]` when it is there, never a copy already kept apart).
// Marks only grow and kept-apart copies get their own indices, so one pass settles every
// face. Returns the copies to keep apart, in mesh order.
std::vector<std::uint32_t> copies_kept_apart(const Mesh& mesh, const std::vector<std::uint32_t>& vmap,
                                             const std::vector<std::uint32_t>& order) {
  std::vector<char> apart(mesh.vertices_size(), 0);
  std::vector<std::pair<std::uint32_t, std::uint32_t>> corners;  // (output vertex, mesh vertex)
  const TypedArray<bool>* repeats = mesh.face_properties().get<bool>(provenance::kRepeats);
  bool any = false;
  for (Face f : mesh.faces()) {
    if (repeats && repeats->vector()[f.idx()]) continue;
    corners.clear();
    for (Vertex v : mesh.vertices(f))
      if (!apart[v.idx()]) corners.emplace_back(vmap[v.idx()], v.idx());
    std::sort(corners.begin(), corners.end());
    for (std::size_t i = 0; i < corners.size();) {
      std::size_t j = i + 1;
      while (j < corners.size() && corners[j].first == corners[i].first) ++j;
      if (j - i > 1) {
        const std::uint32_t representative = order[corners[i].first];
        std::size_t keep = i;
        for (std::size_t k = i; k < j; ++k)
          if (corners[k].second == representative) keep = k;
        for (std::size_t k = i; k < j; ++k)
          if (k != keep) apart[corners[k].second] = any = true;
      }
      i = j;
    }
  }
  std::vector<std::uint32_t> result;
  if (any)
    for (std::uint32_t v = 0; v < apart.size(); ++v)
      if (apart[v]) result.push_back(v);
  return result;
}

}  // namespace

Soup extract(const Mesh& mesh, const ExtractOptions& options, ExtractReport* report) {
  if (report) *report = {};
  Soup soup;
  const TypedArray<std::uint32_t>* source =
      options.restore_source ? mesh.vertex_properties().get<std::uint32_t>(provenance::kVertexSource) : nullptr;
  const TypedArray<bool>* flipped =
      options.restore_source ? mesh.face_properties().get<bool>(provenance::kFlipped) : nullptr;
  const std::size_t nvs = mesh.vertices_size();

  // Output vertex -> mesh vertex (`order`), mesh vertex -> output vertex (`vmap`, empty when
  // both are the identity).
  std::vector<std::uint32_t> order, vmap;
  const bool vertices_identity = !source && mesh.n_vertices() == nvs;
  if (!vertices_identity) {
    vmap.assign(nvs, kInv);
    std::uint32_t n_out = 0;
    if (source) {
      // Copies weld into their source: ordered by source index, each group taking the data
      // of its first (lowest) mesh vertex.
      std::vector<std::pair<std::uint32_t, std::uint32_t>> by_source;  // (source, mesh vertex)
      by_source.reserve(mesh.n_vertices());
      for (Vertex v : mesh.vertices())
        if (const std::uint32_t s = source->vector()[v.idx()]; s != kInv) by_source.emplace_back(s, v.idx());
      std::stable_sort(by_source.begin(), by_source.end(), [](auto& a, auto& b) { return a.first < b.first; });
      for (std::size_t i = 0; i < by_source.size(); ++i) {
        if (i == 0 || by_source[i].first != by_source[i - 1].first) {
          order.push_back(by_source[i].second);
          ++n_out;
        }
        vmap[by_source[i].second] = n_out - 1;
      }
    }
    const std::uint32_t n_sourced = n_out;
    for (Vertex v : mesh.vertices())
      if (vmap[v.idx()] == kInv) {
        vmap[v.idx()] = n_out++;
        order.push_back(v.idx());
      }
    if (source) {
      const std::vector<std::uint32_t> apart = copies_kept_apart(mesh, vmap, order);
      for (std::uint32_t v : apart) {
        vmap[v] = n_out++;
        order.push_back(v);
      }
      std::size_t kept_apart = apart.size();
      if (options.input) {
        detail::Weld weld{std::move(vmap), std::move(order), n_sourced};
        kept_apart += detail::keep_new_defects_apart(mesh, source->vector(), *options.input, weld);
        vmap = std::move(weld.vmap);
        order = std::move(weld.order);
      }
      if (report) report->copies_kept_apart = kept_apart;
    }
  }
  const std::size_t n_out_vertices = vertices_identity ? nvs : order.size();
  auto mesh_vertex = [&](std::size_t i) -> std::uint32_t {
    return vertices_identity ? static_cast<std::uint32_t>(i) : order[i];
  };

  detail::resize_on_huge_pages(soup.positions, n_out_vertices);
  if (vertices_identity) {
    if (nvs) std::memcpy(soup.positions.data(), mesh.positions().data(), nvs * sizeof(Point));
  } else {
    for (std::size_t i = 0; i < n_out_vertices; ++i) soup.positions[i] = mesh.positions()[order[i]];
  }

  // Faces and corners; corner_halfedge remembers where each corner's data lives. Two passes
  // over ranges of faces, on several threads: count each range's faces and corners, then
  // write each range at its place in the output (the live faces in index order).
  const std::size_t nfs = mesh.faces_size();
  const bool faces_identity = mesh.n_faces() == nfs;
  bool has_corner_channels = false;
  const PropertyContainer& hprops = mesh.halfedge_properties();
  for (std::size_t i = 0; i < hprops.count(); ++i) has_corner_channels |= hprops.at(i).type() == typeid(ChannelArray);
  struct OutputRange {
    std::size_t begin = 0, end = 0;  // mesh faces
    std::size_t faces = 0, corners = 0;
  };
  std::vector<OutputRange> ranges =
      parallel_parts<OutputRange>(nfs, 0, [&](std::size_t b, std::size_t e, OutputRange& r) {
        r.begin = b, r.end = e;
        for (std::size_t f = b; f < e; ++f)
          if (!mesh.is_deleted(Face(static_cast<Index>(f)))) {
            ++r.faces;
            r.corners += mesh.valence(Face(static_cast<Index>(f)));
          }
      });
  std::size_t n_faces = 0, n_corners = 0;
  for (OutputRange& r : ranges) {
    const std::size_t faces = r.faces, corners = r.corners;
    r.faces = n_faces, r.corners = n_corners;  // from here on: where the range's output starts
    n_faces += faces, n_corners += corners;
  }
  detail::resize_on_huge_pages(soup.face_sizes, n_faces);
  detail::resize_on_huge_pages(soup.corners, n_corners);
  std::vector<std::uint32_t> corner_halfedge(has_corner_channels ? n_corners : 0);
  parallel_for(
      ranges.size(), 0,
      [&](std::size_t first_range, std::size_t last_range) {
        std::vector<Halfedge> loop;
        for (std::size_t r = first_range; r < last_range; ++r) {
          std::size_t k = ranges[r].faces, c = ranges[r].corners;
          for (std::size_t i = ranges[r].begin; i < ranges[r].end; ++i) {
            const Face f(static_cast<Index>(i));
            if (mesh.is_deleted(f)) continue;
            loop.clear();
            for (Halfedge h : mesh.halfedges(f)) loop.push_back(h);
            // Undo build()'s flip: c0, cn-1, ..., c1 is its own inverse.
            if (flipped && flipped->vector()[f.idx()]) std::reverse(loop.begin() + 1, loop.end());
            soup.face_sizes[k++] = static_cast<std::uint32_t>(loop.size());
            for (Halfedge h : loop) {
              const std::uint32_t v = mesh.to_vertex(h).idx();
              if (has_corner_channels) corner_halfedge[c] = h.idx();
              soup.corners[c++] = vertices_identity ? v : vmap[v];
            }
          }
        }
      },
      1);

  // Attributes: every ChannelArray; TypedArrays are the mesh's own and stay inside.
  // gather(c, n, at): element k of c's data is copied from at(k), on several threads.
  auto gather = [](Channel& c, std::size_t n, auto&& at) {
    const std::size_t stride = c.stride();
    parallel_for(n, 0, [&](std::size_t b, std::size_t e) {
      for (std::size_t k = b; k < e; ++k) std::memcpy(c.data.data() + k * stride, at(k), stride);
    });
  };
  auto emit = [&](const PropertyContainer& props, Domain domain) {
    for (std::size_t i = 0; i < props.count(); ++i) {
      const PropertyArray& array = props.at(i);
      if (array.type() != typeid(ChannelArray)) continue;
      const auto& a = static_cast<const ChannelArray&>(array);
      const std::size_t stride = a.stride();
      Channel c;
      c.name = a.name();
      c.domain = domain;
      c.scalar = a.scalar();
      c.components = a.components();
      switch (domain) {
        case Domain::vertex:
          c.data.resize(n_out_vertices * stride);
          if (vertices_identity) {
            if (nvs) std::memcpy(c.data.data(), a.element(0), nvs * stride);
          } else {
            gather(c, n_out_vertices, [&](std::size_t k) { return a.element(mesh_vertex(k)); });
          }
          break;
        case Domain::face: {
          c.data.resize(mesh.n_faces() * stride);
          if (faces_identity) {
            if (nfs) std::memcpy(c.data.data(), a.element(0), nfs * stride);
          } else {
            std::size_t k = 0;
            for (Face f : mesh.faces()) std::memcpy(c.data.data() + k++ * stride, a.element(f.idx()), stride);
          }
          break;
        }
        case Domain::corner:
          c.data.resize(corner_halfedge.size() * stride);
          gather(c, corner_halfedge.size(), [&](std::size_t k) { return a.element(corner_halfedge[k]); });
          break;
      }
      soup.channels.push_back(std::move(c));
    }
  };
  // Channels come out grouped by domain (vertex, face, corner), each in property order.
  emit(mesh.vertex_properties(), Domain::vertex);
  emit(mesh.face_properties(), Domain::face);
  emit(mesh.halfedge_properties(), Domain::corner);
  return soup;
}

}  // namespace hedge
