// The repair operation: keeps build()'s manifold splits and orientation, and removes
// degenerate and duplicate faces, near-duplicate vertices, pinches and isolated vertices.
#include "hedge/repair.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <numeric>
#include <utility>
#include <vector>

#include "hedge/build.h"
#include "hedge/error.h"
#include "hedge/provenance.h"
#include "hedge/soup.h"
#include "binding.h"
#include "text.h"

namespace hedge {
namespace {

//! The channel's values of the `kept` elements, in that order.
void keep_elements(Channel& channel, const std::vector<std::uint32_t>& kept) {
  const std::size_t stride = channel.stride();
  std::vector<std::byte> data(kept.size() * stride);
  for (std::size_t i = 0; i < kept.size(); ++i)
    std::copy_n(channel.data.begin() + std::ptrdiff_t(kept[i] * stride), stride, data.begin() + std::ptrdiff_t(i * stride));
  channel.data = std::move(data);
}

using detail::plural;

std::string number(double x) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%g", x);
  return buffer;
}

// ---- provenance ---------------------------------------------------------------------------

using provenance::kFaceSource;
using provenance::kFlipped;
using provenance::kVertexSource;

//! The soup vertex a mesh vertex came from; vertices build() did not make get ids of their own.
class SourceOf {
 public:
  explicit SourceOf(const Mesh& mesh) : source_(mesh.vertex_properties().get<std::uint32_t>(kVertexSource)) {}
  std::uint64_t operator()(Vertex v) const {
    if (source_) {
      const std::uint32_t s = source_->vector()[v.idx()];
      if (s != kInvalidIndex) return s;
    }
    return (std::uint64_t(1) << 32) + v.idx();
  }
  bool has_copies() const { return source_ != nullptr; }

