// build(): any soup -> a manifold half-edge mesh (splitting, orienting, recording where
// everything came from); extract(): mesh -> soup, undoing build()'s repairs.
#include "hedge/build.h"

#include <algorithm>
#include <cstdint>
#include <atomic>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <new>
#include <string>
#include <thread>
#include <type_traits>
#include <utility>
#include <vector>

#include "hedge/error.h"
#include "hedge/limits.h"
#include "hedge/threads.h"
#include "weld.h"

#ifdef __linux__
#include <sys/mman.h>
#endif

namespace hedge {
namespace {

constexpr std::uint32_t kInv = kInvalidIndex;
// Corner-edge ids carry their direction in the top bit inside the matching buckets, so
// a soup may hold at most 2^31 - 1 corners (far beyond what fits in memory anyway).
constexpr std::uint32_t kDirBit = 0x80000000u;

constexpr std::uint8_t kFaceOk = 0, kFaceRepeats = 1, kFaceSkipped = 2;

// Below this many elements a second thread costs more than it saves.
constexpr std::size_t kMinParallel = std::size_t(1) << 16;

// Runs fn(begin, end) over [0, n) on two threads when n is large enough to pay for
// starting one; the split point is fixed, so results do not depend on timing.
template <class Fn>
void parallel_ranges(std::size_t n, Fn&& fn) {
  if (n < kMinParallel || thread_count() < 2) {
    fn(std::size_t(0), n);
    return;
  }
  const std::size_t mid = n / 2;
  std::thread other([&] { fn(mid, n); });
  fn(std::size_t(0), mid);
  other.join();
}

// Memory for the big temporary arrays: uninitialised (every element is written before it
// is read), and on transparent huge pages where Linux offers them. In a virtual machine a
// 4 KiB page fault can cost more than writing the page, and these arrays are written once.
void* allocate_scratch(std::size_t bytes) {
  constexpr std::size_t kHugePage = std::size_t(2) << 20;
  void* p = nullptr;
  if (bytes >= kHugePage) {
    const std::size_t rounded = (bytes + kHugePage - 1) / kHugePage * kHugePage;
    p = std::aligned_alloc(kHugePage, rounded);
#ifdef __linux__
    if (p) madvise(p, rounded, MADV_HUGEPAGE);  // only a hint: small pages otherwise
#endif
  } else {
    p = std::malloc(bytes ? bytes : 1);
  }
  if (!p) throw std::bad_alloc();
  return p;
}

struct FreeScratch {
  void operator()(void* p) const { std::free(p); }
};

//! An uninitialised array of n trivial T in scratch memory.
template <class T>
class Scratch {
  static_assert(std::is_trivially_copyable_v<T> && std::is_trivially_destructible_v<T>);

