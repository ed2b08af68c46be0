// build(): any soup -> a manifold half-edge mesh (splitting, orienting, recording where
// everything came from); extract(): mesh -> soup, undoing build()'s repairs.
#include "hedge/build.h"

#include <algorithm>
#include <cstring>
#include <memory>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "hedge/error.h"

namespace hedge {
namespace {

constexpr std::uint32_t kInv = kInvalidIndex;
// Corner-edge ids carry their direction in the top bit inside the matching buckets, so
// a soup may hold at most 2^31 - 1 corners (far beyond what fits in memory anyway).
constexpr std::uint32_t kDirBit = 0x80000000u;

constexpr std::uint8_t kFaceOk = 0, kFaceRepeats = 1, kFaceSkipped = 2;

// Runs fn(begin, end) over [0, n) on two threads when n is large enough to pay for
// starting one; the split point is fixed, so results do not depend on timing.
template <class Fn>
void parallel_ranges(std::size_t n, Fn&& fn) {
  constexpr std::size_t kMinParallel = std::size_t(1) << 16;
  if (n < kMinParallel || std::thread::hardware_concurrency() < 2) {
    fn(std::size_t(0), n);
    return;
  }
  const std::size_t mid = n / 2;
  std::thread other([&] { fn(mid, n); });
  fn(std::size_t(0), mid);
  other.join();
}

// Big scratch arrays whose every element is written before it is read: skip the zero fill.
template <class T>
std::unique_ptr<T[]> scratch(std::size_t n) {
  return std::make_unique_for_overwrite<T[]>(n);
}

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

}  // namespace

BuildResult build(const Soup& soup, const BuildOptions& options) {
  soup.check();
  for (const Channel& c : soup.channels)
    if (c.name.rfind("hedge:", 0) == 0)
      throw Error("soup: " + std::string(domain_name(c.domain)) + " channel '" + c.name +
                  "' uses the prefix 'hedge:', which is reserved for the mesh's own bookkeeping");
  const std::size_t nv = soup.n_vertices(), nf = soup.n_faces(), nc = soup.n_corners();
  if (nc >= kDirBit || nv + nc >= kInv || nf >= kInv)
    throw Error("soup too large: " + std::to_string(nv) + " vertices and " + std::to_string(nc) +
                " corners do not fit the mesh's 32-bit indices");
  const std::uint32_t* corner = soup.corners.data();

  BuildResult result;
  BuildReport& report = result.report;
  BuildMaps& maps = result.maps;

  // ---- 1. faces: offsets, and which ones repeat a vertex or are too degenerate to build --
  std::vector<std::uint32_t> soff(nf + 1);
  std::vector<std::uint8_t> status(nf, kFaceOk);
  {
    std::vector<std::uint32_t> buffer;
    std::uint32_t offset = 0;
    for (std::size_t f = 0; f < nf; ++f) {
      soff[f] = offset;
      const std::uint32_t size = soup.face_sizes[f];
      const std::uint32_t distinct = distinct_count(corner + offset, size, buffer);
      if (distinct < 3) {
        status[f] = kFaceSkipped;
        maps.skipped_faces.push_back(static_cast<std::uint32_t>(f));
      } else if (distinct < size) {
        status[f] = kFaceRepeats;
        ++report.repeated_vertex_faces;
      }
      offset += size;
    }
    soff[nf] = offset;
  }
  report.skipped_faces = maps.skipped_faces.size();
  const bool has_repeats = report.repeated_vertex_faces > 0;
  const bool has_skipped = report.skipped_faces > 0;

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
  auto entries = scratch<BucketEntry>(n_entries);
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
    if (n_entries >= (std::size_t(1) << 16) && std::thread::hardware_concurrency() >= 2) {
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
  std::vector<std::uint8_t> flipped;  // per soup face; empty when nothing flips
  std::size_t n_glued_by_flip = 0;
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
  std::vector<std::uint32_t> moff_storage, mvert_storage, msrc, face_source;
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
  std::size_t n_repeat_cuts = 0;
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
  auto halfedge_of_corner = scratch<std::uint32_t>(nmc);
  std::uint32_t ne = 0;
  for (std::uint32_t m = 0; m < nmc; ++m) {
    const std::uint32_t t = mtwin[m];
    halfedge_of_corner[m] = (t == kInv || t > m) ? 2 * ne++ : halfedge_of_corner[t] ^ 1u;
  }
  const std::uint32_t* H = halfedge_of_corner.get();

  // ---- 8. connectivity of faces and boundary halves --------------------------------------
  Mesh& mesh = result.mesh;
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
  for (std::uint32_t m = 0; m < nmc; ++m) incoming[mvert[m]] = H[m];
  halfedge_of_corner.reset();
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
        mesh.set_halfedge(v, mesh.next(h0));
      } else {
        const Halfedge out = opposite(first), in = opposite(mesh.next(last));
        mesh.set_halfedge(v, out);
        mesh.set_next(in, out);
      }
    }
  });
  split_vertices[0].insert(split_vertices[0].end(), split_vertices[1].begin(), split_vertices[1].end());
  const std::vector<std::uint32_t>& split = split_vertices[0];

  std::vector<std::uint32_t> copy_source;  // source of vertex nv + i
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
    struct Fan {
      std::uint32_t vertex;
      Halfedge out, in;  // boundary halves leaving / entering; `in` invalid for a closed fan
    };
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
          fans.push_back({id, mesh.next(h0), Halfedge()});
        } else {
          const Halfedge in = opposite(mesh.next(last));
          mesh.set_vertex(in, Vertex(id));
          fans.push_back({id, opposite(first), in});
        }
      }
      ++report.non_manifold_vertices;
      i = j;
    }
    report.vertex_copies = copy_source.size();
    if (!copy_source.empty()) {
      mesh.resize(nv + copy_source.size(), ne, nmf);
      for (std::size_t i = 0; i < copy_source.size(); ++i) mesh.positions()[nv + i] = soup.positions[copy_source[i]];
    }
    for (const Fan& fan : fans) {
      mesh.set_halfedge(Vertex(fan.vertex), fan.out);
      if (fan.in.is_valid()) mesh.set_next(fan.in, fan.out);
    }
  }
  // The outer halves are linked now; their vertices too (set_vertex above) — except the
  // `from` side of an outer half, which is the target of its inner twin: already right.
  for (std::size_t v = 0; v < nv; ++v)
    if (!uses[v]) ++report.isolated_vertices;

  // ---- 10. attributes and provenance ----------------------------------------------------
  const std::size_t n_mesh_vertices = nv + copy_source.size();
  maps.vertex_source.resize(n_mesh_vertices);
  for (std::size_t v = 0; v < nv; ++v) maps.vertex_source[v] = static_cast<std::uint32_t>(v);
  std::copy(copy_source.begin(), copy_source.end(), maps.vertex_source.begin() + nv);
  if (identity) {
    maps.face_source.resize(nf);
    for (std::size_t f = 0; f < nf; ++f) maps.face_source[f] = static_cast<std::uint32_t>(f);
  } else {
    maps.face_source = face_source;
  }

  // The corner -> half-edge map is needed again for corner channels: rebuild it from the
  // face loops (cheaper than keeping it alive for meshes without corner channels).
  bool has_corner_channels = false;
  for (const Channel& c : soup.channels) has_corner_channels |= c.domain == Domain::corner;
  std::vector<std::uint32_t> corner_halfedge;
  if (has_corner_channels) {
    corner_halfedge.resize(nmc);
    parallel_ranges(nmf, [&](std::size_t fbegin, std::size_t fend) {
      for (std::size_t fi = fbegin; fi < fend; ++fi) {
        Halfedge h = mesh.halfedge(Face(static_cast<Index>(fi)));
        for (std::uint32_t m = moff[fi]; m < moff[fi + 1]; ++m, h = mesh.next(h)) corner_halfedge[m] = h.idx();
      }
    });
  }
  for (const Channel& c : soup.channels) {
    const std::size_t stride = c.stride();
    switch (c.domain) {
      case Domain::vertex: {
        ChannelArray* a = mesh.vertex_properties().add_channel(c.name, c.scalar, c.components);
        if (nv) std::memcpy(a->element(0), c.data.data(), nv * stride);
        for (std::size_t i = 0; i < copy_source.size(); ++i)
          std::memcpy(a->element(nv + i), c.data.data() + copy_source[i] * stride, stride);
        break;
      }
      case Domain::face: {
        ChannelArray* a = mesh.face_properties().add_channel(c.name, c.scalar, c.components);
        if (identity) {
          if (nf) std::memcpy(a->element(0), c.data.data(), nf * stride);
        } else {
          for (std::size_t fi = 0; fi < nmf; ++fi)
            std::memcpy(a->element(fi), c.data.data() + face_source[fi] * stride, stride);
        }
        break;
      }
      case Domain::corner: {
        ChannelArray* a = mesh.halfedge_properties().add_channel(c.name, c.scalar, c.components);
        for (std::size_t m = 0; m < nmc; ++m)
          std::memcpy(a->element(corner_halfedge[m]), c.data.data() + (identity ? m : msrc[m]) * stride, stride);
        break;
      }
    }
  }
  if (!copy_source.empty()) {
    auto source = mesh.add_vertex_property<std::uint32_t>("hedge:source", kInvalidIndex);
    source.vector() = maps.vertex_source;
  }
  if (!flipped.empty()) {
    auto flip = mesh.add_face_property<bool>("hedge:flipped", false);
    for (std::size_t fi = 0; fi < nmf; ++fi) flip.vector()[fi] = flipped[identity ? fi : face_source[fi]] != 0;
  }
  if (has_skipped) {
    auto source = mesh.add_face_property<std::uint32_t>("hedge:source", kInvalidIndex);
    source.vector() = face_source;
  }
  if (!copy_source.empty()) mesh.shrink_to_fit();

  // ---- 11. messages ---------------------------------------------------------------------
  auto say = [&](std::string line) { report.messages.push_back(std::move(line)); };
  if (report.skipped_faces)
    say("skipped " + plural(report.skipped_faces, "face", "faces") + " with fewer than 3 distinct vertices");
  if (report.repeated_vertex_faces)
    say(plural(report.repeated_vertex_faces, "face visits", "faces visit") +
        " a vertex more than once; their corners were given separate vertices" +
        (n_repeat_cuts ? " (" + plural(n_repeat_cuts, "edge", "edges") + " unglued)" : std::string()));
  if (report.flipped_faces)
    say("flipped " + plural(report.flipped_faces, "face", "faces") + " to orient consistently (" +
        plural(n_glued_by_flip, "edge", "edges") + " glued)");
  if (report.unorientable_edges)
    say("cut " + plural(report.unorientable_edges, "edge", "edges") + " where the surface cannot be oriented");
  if (report.non_manifold_edges)
    say("split " + plural(report.non_manifold_edges, "non-manifold edge", "non-manifold edges"));
  if (report.non_manifold_vertices)
    say("split " + plural(report.non_manifold_vertices, "non-manifold vertex", "non-manifold vertices") + " into " +
        plural(report.vertex_copies, "extra copy", "extra copies"));
  if (report.isolated_vertices)
    say("kept " + plural(report.isolated_vertices, "isolated vertex", "isolated vertices") + " no face uses");
  return result;
}

Soup extract(const Mesh& mesh, const ExtractOptions& options) {
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
    for (Vertex v : mesh.vertices())
      if (vmap[v.idx()] == kInv) {
        vmap[v.idx()] = n_out++;
        order.push_back(v.idx());
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