 private:
  const TypedArray<std::uint32_t>* source_;
};

void drop_provenance(Mesh& mesh) {
  mesh.vertex_properties().remove(kVertexSource);
  mesh.face_properties().remove(kFaceSource);
  mesh.face_properties().remove(kFlipped);
}

// ---- duplicate faces ------------------------------------------------------------------------

//! Faces given as sizes + corner ids; returns, per face, whether an earlier face has the
//! same set of ids (so it can go). Faces are sorted by a hash of their sorted ids; only
//! equal hashes compare the ids themselves.
std::vector<char> later_duplicates(const std::vector<std::uint32_t>& sizes, const std::vector<std::uint64_t>& ids) {
  const std::size_t nf = sizes.size();
  std::vector<std::size_t> offset(nf + 1, 0);
  for (std::size_t f = 0; f < nf; ++f) offset[f + 1] = offset[f] + sizes[f];
  std::vector<std::uint64_t> sorted = ids;
  std::vector<std::pair<std::uint64_t, std::uint32_t>> keys(nf);
  for (std::size_t f = 0; f < nf; ++f) {
    auto first = sorted.begin() + std::ptrdiff_t(offset[f]), last = sorted.begin() + std::ptrdiff_t(offset[f + 1]);
    std::sort(first, last);
    std::uint64_t h = 0x9e3779b97f4a7c15ull ^ sizes[f];
    for (auto it = first; it != last; ++it) h = (h ^ *it) * 0x100000001b3ull + (h >> 29);
    keys[f] = {h, static_cast<std::uint32_t>(f)};
  }
  std::sort(keys.begin(), keys.end());  // equal hashes: by face index, so the earliest comes first
  auto same = [&](std::uint32_t a, std::uint32_t b) {
    return sizes[a] == sizes[b] &&
           std::equal(sorted.begin() + std::ptrdiff_t(offset[a]), sorted.begin() + std::ptrdiff_t(offset[a + 1]),
                      sorted.begin() + std::ptrdiff_t(offset[b]));
  };
  std::vector<char> drop(nf, 0);
  for (std::size_t i = 0; i < nf;) {
    std::size_t j = i + 1;
    while (j < nf && keys[j].first == keys[i].first) ++j;
    for (std::size_t k = i + 1; k < j; ++k)  // a run is almost always one face, or true duplicates
      for (std::size_t m = i; m < k; ++m)
        if (!drop[keys[m].second] && same(keys[m].second, keys[k].second)) {
          drop[keys[k].second] = 1;
          break;
        }
    i = j;
  }
  return drop;
}

std::size_t count_true(const std::vector<char>& v) {
  return static_cast<std::size_t>(std::count(v.begin(), v.end(), 1));
}

//! Calls fn(first, last) for each group of 2+ edges whose end vertices have the same two
//! ids (id per vertex index, all below n_ids), as a range of Edge. Counting sort by the
//! smaller id, then a small sort per bucket: O(edges). Needs no vertex fans, so it works
//! on a mesh where a deletion left a vertex with two.
template <class Fn>
void for_each_multi_edge(const Mesh& mesh, const std::vector<std::uint32_t>& id, std::size_t n_ids, Fn fn) {
  std::vector<std::uint32_t> start(n_ids + 1, 0);
  for (Edge e : mesh.edges()) ++start[std::min(id[mesh.vertex(e, 0).idx()], id[mesh.vertex(e, 1).idx()])];
  std::uint32_t sum = 0;
  for (std::size_t i = 0; i <= n_ids; ++i) {
    const std::uint32_t count = i < n_ids ? start[i] : 0;
    start[i] = sum;
    sum += count;
  }
  std::vector<std::pair<std::uint32_t, Edge>> bucket(sum);  // (larger id, edge)
  {
    std::vector<std::uint32_t> cursor(start.begin(), start.end() - 1);
    for (Edge e : mesh.edges()) {
      const std::uint32_t a = id[mesh.vertex(e, 0).idx()], b = id[mesh.vertex(e, 1).idx()];
      bucket[cursor[std::min(a, b)]++] = {std::max(a, b), e};
    }
  }
  std::vector<Edge> group;
  for (std::size_t i = 0; i < n_ids; ++i) {
    if (start[i + 1] - start[i] < 2) continue;
    auto first = bucket.begin() + start[i], last = bucket.begin() + start[i + 1];
    std::sort(first, last);
    for (auto it = first; it != last;) {
      auto end = it + 1;
      while (end != last && end->first == it->first) ++end;
      if (end - it > 1) {
        group.clear();
        for (auto k = it; k != end; ++k) group.push_back(k->second);
        fn(group);
      }
      it = end;
    }
  }
}

//! Per face of the mesh, in order: 1 when an earlier face has the same vertex set, vertices
//! named by `id` (build()'s source, or the mesh vertex itself).
template <class VertexId>
std::vector<char> later_duplicate_faces(const Mesh& mesh, VertexId id) {
  std::vector<std::uint32_t> sizes;
  std::vector<std::uint64_t> ids;
  for (Face f : mesh.faces()) {
    sizes.push_back(static_cast<std::uint32_t>(mesh.valence(f)));
    for (Vertex v : mesh.vertices(f)) ids.push_back(id(v));
  }
  return later_duplicates(sizes, ids);
}

bool has_duplicate_faces(const Mesh& mesh) {
  const SourceOf source(mesh);
  return count_true(later_duplicate_faces(mesh, [&](Vertex v) { return source(v); })) > 0;
}

// ---- soup editing ---------------------------------------------------------------------------

//! Keeps the faces with keep[f] != 0; face and corner channels follow.
void keep_faces(Soup& soup, const std::vector<char>& keep) {
  const auto offset = soup.face_offsets();
  std::vector<std::uint32_t> sizes, corners, kept_faces, kept_corners;
  for (std::size_t f = 0; f < soup.n_faces(); ++f) {
    if (!keep[f]) continue;
    kept_faces.push_back(static_cast<std::uint32_t>(f));
    sizes.push_back(soup.face_sizes[f]);
    for (std::size_t c = offset[f]; c < offset[f + 1]; ++c) {
      corners.push_back(soup.corners[c]);
      kept_corners.push_back(static_cast<std::uint32_t>(c));
    }
  }
  for (Channel& channel : soup.channels) {
    if (channel.domain == Domain::vertex) continue;
    keep_elements(channel, channel.domain == Domain::face ? kept_faces : kept_corners);
  }
  soup.face_sizes = std::move(sizes);
  soup.corners = std::move(corners);
}

class UnionFind {
 public:
  explicit UnionFind(std::size_t n) : parent_(n) { std::iota(parent_.begin(), parent_.end(), 0u); }
  std::uint32_t find(std::uint32_t i) {
    while (parent_[i] != i) i = parent_[i] = parent_[parent_[i]];
    return i;
  }
  //! The smaller index becomes the root, so every set is named by its first vertex.
  bool unite(std::uint32_t a, std::uint32_t b) {
    a = find(a);
    b = find(b);
    if (a == b) return false;
    if (a < b) std::swap(a, b);
    parent_[a] = b;
    return true;
  }