 public:
  Scratch() = default;
  explicit Scratch(std::size_t n) : memory_(allocate_scratch(n * sizeof(T))), bytes_(n * sizeof(T)) {
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

struct ComplexGroup {  // 3+ corner-edges on one vertex pair: a non-manifold edge
  std::uint32_t first, size;  // range in the bucket entries
};

std::string plural(std::size_t n, const char* one, const char* many) {
  return std::to_string(n) + " " + (n == 1 ? one : many);
}

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

// pred = the inverse of succ.
void invert_links(const std::uint32_t* succ, std::uint32_t k, std::uint32_t* pred) {
  for (std::uint32_t i = 0; i < k; ++i) pred[i] = kInv;
  for (std::uint32_t i = 0; i < k; ++i)
    if (succ[i] != kInv) pred[succ[i]] = i;
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

class Builder {
 public:
  Builder(const Soup& soup, const BuildOptions& options)
      : soup_(soup), options_(options), nv_(soup.n_vertices()), nf_(soup.n_faces()), nc_(soup.n_corners()),
        corner_(soup.corners.data()) {}

  BuildResult run() {
    classify_faces();
    if (has_skipped_ || has_repeats_ || !build_local()) build_general();
    finish();
    return std::move(result_);
  }

 private:
  const std::vector<std::uint32_t>& moff() const { return identity_ ? soff_ : moff_; }
  std::size_t n_mesh_faces() const { return nf_ - result_.report.skipped_faces; }

  // Offsets, the faces that repeat a vertex or are too degenerate to build, and the
  // number of corners of each vertex in built faces (per half of the faces, so that the
  // fast path can fill its corner lists on two threads).
  void classify_faces() {
    soff_.resize(nf_ + 1);
    std::uint32_t offset = 0;
    for (std::size_t f = 0; f < nf_; ++f) {
      soff_[f] = offset;
      offset += soup_.face_sizes[f];
    }
    soff_[nf_] = offset;
    status_.assign(nf_, kFaceOk);
    fmid_ = nf_;
    if (nc_ >= kMinParallel && thread_count() >= 2)
      fmid_ = static_cast<std::size_t>(std::upper_bound(soff_.begin(), soff_.end(), offset / 2) - soff_.begin()) - 1;
    struct Part {
      std::vector<std::uint32_t> skipped;
      std::size_t repeats = 0;
    } parts[2];
    auto work = [&](std::size_t fbegin, std::size_t fend, int p) {
      std::vector<std::uint32_t>& counts = vertex_corners_[p];
      counts.assign(nv_, 0);
      std::vector<std::uint32_t> buffer;
      for (std::size_t f = fbegin; f < fend; ++f) {
        const std::uint32_t size = soup_.face_sizes[f], b = soff_[f];
        const std::uint32_t distinct = distinct_count(corner_ + b, size, buffer);
        if (distinct < 3) {
          status_[f] = kFaceSkipped;
          parts[p].skipped.push_back(static_cast<std::uint32_t>(f));
          continue;
        }
        if (distinct < size) {
          status_[f] = kFaceRepeats;
          ++parts[p].repeats;
        }
        for (std::uint32_t c = b; c < b + size; ++c) ++counts[corner_[c]];
      }
    };
    if (fmid_ < nf_) {
      std::thread other([&] { work(fmid_, nf_, 1); });
      work(0, fmid_, 0);
      other.join();
    } else {
      work(0, nf_, 0);
    }
    result_.maps.skipped_faces = std::move(parts[0].skipped);
    result_.maps.skipped_faces.insert(result_.maps.skipped_faces.end(), parts[1].skipped.begin(), parts[1].skipped.end());
    result_.report.skipped_faces = result_.maps.skipped_faces.size();
    result_.report.repeated_vertex_faces = parts[0].repeats + parts[1].repeats;
    has_repeats_ = result_.report.repeated_vertex_faces > 0;
    has_skipped_ = result_.report.skipped_faces > 0;
  }

  // The fast path, for soups that need no flip and no face skipped or split inside: any
  // manifold surface, fans touching at a vertex, edges with three or more faces. Everything
  // is decided locally in the corner list of each vertex. Returns false, having built
  // nothing, when two faces on an edge run the same way (orientation is global).
  bool build_local() {
    // Corners per vertex: a counting sort, each half of the faces filling its own part of
    // every vertex's list, so the lists come out in corner order.
    std::vector<std::uint32_t> vstart(nv_ + 1);
    std::vector<std::uint32_t>& cursor0 = vertex_corners_[0];
    std::vector<std::uint32_t>& cursor1 = vertex_corners_[1];
    const bool two = fmid_ < nf_;
    {
      std::uint32_t sum = 0;
      for (std::size_t v = 0; v < nv_; ++v) {
        const std::uint32_t c0 = cursor0[v], c1 = two ? cursor1[v] : 0;
        vstart[v] = sum;
        cursor0[v] = sum;
        if (two) cursor1[v] = sum + c0;
        sum += c0 + c1;
      }
      vstart[nv_] = sum;
    }
    Scratch<VertexCorner> list(nc_);
    auto fill = [&](std::size_t fbegin, std::size_t fend, std::vector<std::uint32_t>& cursor) {
      for (std::size_t f = fbegin; f < fend; ++f) {
        const std::uint32_t b = soff_[f], e = soff_[f + 1];
        std::uint32_t prev = corner_[e - 1], cur = corner_[b];
        for (std::uint32_t c = b; c < e; ++c) {
          const std::uint32_t next = c + 1 < e ? corner_[c + 1] : corner_[b];
          list[cursor[cur]++] = {c, prev, next};
          prev = cur;
          cur = next;
        }
      }
    };
    if (two) {
      std::thread other([&] { fill(fmid_, nf_, cursor1); });
      fill(0, fmid_, cursor0);
      other.join();
    } else {
      fill(0, nf_, cursor0);
    }
    vertex_corners_[0] = {};
    vertex_corners_[1] = {};

    // Link the corners around each vertex. out_twin[c] is the twin of the edge leaving
    // corner c: the corner-edge (named by the corner it points to) of the glued face.
    Scratch<std::uint32_t> out_twin(nc_);
    Scratch<std::uint32_t> vfirst(nv_), vlast(nv_);
    std::atomic<bool> unclean{false};
    std::vector<std::uint32_t> several[2];  // vertices with more than one fan, per thread
    std::size_t non_manifold[2] = {0, 0};   // non-manifold edges, per thread
    auto link = [&](std::size_t vbegin, std::size_t vend, int part) {
      std::vector<std::pair<std::uint32_t, std::uint32_t>> by_next, by_prev;
      std::vector<std::uint32_t> big;
      std::uint32_t small[32];
      for (std::size_t v = vbegin; v < vend; ++v) {
        const std::uint32_t k = vstart[v + 1] - vstart[v];
        vfirst[v] = vlast[v] = kInv;
        if (k == 0) continue;
        if ((v & 1023) == 0 && unclean.load(std::memory_order_relaxed)) return;
        std::uint32_t* succ = small;
        if (k > 32) {
          big.resize(k);
          succ = big.data();
        }
        const VertexCorner* e = list.get() + vstart[v];
        if (!link_corners(e, k, static_cast<std::uint32_t>(v), succ, non_manifold[part], by_next, by_prev)) {
          unclean.store(true, std::memory_order_relaxed);
          return;
        }
        for (std::uint32_t i = 0; i < k; ++i) out_twin[e[i].corner] = succ[i] == kInv ? kInv : e[succ[i]].corner;
        std::uint32_t first, last;
        if (one_fan(succ, k, first, last)) {
          vfirst[v] = e[first].corner;
          vlast[v] = last == kInv ? kInv : e[last].corner;
        } else {
          several[part].push_back(static_cast<std::uint32_t>(v));
        }
      }
    };
    if (nc_ >= kMinParallel && thread_count() >= 2) {
      // Split where half the corners lie, so both threads get equal work.
      const std::size_t mid = std::min<std::size_t>(
          nv_, static_cast<std::size_t>(std::upper_bound(vstart.begin(), vstart.end(), vstart[nv_] / 2) - vstart.begin()));
      std::thread other([&] { link(mid, nv_, 1); });
      link(0, mid, 0);
      other.join();
    } else {
      link(0, nv_, 0);
    }
    if (unclean) return false;
    result_.report.non_manifold_edges = non_manifold[0] + non_manifold[1];

    // Keep the corner lists of the vertices with several fans (few), then reuse the lists'
    // memory for the corner -> half-edge map.
    several[0].insert(several[0].end(), several[1].begin(), several[1].end());
    std::vector<VertexCorner> several_lists;
    std::vector<std::uint32_t> several_start{0};
    for (std::uint32_t v : several[0]) {
      several_lists.insert(several_lists.end(), list.get() + vstart[v], list.get() + vstart[v + 1]);
      several_start.push_back(static_cast<std::uint32_t>(several_lists.size()));
    }
    Scratch<std::uint32_t> halfedge_of_corner = std::move(list).reuse_as<std::uint32_t>(nc_);

    // Edges: a glued pair shares one, numbered in the order of its first corner. Each half
    // of the faces numbers its own edges on its own thread; then the second half's numbers
    // are shifted by the first half's count, and its half-edges whose twin lies in the
    // first half (kInv until then) are filled in.
    std::uint32_t* H = halfedge_of_corner.get();
    std::uint32_t edges_in[2] = {0, 0};
    auto number = [&](std::size_t fbegin, std::size_t fend, int part) {
      const std::uint32_t first = soff_[fbegin];
      if (first < nc_) H[first] = 0;  // read (harmlessly) before it is written
      std::uint32_t ne = 0;
      for (std::size_t f = fbegin; f < fend; ++f) {
        std::uint32_t prev = soff_[f + 1] - 1;
        for (std::uint32_t m = soff_[f]; m < soff_[f + 1]; ++m) {
          // A new edge unless the twin came first (kInv, a boundary, is above every m).
          // Branch-free: which case it is is a coin toss.
          const std::uint32_t t = out_twin[prev];
          const bool fresh = t > m, elsewhere = !fresh && t < first;
          const std::uint32_t twin_half = H[fresh || elsewhere ? first : t] ^ 1u;
          H[m] = fresh ? 2 * ne : elsewhere ? kInv : twin_half;
          ne += fresh;
          prev = m;
        }
      }
      edges_in[part] = ne;
    };
    if (fmid_ < nf_) {
      std::thread other([&] { number(fmid_, nf_, 1); });
      number(0, fmid_, 0);
      other.join();
      const std::uint32_t shift = 2 * edges_in[0];
      parallel_ranges(nf_ - fmid_, [&](std::size_t begin, std::size_t end) {
        for (std::size_t f = fmid_ + begin; f < fmid_ + end; ++f) {
          std::uint32_t prev = soff_[f + 1] - 1;
          for (std::uint32_t m = soff_[f]; m < soff_[f + 1]; ++m) {
            H[m] = H[m] == kInv ? H[out_twin[prev]] ^ 1u : H[m] + shift;
            prev = m;
          }
        }
      });
    } else {
      number(0, nf_, 0);
    }
    const std::uint32_t ne = edges_in[0] + edges_in[1];

    Mesh& mesh = result_.mesh;
    // The connectivity arrays are allocated unset and written below, every field exactly
    // once, on both threads: their first touch is those writes.
    mesh.positions().assign(soup_.positions.begin(), soup_.positions.end());
    mesh.resize_unset(nv_, ne, nf_);
    parallel_ranges(nf_, [&](std::size_t fbegin, std::size_t fend) {
      for (std::size_t fi = fbegin; fi < fend; ++fi) {
        const std::uint32_t b = soff_[fi], e = soff_[fi + 1];
        const Face f(static_cast<Index>(fi));
        mesh.set_halfedge(f, Halfedge(H[b]));
        std::uint32_t prev = e - 1;
        for (std::uint32_t m = b; m < e; ++m) {
          const Halfedge h(H[m]);
          mesh.set_vertex(h, Vertex(corner_[m]));
          mesh.set_face(h, f);
          mesh.set_next(Halfedge(H[prev]), h);
          if (out_twin[prev] == kInv) {  // a boundary: the outer half is this face's to set
            mesh.set_vertex(opposite(h), Vertex(corner_[prev]));
            mesh.set_face(opposite(h), Face());
          }
          prev = m;
        }
      }
    });
    // halfedge(v) and the boundary loops: the outer half entering v continues with the one
    // leaving it.
    parallel_ranges(nv_, [&](std::size_t vbegin, std::size_t vend) {
      for (std::size_t v = vbegin; v < vend; ++v) {
        if (vfirst[v] == kInv) {  // isolated, or several fans (set below)
          mesh.set_halfedge(Vertex(static_cast<Index>(v)), Halfedge());
          continue;
        }
        const Halfedge out(H[vfirst[v]] ^ 1u);
        mesh.set_halfedge(Vertex(static_cast<Index>(v)), out);
        if (vlast[v] != kInv) mesh.set_next(opposite(mesh.next(Halfedge(H[vlast[v]]))), out);
      }
    });

    // Vertices with several fans (touching at a vertex only): each fan after the first, in
    // the order of their lowest corner, becomes a copy.
    if (!several[0].empty()) {
      std::vector<Fan> fans;
      std::vector<std::pair<std::uint32_t, std::uint32_t>> by_next, by_prev;
      std::vector<std::uint32_t> links;
      std::vector<std::uint8_t> visited;
      for (std::size_t sv = 0; sv < several[0].size(); ++sv) {
        const std::uint32_t v = several[0][sv];
        const std::uint32_t k = several_start[sv + 1] - several_start[sv];
        const VertexCorner* e = several_lists.data() + several_start[sv];
        links.resize(2 * k);
        std::uint32_t *succ = links.data(), *pred = succ + k;
        std::size_t counted_already = 0;
        link_corners(e, k, v, succ, counted_already, by_next, by_prev);
        invert_links(succ, k, pred);
        visited.assign(k, 0);
        bool first_fan = true;
        for (std::uint32_t i = 0; i < k; ++i) {
          if (visited[i]) continue;
          std::uint32_t s = i;
          bool closed = false;
          while (pred[s] != kInv) {
            s = pred[s];
            if (s == i) {
              closed = true;
              break;
            }
          }
          const std::uint32_t id = first_fan ? v : static_cast<std::uint32_t>(nv_ + copy_source_.size());
          if (!first_fan) copy_source_.push_back(v);
          first_fan = false;
          std::uint32_t x = s, end = s;
          do {
            visited[x] = 1;
            mesh.set_vertex(Halfedge(H[e[x].corner]), Vertex(id));
            end = x;
            x = succ[x];
          } while (x != kInv && x != s);
          const Halfedge out(H[e[s].corner] ^ 1u);
          Halfedge in;
          if (!closed) {
            in = opposite(mesh.next(Halfedge(H[e[end].corner])));
            mesh.set_vertex(in, Vertex(id));
          }
          fans.push_back({id, out, in});
        }
        ++result_.report.non_manifold_vertices;
      }
      add_copies(fans);
    }
    for (std::size_t v = 0; v < nv_; ++v) result_.report.isolated_vertices += vstart[v + 1] == vstart[v];
    identity_ = true;
    halfedge_of_corner_ = std::move(halfedge_of_corner);
    return true;
  }

  // Appends the vertex copies and links the fans that became vertices.
  void add_copies(const std::vector<Fan>& fans) {
    Mesh& mesh = result_.mesh;
    result_.report.vertex_copies = copy_source_.size();
    if (!copy_source_.empty()) {
      mesh.resize(nv_ + copy_source_.size(), mesh.edges_size(), mesh.faces_size());
      for (std::size_t i = 0; i < copy_source_.size(); ++i) mesh.positions()[nv_ + i] = soup_.positions[copy_source_[i]];
    }
    for (const Fan& fan : fans) {
      mesh.set_halfedge(Vertex(fan.vertex), fan.out);
      if (fan.in.is_valid()) mesh.set_next(fan.in, fan.out);
    }
  }

  // The general path: twins by a counting sort of the corner-edges, orientation, non-manifold
  // edges and vertices, faces that visit a vertex twice.
  void build_general() {
    vertex_corners_[0] = {};
    vertex_corners_[1] = {};
    const Soup& soup = soup_;
    const BuildOptions& options = options_;
    const std::size_t nv = nv_, nf = nf_, nc = nc_;
    const std::uint32_t* corner = corner_;
    BuildReport& report = result_.report;
    std::vector<std::uint32_t>& soff = soff_;
    const std::vector<std::uint8_t>& status = status_;
    const bool has_repeats = has_repeats_, has_skipped = has_skipped_;
    std::vector<std::uint8_t>& flipped = flipped_;
    std::vector<std::uint32_t>& moff_storage = moff_;
    std::vector<std::uint32_t>& msrc = msrc_;
    std::vector<std::uint32_t>& face_source = face_source_;
    std::vector<std::uint32_t>& copy_source = copy_source_;
    std::size_t& n_glued_by_flip = n_glued_by_flip_;
    std::size_t& n_repeat_cuts = n_repeat_cuts_;

    // Soup corner -> soup face, built only on the paths that need it.
    std::vector<std::uint32_t> soup_face_of;
    auto need_soup_face_of = [&] {
      if (!soup_face_of.empty() || nc == 0) return;
      soup_face_of.resize(nc);
      for (std::size_t f = 0; f < nf; ++f) std::fill(soup_face_of.begin() + soff[f], soup_face_of.begin() + soff[f + 1], f);
    };
    if (has_repeats) need_soup_face_of();

    // ---- 2. twins: bucket corner-edges by their smaller vertex (counting sort), match inside
    // the buckets. Corner-edge c is the directed edge of its face that points to corner c.
    std::vector<std::uint32_t> bstart(nv + 1, 0);
    std::vector<std::uint32_t> uses(nv, 0);  // corners per vertex in built faces
    for (std::size_t f = 0; f < nf; ++f) {
      if (status[f] == kFaceSkipped) continue;
      std::uint32_t prev = corner[soff[f + 1] - 1];
      for (std::uint32_t c = soff[f]; c < soff[f + 1]; ++c) {
        const std::uint32_t cur = corner[c];
        ++uses[cur];
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
    const std::size_t n_entries = bstart[nv];
    Scratch<BucketEntry> entries(n_entries);
    {
      std::vector<std::uint32_t> cursor(bstart.begin(), bstart.end() - 1);
      for (std::size_t f = 0; f < nf; ++f) {
        if (status[f] == kFaceSkipped) continue;
        std::uint32_t prev = corner[soff[f + 1] - 1];
        for (std::uint32_t c = soff[f]; c < soff[f + 1]; ++c) {
          const std::uint32_t cur = corner[c];
          if (cur < prev)
            entries[cursor[cur]++] = {prev, c};
          else if (cur > prev)
            entries[cursor[prev]++] = {cur, c | kDirBit};
          prev = cur;
        }
      }
    }

    std::vector<std::uint32_t> twin(nc, kInv);
    std::vector<std::pair<std::uint32_t, std::uint32_t>> same_direction;  // pairs glued only after a flip
    std::vector<ComplexGroup> complex_groups;
    {
      struct Found {
        std::vector<std::pair<std::uint32_t, std::uint32_t>> same;
        std::vector<ComplexGroup> groups;
      };
      Found found[2];
      auto match = [&](std::size_t vbegin, std::size_t vend, Found& out) {
        for (std::size_t v = vbegin; v < vend; ++v) {
          const std::uint32_t b = bstart[v], e = bstart[v + 1];
          if (e - b < 2) continue;
          // Entries were filled in corner order; a stable sort by the other end keeps each
          // group in corner order, which is what makes the pairing deterministic.
          if (e - b <= 32) {
            for (std::uint32_t i = b + 1; i < e; ++i) {
              const BucketEntry x = entries[i];
              std::uint32_t j = i;
              for (; j > b && entries[j - 1].other > x.other; --j) entries[j] = entries[j - 1];
              entries[j] = x;
            }
          } else {  // a hub vertex: avoid the quadratic insertion sort
            std::stable_sort(entries.get() + b, entries.get() + e,
                             [](const BucketEntry& x, const BucketEntry& y) { return x.other < y.other; });
          }
          for (std::uint32_t i = b; i < e;) {
            std::uint32_t j = i + 1;
            while (j < e && entries[j].other == entries[i].other) ++j;
            if (j - i == 2) {
              const std::uint32_t c0 = entries[i].edge & ~kDirBit, c1 = entries[i + 1].edge & ~kDirBit;
              // Two sides of one face never glue to each other (the face would fold onto itself).
              if (!has_repeats || soup_face_of[c0] != soup_face_of[c1]) {
                if ((entries[i].edge ^ entries[i + 1].edge) & kDirBit) {
                  twin[c0] = c1;
                  twin[c1] = c0;
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
      };
      std::size_t mid = nv;
      if (n_entries >= kMinParallel && thread_count() >= 2) {
        // Split the vertices where half the entries lie, so both threads get equal work.
        mid = static_cast<std::size_t>(std::upper_bound(bstart.begin(), bstart.end(), bstart[nv] / 2) - bstart.begin());
        mid = std::min(mid, nv);
        std::thread other([&] { match(mid, nv, found[1]); });
        match(0, mid, found[0]);
        other.join();
      } else {
        match(0, nv, found[0]);
      }
      same_direction = std::move(found[0].same);
      same_direction.insert(same_direction.end(), found[1].same.begin(), found[1].same.end());
      complex_groups = std::move(found[0].groups);
      complex_groups.insert(complex_groups.end(), found[1].groups.begin(), found[1].groups.end());
    }
    bstart = {};
    bstart.shrink_to_fit();
    report.non_manifold_edges = complex_groups.size();

    // ---- 3. orientation: BFS over faces glued by 2-sided edges, flipping the minority -----
    if (!same_direction.empty() && options.orient) {
      need_soup_face_of();
      std::vector<std::uint8_t> same(nc, 0);
      for (auto [a, b] : same_direction) {
        twin[a] = b;
        twin[b] = a;
        same[a] = same[b] = 1;
      }
      std::vector<std::uint8_t> parity(nf, 0), seen(nf, 0);
      std::vector<std::uint32_t> queue;
      std::size_t n_flipped = 0;
      for (std::size_t root = 0; root < nf; ++root) {
        if (seen[root] || status[root] == kFaceSkipped) continue;
        queue.clear();
        queue.push_back(static_cast<std::uint32_t>(root));
        seen[root] = 1;
        std::size_t component_flips = 0;
        for (std::size_t q = 0; q < queue.size(); ++q) {
          const std::uint32_t f = queue[q];
          component_flips += parity[f];
          for (std::uint32_t c = soff[f]; c < soff[f + 1]; ++c) {
            const std::uint32_t t = twin[c];
            if (t == kInv) continue;
            const std::uint32_t g = soup_face_of[t];
            const std::uint8_t want = parity[f] ^ same[c];
            if (!seen[g]) {
              seen[g] = 1;
              parity[g] = want;
              queue.push_back(g);
            } else if (parity[g] != want) {
              // A Möbius-like loop: no orientation satisfies both sides, so cut the edge.
              twin[c] = twin[t] = kInv;
              ++report.unorientable_edges;
            }
          }
        }
        // Keep the orientation most faces have; on a tie, the one of the lowest face.
        const bool invert = 2 * component_flips > queue.size();
        for (std::uint32_t f : queue) parity[f] ^= static_cast<std::uint8_t>(invert);
        n_flipped += invert ? queue.size() - component_flips : component_flips;
      }
      for (auto [a, b] : same_direction)
        if (twin[a] != kInv) ++n_glued_by_flip;
      report.flipped_faces = n_flipped;
      if (n_flipped) flipped = std::move(parity);
    } else if (!same_direction.empty()) {
      report.non_manifold_edges += same_direction.size();  // left as two boundary edges
    }

    // ---- 4. non-manifold edges: glue the first opposite pair of different faces -----------
    if (!complex_groups.empty()) {
      need_soup_face_of();
      for (const ComplexGroup& group : complex_groups) {
        const BucketEntry* g = entries.get() + group.first;
        auto direction = [&](std::uint32_t i) {
          const std::uint32_t c = g[i].edge & ~kDirBit;
          const bool forward = g[i].edge & kDirBit;
          return forward != (!flipped.empty() && flipped[soup_face_of[c]]);
        };
        bool glued = false;
        for (std::uint32_t i = 0; i < group.size && !glued; ++i)
          for (std::uint32_t j = i + 1; j < group.size && !glued; ++j) {
            const std::uint32_t a = g[i].edge & ~kDirBit, b = g[j].edge & ~kDirBit;
            if (direction(i) != direction(j) && soup_face_of[a] != soup_face_of[b]) {
              twin[a] = b;
              twin[b] = a;
              glued = true;
            }
          }
      }
    }
    entries.reset();

    // ---- 5. mesh corners: soup order minus skipped faces, flipped faces as c0, cn-1, .., c1 --
    const std::size_t nmf = nf - report.skipped_faces;
    const bool identity = !has_skipped && flipped.empty();
    identity_ = identity;
    std::vector<std::uint32_t> mvert_storage;
    std::vector<std::uint32_t>& moff = identity ? soff : moff_storage;
    std::vector<std::uint32_t> mtwin;
    if (identity) {
      mtwin = std::move(twin);
    } else {
      moff_storage.resize(nmf + 1);
      face_source.resize(nmf);
      std::size_t nmc = 0;
      for (std::size_t f = 0; f < nf; ++f)
        if (status[f] != kFaceSkipped) nmc += soup.face_sizes[f];
      msrc.resize(nmc);
      mvert_storage.resize(nmc);
      std::vector<std::uint32_t> edge_map(nc, kInv);  // soup corner-edge -> mesh corner-edge
      std::uint32_t m = 0, fi = 0;
      for (std::size_t f = 0; f < nf; ++f) {
        if (status[f] == kFaceSkipped) continue;
        const std::uint32_t size = soup.face_sizes[f], base = soff[f];
        const bool flip = !flipped.empty() && flipped[f];
        face_source[fi] = static_cast<std::uint32_t>(f);
        moff_storage[fi++] = m;
        for (std::uint32_t p = 0; p < size; ++p) {
          msrc[m + p] = base + (flip ? (size - p) % size : p);
          mvert_storage[m + p] = corner[msrc[m + p]];
          // The edge into soup corner k runs, reversed, into mesh corner (n - k + 1) % n.
          edge_map[base + p] = m + (flip ? (size - p + 1) % size : p);
        }
        m += size;
      }
      moff_storage[nmf] = m;
      mtwin.assign(nmc, kInv);
      for (std::size_t c = 0; c < nc; ++c)
        if (twin[c] != kInv) mtwin[edge_map[c]] = edge_map[twin[c]];
      twin = {};
      twin.shrink_to_fit();
    }
    const std::uint32_t* mvert = identity ? corner : mvert_storage.data();
    const std::size_t nmc = moff[nmf];

    // ---- 6. faces that visit a vertex twice: no fan may hold two corners of one face -------
    if (has_repeats) {
      std::vector<std::uint32_t> mface_of(nmc);
      for (std::size_t fi = 0; fi < nmf; ++fi)
        std::fill(mface_of.begin() + moff[fi], mface_of.begin() + moff[fi + 1], static_cast<std::uint32_t>(fi));
      auto nxt = [&](std::uint32_t m) {
        return m + 1 == moff[mface_of[m] + 1] ? moff[mface_of[m]] : m + 1;
      };
      auto prv = [&](std::uint32_t m) {
        return m == moff[mface_of[m]] ? moff[mface_of[m] + 1] - 1 : m - 1;
      };
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
        ++n_repeat_cuts;
      };
      std::vector<std::uint8_t> marked(nv, 0);
      for (std::size_t fi = 0; fi < nmf; ++fi)
        if (status[identity ? fi : face_source[fi]] == kFaceRepeats)
          for (std::uint32_t m = moff[fi]; m < moff[fi + 1]; ++m) marked[mvert[m]] = 1;
      std::vector<std::pair<std::uint32_t, std::uint32_t>> at;  // (vertex, corner) of marked vertices
      for (std::uint32_t m = 0; m < nmc; ++m)
        if (marked[mvert[m]]) at.emplace_back(mvert[m], m);
      std::stable_sort(at.begin(), at.end(), [](auto& a, auto& b) { return a.first < b.first; });
      std::vector<std::uint32_t> stamp(nmf, 0), fan;
      std::vector<std::uint8_t> done;
      std::uint32_t segment = 0;
      for (std::size_t i = 0; i < at.size();) {
        std::size_t j = i;
        while (j < at.size() && at[j].first == at[i].first) ++j;
        done.assign(j - i, 0);
        auto position = [&](std::uint32_t m) {
          return static_cast<std::size_t>(
              std::lower_bound(at.begin() + i, at.begin() + j, std::make_pair(at[i].first, m)) - (at.begin() + i));
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

    // ---- 7. edges: a glued pair shares one edge, everything else gets an outer half ------
    Scratch<std::uint32_t> halfedge_of_corner(nmc);
    std::uint32_t ne = 0;
    for (std::uint32_t m = 0; m < nmc; ++m) {
      const std::uint32_t t = mtwin[m];
      halfedge_of_corner[m] = (t == kInv || t > m) ? 2 * ne++ : halfedge_of_corner[t] ^ 1u;
    }
    const std::uint32_t* H = halfedge_of_corner.get();

    // ---- 8. connectivity of faces and boundary halves --------------------------------------
    Mesh& mesh = result_.mesh;
    mesh.resize(nv, ne, nmf);
    if (nv) std::memcpy(mesh.positions().data(), soup.positions.data(), nv * sizeof(Point));
    std::vector<std::uint32_t> incoming(nv, kInv);  // one inner half-edge pointing to v
    parallel_ranges(nmf, [&](std::size_t fbegin, std::size_t fend) {
      for (std::size_t fi = fbegin; fi < fend; ++fi) {
        const std::uint32_t b = moff[fi], e = moff[fi + 1];
        const Face f(static_cast<Index>(fi));
        mesh.set_halfedge(f, Halfedge(H[b]));
        std::uint32_t prev = e - 1;
        for (std::uint32_t m = b; m < e; ++m) {
          const Halfedge h(H[m]);
          mesh.set_vertex(h, Vertex(mvert[m]));
          mesh.set_face(h, f);
          mesh.set_next(Halfedge(H[prev]), h);
          if (mtwin[m] == kInv) mesh.set_vertex(opposite(h), Vertex(mvert[prev]));
          prev = m;
        }
      }
    });
    // The lowest corner's: halfedge(v) of a closed fan is its opposite, as in build_local().
    for (std::uint32_t m = static_cast<std::uint32_t>(nmc); m-- > 0;) incoming[mvert[m]] = H[m];
    mtwin = {};
    mtwin.shrink_to_fit();

    // ---- 9. fans: one per vertex is the fast path; the others are split below ----------------
    // Rotating around v through inner half-edges pointing to v: across next(h) to the
    // neighbour face. Boundary halves are not linked yet, but their face is invalid.
    std::vector<std::uint32_t> split_vertices[2];
    parallel_ranges(nv, [&](std::size_t vbegin, std::size_t vend) {
      auto& split = split_vertices[vbegin == 0 ? 0 : 1];
      for (std::size_t vi = vbegin; vi < vend; ++vi) {
        if (incoming[vi] == kInv) continue;
        const Halfedge h0(incoming[vi]);
        std::uint32_t count = 1;
        Halfedge h = h0, last = h0, first = h0;
        bool cycle = false;
        while (count <= uses[vi]) {
          const Halfedge t = opposite(mesh.next(h));
          if (!mesh.face(t).is_valid()) break;
          if (t == h0) {
            cycle = true;
            break;
          }
          h = t;
          ++count;
        }
        last = h;
        if (!cycle) {
          for (h = h0; count <= uses[vi];) {
            const Halfedge t = opposite(h);
            if (!mesh.face(t).is_valid()) break;
            h = mesh.prev(t);
            ++count;
          }
          first = h;
        }
        if (count != uses[vi]) {
          split.push_back(static_cast<std::uint32_t>(vi));
          continue;
        }
        const Vertex v(static_cast<Index>(vi));
        if (cycle) {
          mesh.set_halfedge(v, opposite(h0));
        } else {
          const Halfedge out = opposite(first), in = opposite(mesh.next(last));
          mesh.set_halfedge(v, out);
          mesh.set_next(in, out);
        }
      }
    });
    split_vertices[0].insert(split_vertices[0].end(), split_vertices[1].begin(), split_vertices[1].end());
    const std::vector<std::uint32_t>& split = split_vertices[0];

    if (!split.empty()) {
      // Every fan after the first (ordered by lowest corner) becomes a copy of the vertex.
      std::vector<std::uint8_t> marked(nv, 0);
      for (std::uint32_t v : split) marked[v] = 1;
      std::vector<std::pair<std::uint32_t, std::uint32_t>> at;  // (vertex, incoming inner half-edge)
      for (std::size_t fi = 0; fi < nmf; ++fi)
        for (Halfedge h : mesh.halfedges(Face(static_cast<Index>(fi))))
          if (marked[mesh.to_vertex(h).idx()]) at.emplace_back(mesh.to_vertex(h).idx(), h.idx());
      std::stable_sort(at.begin(), at.end(), [](auto& a, auto& b) { return a.first < b.first; });
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
          Halfedge h = h0;
          bool cycle = false;
          for (;;) {
            members.push_back(h);
            const Halfedge t = opposite(mesh.next(h));
            if (!mesh.face(t).is_valid()) break;
            if (t == h0) {
              cycle = true;
              break;
            }
            h = t;
          }
          const Halfedge last = h;
          Halfedge first = h0;
          if (!cycle)
            for (h = h0; mesh.face(opposite(h)).is_valid();) {
              h = mesh.prev(opposite(h));
              members.push_back(h);
              first = h;
            }
          std::uint32_t id = v;
          if (!first_fan) {
            id = static_cast<std::uint32_t>(nv + copy_source.size());
            copy_source.push_back(v);
          }
          first_fan = false;
          for (Halfedge m : members) {
            visited[m.idx()] = 1;
            mesh.set_vertex(m, Vertex(id));
          }
          if (cycle) {
            fans.push_back({id, opposite(h0), Halfedge()});
          } else {
            const Halfedge in = opposite(mesh.next(last));
            mesh.set_vertex(in, Vertex(id));
            fans.push_back({id, opposite(first), in});
          }
        }
        ++report.non_manifold_vertices;
        i = j;
      }
      add_copies(fans);
    }
    for (std::size_t v = 0; v < nv; ++v)
      if (!uses[v]) ++report.isolated_vertices;
    halfedge_of_corner_ = std::move(halfedge_of_corner);
  }

  // Attributes, provenance, maps and messages: the same for both paths.
  void finish() {
    Mesh& mesh = result_.mesh;
    BuildReport& report = result_.report;
    BuildMaps& maps = result_.maps;
    const std::size_t nmf = n_mesh_faces(), nmc = moff()[nmf];
    const std::uint32_t* H = halfedge_of_corner_.get();

    maps.vertex_source.resize(nv_ + copy_source_.size());
    for (std::size_t v = 0; v < nv_; ++v) maps.vertex_source[v] = static_cast<std::uint32_t>(v);
    std::copy(copy_source_.begin(), copy_source_.end(), maps.vertex_source.begin() + nv_);
    if (identity_) {
      maps.face_source.resize(nf_);
      for (std::size_t f = 0; f < nf_; ++f) maps.face_source[f] = static_cast<std::uint32_t>(f);
    } else {
      maps.face_source = face_source_;
    }

    for (const Channel& c : soup_.channels) {
      const std::size_t stride = c.stride();
      const std::byte* data = c.data.data();
      switch (c.domain) {
        case Domain::vertex: {
          ChannelArray* a = mesh.vertex_properties().add_channel(c.name, c.scalar, c.components);
          if (nv_) std::memcpy(a->element(0), data, nv_ * stride);
          for (std::size_t i = 0; i < copy_source_.size(); ++i)
            std::memcpy(a->element(nv_ + i), data + copy_source_[i] * stride, stride);
          break;
        }
        case Domain::face: {
          ChannelArray* a = mesh.face_properties().add_channel(c.name, c.scalar, c.components);
          if (identity_) {
            if (nf_) std::memcpy(a->element(0), data, nf_ * stride);
          } else {
            for (std::size_t fi = 0; fi < nmf; ++fi) std::memcpy(a->element(fi), data + face_source_[fi] * stride, stride);
          }
          break;
        }
        case Domain::corner: {
          // Corner data lives on the half-edge pointing to the corner; outer halves keep zeros.
          ChannelArray* a = mesh.halfedge_properties().add_channel(c.name, c.scalar, c.components);
          for (std::size_t m = 0; m < nmc; ++m)
            std::memcpy(a->element(H[m]), data + (identity_ ? m : msrc_[m]) * stride, stride);
          break;
        }
      }
    }
    halfedge_of_corner_.reset();

    // Provenance only where something changed: a clean build adds no arrays.
    if (!copy_source_.empty()) {
      auto source = mesh.add_vertex_property<std::uint32_t>("hedge:source", kInvalidIndex);
      source.vector() = maps.vertex_source;
    }
    if (!flipped_.empty()) {
      auto flip = mesh.add_face_property<bool>("hedge:flipped", false);
      for (std::size_t fi = 0; fi < nmf; ++fi) flip.vector()[fi] = flipped_[identity_ ? fi : face_source_[fi]] != 0;
    }
    if (has_repeats_) {  // these faces come back repeating their vertex (extract)
      auto repeats = mesh.add_face_property<bool>("hedge:repeats", false);
      for (std::size_t fi = 0; fi < nmf; ++fi)
        repeats.vector()[fi] = status_[identity_ ? fi : face_source_[fi]] == kFaceRepeats;
    }
    if (has_skipped_) {
      auto source = mesh.add_face_property<std::uint32_t>("hedge:source", kInvalidIndex);
      source.vector() = face_source_;
    }
    // Appending the copies grew the vertex arrays with slack.
    if (!copy_source_.empty()) mesh.shrink_to_fit();

    auto say = [&](std::string line) { report.messages.push_back(std::move(line)); };
    if (report.skipped_faces)
      say("skipped " + plural(report.skipped_faces, "face", "faces") + " with fewer than 3 distinct vertices");
    if (report.repeated_vertex_faces)
      say(plural(report.repeated_vertex_faces, "face visits", "faces visit") +
          " a vertex more than once; their corners were given separate vertices" +
          (n_repeat_cuts_ ? " (" + plural(n_repeat_cuts_, "edge", "edges") + " unglued)" : std::string()));
    if (report.flipped_faces)
      say("flipped " + plural(report.flipped_faces, "face", "faces") + " to orient consistently (" +
          plural(n_glued_by_flip_, "edge", "edges") + " glued)");
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

  const Soup& soup_;
  const BuildOptions& options_;
  const std::size_t nv_, nf_, nc_;
  const std::uint32_t* corner_;
  BuildResult result_;

  std::vector<std::uint32_t> soff_;   // soup face -> first corner
  std::vector<std::uint8_t> status_;  // kFaceOk, kFaceRepeats or kFaceSkipped
  std::size_t fmid_ = 0;              // the faces are classified in two halves, split here
  std::vector<std::uint32_t> vertex_corners_[2];  // corners per vertex in built faces, per half
  bool has_repeats_ = false, has_skipped_ = false;

  // Mesh corners: the soup's corners minus skipped faces, flipped faces as c0, cn-1, ..., c1.
  bool identity_ = true;                  // mesh corners are the soup's; the arrays below stay empty
  std::vector<std::uint32_t> moff_;       // mesh face -> first mesh corner
  std::vector<std::uint32_t> msrc_;       // mesh corner -> soup corner
  std::vector<std::uint32_t> face_source_;  // mesh face -> soup face
  std::vector<std::uint8_t> flipped_;     // per soup face; empty when nothing flipped
  Scratch<std::uint32_t> halfedge_of_corner_;  // mesh corner -> half-edge pointing to it
  std::vector<std::uint32_t> copy_source_;  // mesh vertex nv_ + i copies soup vertex copy_source_[i]
  std::size_t n_repeat_cuts_ = 0, n_glued_by_flip_ = 0;
};

}  // namespace

BuildResult build(const Soup& soup, const BuildOptions& options) {
  soup.check();
  for (const Channel& c : soup.channels)
    if (c.name.rfind("hedge:", 0) == 0)
      throw Error("soup: " + std::string(domain_name(c.domain)) + " channel '" + c.name +
                  "' uses the prefix 'hedge:', which is reserved for the mesh's own bookkeeping");
  // Every corner is a half-edge, and its edge may need an outer one; each corner may
  // become a vertex copy.
  static_assert(kMaxCorners < kDirBit, "corner ids must leave the matching's direction bit free");
  check_limit("soup too large", soup.n_corners(), kMaxCorners, "corners");
  check_limit("soup too large", soup.n_faces(), kMaxElements, "faces");
  check_limit("soup too large", std::uint64_t{soup.n_vertices()} + soup.n_corners(), kMaxElements,
              "vertices with their possible copies (vertices plus corners)");
  return Builder(soup, options).run();
}

namespace {

// An operation can bring two copies of one source vertex into one face (a hole filled
// across a split non-manifold vertex, a collapse next to a copy); welding them would make
// the face visit a vertex twice, which no host can hold. Faces whose input did so
// ("hedge:repeats") weld as they came; in every other face such copies stay separate:
// in each face, of the corners that weld to one output vertex only one keeps welding (the
// group's representative `order[out]` when it is there, never a copy already kept apart).
// Marks only grow and kept-apart copies get their own indices, so one pass settles every
// face. Returns the copies to keep apart, in mesh order.
std::vector<std::uint32_t> copies_kept_apart(const Mesh& mesh, const std::vector<std::uint32_t>& vmap,
                                             const std::vector<std::uint32_t>& order) {
  std::vector<char> apart(mesh.vertices_size(), 0);
  std::vector<std::pair<std::uint32_t, std::uint32_t>> corners;  // (output vertex, mesh vertex)
  const TypedArray<bool>* repeats = mesh.face_properties().get<bool>("hedge:repeats");
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
      options.restore_source ? mesh.vertex_properties().get<std::uint32_t>("hedge:source") : nullptr;
  const TypedArray<bool>* flipped = options.restore_source ? mesh.face_properties().get<bool>("hedge:flipped") : nullptr;
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

  soup.positions.resize(n_out_vertices);
  if (vertices_identity) {
    if (nvs) std::memcpy(soup.positions.data(), mesh.positions().data(), nvs * sizeof(Point));
  } else {
    for (std::size_t i = 0; i < n_out_vertices; ++i) soup.positions[i] = mesh.positions()[order[i]];
  }

  // Faces and corners; corner_halfedge remembers where each corner's data lives.
  const std::size_t nfs = mesh.faces_size();
  const bool faces_identity = mesh.n_faces() == nfs;
  soup.face_sizes.reserve(mesh.n_faces());
  std::size_t n_inner = 0;
  for (Halfedge h : mesh.halfedges())
    if (!mesh.is_boundary(h)) ++n_inner;
  soup.corners.reserve(n_inner);
  bool has_corner_channels = false;
  const PropertyContainer& hprops = mesh.halfedge_properties();
  for (std::size_t i = 0; i < hprops.count(); ++i) has_corner_channels |= hprops.at(i).type() == typeid(ChannelArray);
  std::vector<std::uint32_t> corner_halfedge;
  if (has_corner_channels) corner_halfedge.reserve(n_inner);
  std::vector<Halfedge> loop;
  for (Face f : mesh.faces()) {
    loop.clear();
    for (Halfedge h : mesh.halfedges(f)) loop.push_back(h);
    // Undo build()'s flip: c0, cn-1, ..., c1 is its own inverse.
    if (flipped && flipped->vector()[f.idx()]) std::reverse(loop.begin() + 1, loop.end());
    soup.face_sizes.push_back(static_cast<std::uint32_t>(loop.size()));
    for (Halfedge h : loop) {
      const std::uint32_t v = mesh.to_vertex(h).idx();
      soup.corners.push_back(vertices_identity ? v : vmap[v]);
      if (has_corner_channels) corner_halfedge.push_back(h.idx());
    }
  }

  // Attributes: every ChannelArray; TypedArrays are the mesh's own and stay inside.
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
            for (std::size_t k = 0; k < n_out_vertices; ++k) std::memcpy(c.data.data() + k * stride, a.element(mesh_vertex(k)), stride);
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
          for (std::size_t k = 0; k < corner_halfedge.size(); ++k)
            std::memcpy(c.data.data() + k * stride, a.element(corner_halfedge[k]), stride);
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