 private:
  std::vector<std::uint32_t> parent_;
};

//! Merges vertices at most `distance` apart (transitively) into the first of each group,
//! which keeps its position and attributes; returns how many vertices went. Vertices are
//! sorted into cells of side distance / sqrt(3), so that a cell's vertices are all within
//! reach of each other and only the cells two steps around need distance tests.
std::size_t weld(Soup& soup, double distance) {
  const std::size_t n = soup.n_vertices();
  if (n < 2 || !(distance > 0)) return 0;
  std::array<double, 3> lo, hi;
  lo.fill(std::numeric_limits<double>::infinity());
  hi.fill(-std::numeric_limits<double>::infinity());
  for (const Point& p : soup.positions)
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], double(p[k]));
      hi[k] = std::max(hi[k], double(p[k]));
    }
  const double extent = std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]});
  // Cells finer than the float grid of the coordinates are pointless and would overflow
  // the cell numbers; then a cell no longer guarantees closeness and pairs are tested.
  const double cell = std::max(distance / std::sqrt(3.0), extent * 1e-12);
  const bool cell_is_close = cell * std::sqrt(3.0) <= distance;
  const int reach = static_cast<int>(std::ceil(distance / cell));
  const double d2 = distance * distance;

  struct Entry {
    std::array<std::int64_t, 3> cell;
    std::uint32_t vertex;
  };
  std::vector<Entry> entries(n);
  for (std::uint32_t v = 0; v < n; ++v) {
    entries[v].vertex = v;
    for (int k = 0; k < 3; ++k)
      entries[v].cell[k] = static_cast<std::int64_t>(std::floor((double(soup.positions[v][k]) - lo[k]) / cell));
  }
  std::sort(entries.begin(), entries.end(),
            [](const Entry& a, const Entry& b) { return a.cell != b.cell ? a.cell < b.cell : a.vertex < b.vertex; });
  std::vector<std::size_t> start;  // first entry of each occupied cell
  for (std::size_t i = 0; i < n; ++i)
    if (i == 0 || entries[i].cell != entries[i - 1].cell) start.push_back(i);
  start.push_back(n);

  UnionFind sets(n);
  auto close = [&](std::uint32_t a, std::uint32_t b) {
    double s = 0;
    for (int k = 0; k < 3; ++k) {
      double d = double(soup.positions[a][k]) - double(soup.positions[b][k]);
      s += d * d;
    }
    return s <= d2;
  };
  const std::size_t n_cells = start.size() - 1;
  auto key = [&](std::size_t c) -> const std::array<std::int64_t, 3>& { return entries[start[c]].cell; };
  // Cells are visited in sorted order, so for each column offset (dx, dy) the first cell
  // at or after (x + dx, y + dy, z - reach) only moves forward: one cursor per offset.
  const int side = 2 * reach + 1;
  std::vector<std::size_t> cursor(std::size_t(side * side), 0);
  for (std::size_t a = 0; a < n_cells; ++a) {
    const std::size_t a0 = start[a], a1 = start[a + 1];
    for (std::size_t i = a0 + 1; i < a1; ++i)
      if (cell_is_close)
        sets.unite(entries[a0].vertex, entries[i].vertex);
      else
        for (std::size_t j = a0; j < i; ++j)
          if (close(entries[i].vertex, entries[j].vertex)) sets.unite(entries[i].vertex, entries[j].vertex);
    const auto& ka = key(a);
    for (int dx = -reach; dx <= reach; ++dx)
      for (int dy = -reach; dy <= reach; ++dy) {
        std::size_t& q = cursor[std::size_t((dx + reach) * side + dy + reach)];
        const std::array<std::int64_t, 3> from{ka[0] + dx, ka[1] + dy, ka[2] - reach};
        while (q < n_cells && key(q) < from) ++q;
        for (std::size_t b = q;
             b < n_cells && key(b)[0] == from[0] && key(b)[1] == from[1] && key(b)[2] <= ka[2] + reach; ++b) {
          if (b <= a) continue;  // each pair of cells once
          const std::size_t b0 = start[b], b1 = start[b + 1];
          if (cell_is_close && sets.find(entries[a0].vertex) == sets.find(entries[b0].vertex)) continue;
          bool joined = false;
          for (std::size_t i = a0; i < a1 && !joined; ++i)
            for (std::size_t j = b0; j < b1 && !joined; ++j)
              if (close(entries[i].vertex, entries[j].vertex)) {
                sets.unite(entries[i].vertex, entries[j].vertex);
                joined = cell_is_close;  // both cells are one set already: one pair is enough
              }
        }
      }
  }

  // Compact: the first vertex of each set stays, in order.
  std::vector<std::uint32_t> new_index(n), kept;
  for (std::uint32_t v = 0; v < n; ++v)
    if (sets.find(v) == v) {
      new_index[v] = static_cast<std::uint32_t>(kept.size());
      kept.push_back(v);
    }
  if (kept.size() == n) return 0;
  for (std::uint32_t v = 0; v < n; ++v) new_index[v] = new_index[sets.find(v)];
  for (std::uint32_t& c : soup.corners) c = new_index[c];
  std::vector<Point> positions(kept.size());
  for (std::size_t i = 0; i < kept.size(); ++i) positions[i] = soup.positions[kept[i]];
  soup.positions = std::move(positions);
  for (Channel& channel : soup.channels)
    if (channel.domain == Domain::vertex) keep_elements(channel, kept);
  return n - kept.size();
}

// ---- mesh steps -----------------------------------------------------------------------------

double face_area(const Mesh& mesh, Face f) {
  Halfedge h0 = mesh.halfedge(f);
  Vec3d p0 = to_double(mesh.position(mesh.to_vertex(h0)));
  Vec3d normal{};
  for (Halfedge h = mesh.next(h0); mesh.next(h) != h0; h = mesh.next(h))
    normal += cross(to_double(mesh.position(mesh.to_vertex(h))) - p0,
                    to_double(mesh.position(mesh.to_vertex(mesh.next(h)))) - p0);
  return 0.5 * norm(normal);
}

//! Zero-area faces (relative to the bounding box, as the report operation counts them):
//! collapse the shortest edge that may collapse; faces where none may are deleted at the
//! end (deleting can leave a vertex with two fans, which collapses must not meet). Returns
//! the faces handled and, through `deleted`, how many of them were deleted.
std::size_t remove_degenerate_faces(Mesh& mesh, std::size_t& deleted, Progress& progress) {
  Vec3d lo{}, hi{};
  bool first = true;
  for (Vertex v : mesh.vertices()) {
    Vec3d p = to_double(mesh.position(v));
    for (int k = 0; k < 3; ++k) {
      lo[k] = first ? p[k] : std::min(lo[k], p[k]);
      hi[k] = first ? p[k] : std::max(hi[k], p[k]);
    }
    first = false;
  }
  const double diagonal = distance(lo, hi);
  const double threshold = 1e-12 * std::max(diagonal * diagonal, 1e-300);
  auto degenerate = [&](Face f) { return !mesh.is_deleted(f) && face_area(mesh, f) <= threshold; };

  std::vector<char> counted(mesh.faces_size(), 0);
  std::size_t handled = 0;
  std::vector<std::pair<double, Halfedge>> sides;
  const Index nf = static_cast<Index>(mesh.faces_size());
  // A collapse can make a neighbour degenerate (or leave a polygon so): repeat until stable.
  for (int pass = 0; pass < 100; ++pass) {
    bool changed = false;
    for (Index i = 0; i < nf; ++i) {
      const Face f(i);
      if (!degenerate(f)) continue;
      if (!counted[i]) {
        counted[i] = 1;
        ++handled;
      }
      sides.clear();
      for (Halfedge h : mesh.halfedges(f))
        sides.emplace_back(
            distance(to_double(mesh.position(mesh.from_vertex(h))), to_double(mesh.position(mesh.to_vertex(h)))), h);
      std::stable_sort(sides.begin(), sides.end(), [](auto& a, auto& b) { return a.first < b.first; });
      for (auto [length, h] : sides) {
        // Keep the boundary vertex where there is one, so the border does not move.
        Halfedge c = mesh.is_boundary(mesh.from_vertex(h)) ? Mesh::opposite(h) : h;
        if (!mesh.is_collapse_ok(c)) c = Mesh::opposite(c);
        if (!mesh.is_collapse_ok(c)) continue;
        mesh.collapse(c);
        changed = true;
        break;
      }
    }
    if (!changed) break;
    progress.update(0.6, "removing degenerate faces");
  }
  for (Index i = 0; i < nf; ++i)
    if (degenerate(Face(i))) {
      if (!counted[i]) ++handled;
      mesh.delete_face(Face(i));
      ++deleted;
    }
  return handled;
}

//! A non-manifold edge whose extra face stays attached at both ends leaves two edges
//! between the same two vertices: fine for half-edges, but a soup (vertex lists) would
//! glue them back into a non-manifold edge. Keep one edge (an interior one if any) and
//! remove the faces of the others. Returns the faces removed.
std::size_t remove_pinches(Mesh& mesh) {
  std::vector<std::uint32_t> id(mesh.vertices_size());
  std::iota(id.begin(), id.end(), 0u);
  std::vector<Face> doomed;
  for_each_multi_edge(mesh, id, id.size(), [&](const std::vector<Edge>& group) {
    std::size_t keep = 0;
    for (std::size_t k = 0; k < group.size(); ++k)
      if (!mesh.is_boundary(group[k])) {
        keep = k;
        break;
      }
    for (std::size_t k = 0; k < group.size(); ++k)
      if (k != keep)
        for (unsigned side = 0; side < 2; ++side)
          if (Face f = mesh.face(group[k], side); f.is_valid()) doomed.push_back(f);
  });
  std::sort(doomed.begin(), doomed.end());
  doomed.erase(std::unique(doomed.begin(), doomed.end()), doomed.end());
  for (Face f : doomed) mesh.delete_face(f);
  return doomed.size();
}

//! Collapses can leave two faces over one vertex set (a pillow of two faces glued on every
//! edge, say), which extract() would hand on as a duplicate face: the later ones go.
//! Returns the faces removed.
std::size_t remove_duplicate_faces(Mesh& mesh) {
  std::vector<Face> faces;
  for (Face f : mesh.faces()) faces.push_back(f);
  const std::vector<char> drop = later_duplicate_faces(mesh, [](Vertex v) { return v.idx(); });
  for (std::size_t i = 0; i < faces.size(); ++i)
    if (drop[i]) mesh.delete_face(faces[i]);
  return count_true(drop);
}

void say(RepairReport& r, std::size_t n, const std::string& what) {
  if (n) r.messages.push_back(what);
}

}  // namespace

BuildRepairs build_repairs(const Mesh& mesh) {
  BuildRepairs r;
  const SourceOf source(mesh);

  if (source.has_copies()) {
    std::vector<std::uint64_t> sources;
    for (Vertex v : mesh.vertices()) sources.push_back(source(v));
    std::sort(sources.begin(), sources.end());
    for (std::size_t i = 0; i < sources.size();) {
      std::size_t j = i + 1;
      while (j < sources.size() && sources[j] == sources[i]) ++j;
      if (j - i > 1) {
        ++r.non_manifold_vertices;
        r.vertex_copies += j - i - 1;
      }
      i = j;
    }
    for (Face f : mesh.faces()) {
      sources.clear();
      for (Vertex v : mesh.vertices(f)) sources.push_back(source(v));
      std::sort(sources.begin(), sources.end());
      if (std::adjacent_find(sources.begin(), sources.end()) != sources.end()) ++r.repeated_vertex_faces;
    }
  }

  // Soup edges that became several mesh edges: 3+ faces is a non-manifold edge split, 2 is
  // an edge cut (unorientable, or a face visiting a vertex twice). Sources fit 32 bits
  // (vertices build() did not make are numbered after the largest source).
  std::uint64_t next_id = 0;
  std::vector<std::uint32_t> id(mesh.vertices_size(), kInvalidIndex);
  for (Vertex v : mesh.vertices())
    if (std::uint64_t s = source(v); s < (std::uint64_t(1) << 32)) next_id = std::max(next_id, s + 1);
  for (Vertex v : mesh.vertices()) {
    std::uint64_t s = source(v);
    id[v.idx()] = static_cast<std::uint32_t>(s < (std::uint64_t(1) << 32) ? s : next_id++);
  }
  for_each_multi_edge(mesh, id, std::size_t(next_id), [&](const std::vector<Edge>& group) {
    std::size_t faces = 0;
    for (Edge e : group) faces += std::size_t(mesh.face(e, 0).is_valid()) + std::size_t(mesh.face(e, 1).is_valid());
    ++(faces >= 3 ? r.non_manifold_edges : r.edges_cut);
  });

  if (const auto* flipped = mesh.face_properties().get<bool>(kFlipped))
    for (Face f : mesh.faces()) r.faces_flipped += flipped->vector()[f.idx()] ? 1 : 0;

  if (const auto* face_source = mesh.face_properties().get<std::uint32_t>(kFaceSource)) {
    std::vector<std::uint32_t> ids;
    for (Face f : mesh.faces())
      if (std::uint32_t s = face_source->vector()[f.idx()]; s != kInvalidIndex) ids.push_back(s);
    std::sort(ids.begin(), ids.end());
    ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
    if (!ids.empty()) r.skipped_faces = std::size_t(ids.back()) + 1 - ids.size();
  }
  return r;
}

RepairReport repair(Mesh& mesh, const RepairOptions& options, Progress& progress) {
  if (!std::isfinite(options.weld_distance) || options.weld_distance < 0)
    throw Error("repair: weld_distance must be a finite number of at least 0, got " + number(options.weld_distance));
  RepairReport report;
  progress.update(0, "reading what building repaired");
  const BuildRepairs input = build_repairs(mesh);
  report.degenerate_faces_removed += input.skipped_faces;

  // Welding and duplicate removal work on the host's own topology (provenance restored),
  // then build again: the survivors glue where the copies and duplicates were.
  Mesh work;
  BuildRepairs kept = input;
  const bool weld_wanted = options.weld_distance > 0;
  if (weld_wanted || has_duplicate_faces(mesh)) {
    Soup soup = extract(mesh);
    progress.update(0.1, "welding vertices");
    if (weld_wanted) report.vertices_welded = weld(soup, options.weld_distance);
    std::vector<char> keep(soup.n_faces(), 1);
    {
      const auto offset = soup.face_offsets();
      std::vector<std::uint64_t> ids(soup.corners.begin(), soup.corners.end());
      std::vector<std::uint64_t> corner;
      for (std::size_t f = 0; f < soup.n_faces(); ++f) {
        corner.assign(ids.begin() + std::ptrdiff_t(offset[f]), ids.begin() + std::ptrdiff_t(offset[f + 1]));
        std::sort(corner.begin(), corner.end());
        if (std::unique(corner.begin(), corner.end()) - corner.begin() < 3) {
          keep[f] = 0;
          ++report.degenerate_faces_removed;
        }
      }
      std::vector<char> duplicate = later_duplicates(soup.face_sizes, ids);
      for (std::size_t f = 0; f < soup.n_faces(); ++f)
        if (duplicate[f] && keep[f]) {
          keep[f] = 0;
          ++report.duplicate_faces_removed;
        }
    }
    keep_faces(soup, keep);
    progress.update(0.3, "rebuilding");
    BuildResult rebuilt = build(soup);
    work = std::move(rebuilt.mesh);
    kept = build_repairs(work);
    if (weld_wanted && (kept.non_manifold_edges > input.non_manifold_edges ||
                        kept.non_manifold_vertices > input.non_manifold_vertices))
      report.messages.push_back("welding made new non-manifold places; they were split again");
  } else {
    work = mesh;
  }
  report.non_manifold_edges_split = kept.non_manifold_edges;
  report.non_manifold_vertices_split = kept.non_manifold_vertices;
  report.vertex_copies_added = kept.vertex_copies;
  report.faces_flipped = kept.faces_flipped;
  report.repeated_vertex_faces_split = kept.repeated_vertex_faces;
  report.edges_cut = kept.edges_cut;
  drop_provenance(work);

  progress.update(0.5, "removing degenerate faces");
  report.degenerate_faces_removed += remove_degenerate_faces(work, report.degenerate_faces_deleted, progress);
  progress.update(0.7, "removing pinches");
  const std::size_t duplicates_left = remove_duplicate_faces(work);
  report.duplicate_faces_removed += duplicates_left;
  report.pinched_faces_removed = remove_pinches(work);

  // Deleting a face can leave a vertex with two fans; a round trip through a soup lets
  // build() split it like any other non-manifold vertex.
  if (report.degenerate_faces_deleted || duplicates_left || report.pinched_faces_removed) {
    progress.update(0.8, "splitting vertices left non-manifold");
    BuildResult again = build(extract(work));
    const BuildRepairs more = build_repairs(again.mesh);
    report.non_manifold_vertices_split += more.non_manifold_vertices;
    report.vertex_copies_added += more.vertex_copies;
    work = std::move(again.mesh);
    drop_provenance(work);
  }

  if (options.remove_isolated_vertices) {
    progress.update(0.9, "removing isolated vertices");
    for (Vertex v : work.vertices())
      if (work.is_isolated(v)) {
        work.remove_isolated_vertex(v);
        ++report.isolated_vertices_removed;
      }
  }
  work.compact();

  say(report, report.vertices_welded,
      "welded " + plural(report.vertices_welded, "vertex", "vertices") + " into a neighbour at most " +
          number(options.weld_distance) + " away");
  say(report, report.duplicate_faces_removed,
      "removed " + plural(report.duplicate_faces_removed, "duplicate face", "duplicate faces"));
  say(report, report.non_manifold_edges_split,
      "kept " + plural(report.non_manifold_edges_split, "non-manifold edge", "non-manifold edges") +
          " split into manifold ones");
  say(report, report.non_manifold_vertices_split,
      "kept " + plural(report.non_manifold_vertices_split, "non-manifold vertex", "non-manifold vertices") +
          " split into " + plural(report.vertex_copies_added, "extra copy", "extra copies"));
  say(report, report.faces_flipped,
      "kept " + plural(report.faces_flipped, "face", "faces") + " flipped to orient the surface consistently");
  say(report, report.repeated_vertex_faces_split,
      "kept " + plural(report.repeated_vertex_faces_split, "face", "faces") +
          " that visit a vertex twice on separate vertex copies");
  say(report, report.edges_cut,
      "kept " + plural(report.edges_cut, "edge", "edges") + " cut open where the surface cannot be oriented");
  say(report, report.degenerate_faces_removed,
      "removed " + plural(report.degenerate_faces_removed, "degenerate face", "degenerate faces") +
          (report.degenerate_faces_deleted ? " (" + std::to_string(report.degenerate_faces_deleted) +
                                                 " deleted, leaving holes, where no edge could collapse)"
                                           : std::string()));
  say(report, report.pinched_faces_removed,
      "removed " + plural(report.pinched_faces_removed, "face", "faces") +
          " hanging on a second edge between the same two vertices");
  say(report, report.isolated_vertices_removed,
      "removed " + plural(report.isolated_vertices_removed, "isolated vertex", "isolated vertices"));

  mesh = std::move(work);
  progress.update(1, "repaired");
  return report;
}

Operation repair_operation() {
  const char* help =
      "Makes the mesh clean for tools that need a manifold, consistently oriented surface, and keeps the "
      "result: non-manifold edges and vertices are split into manifold copies and faces are flipped to a "
      "consistent orientation (the repairs the core always makes internally, which other operations give "
      "back undone), faces of zero area are collapsed (or deleted when no collapse is legal), duplicate faces "
      "are removed, vertices closer than 'weld_distance' are welded, faces pinched onto a second edge between "
      "the same two vertices are removed, and isolated vertices are dropped. The output builds again without "
      "any repair. Vertex copies keep their vertex's attributes; faces and corners keep theirs. Orientation "
      "follows the majority of each connected part. Run it before operations or exports that refuse "
      "non-manifold input (3D printing, booleans).";
  using O = RepairOptions;
  using R = RepairReport;
  return Binding<O, R>("repair", "Repair", Category::cleaning, help, repair)
      .option(&O::weld_distance, "weld_distance", "Weld distance", at_least(0),
              "Vertices at most this far apart (in the mesh's units) are merged into one; 0 leaves them.")
      .option(&O::remove_isolated_vertices, "remove_isolated_vertices", "Remove isolated vertices",
              "Remove vertices that no face uses.")
      .result(&R::non_manifold_edges_split, "non_manifold_edges_split")
      .result(&R::non_manifold_vertices_split, "non_manifold_vertices_split")
      .result(&R::vertex_copies_added, "vertex_copies_added")
      .result(&R::faces_flipped, "faces_flipped")
      .result(&R::repeated_vertex_faces_split, "repeated_vertex_faces_split")
      .result(&R::edges_cut, "edges_cut")
      .result(&R::degenerate_faces_removed, "degenerate_faces_removed")
      .result(&R::duplicate_faces_removed, "duplicate_faces_removed")
      .result(&R::vertices_welded, "vertices_welded")
      .result(&R::pinched_faces_removed, "pinched_faces_removed")
      .result(&R::isolated_vertices_removed, "isolated_vertices_removed")
      .messages(&R::messages);
}

}  // namespace hedge
