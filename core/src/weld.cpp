// extract()'s guard on the weld (weld.h), as passes over the faces around welded copies:
//   1. watch: the output vertices that weld two or more copies of an input vertex;
//   2. baseline: the input's defects around those vertices;
//   3. repeat until nothing moves: find the output's defects there, and for each one the
//      input did not have, give the copies that make it their own output vertex.
//   4. count: where the output still has more of a kind of defect than the input (a pinch
//      of the mesh itself can take the place of an input edge the weld restores), that kind
//      is judged strictly (every one new) and step 3 runs again.
// Moving a copy out of a weld never makes an edge carry more faces or two faces one vertex
// set; a vertex it leaves with two fans is split in the next pass. Every move makes a weld
// smaller, and each kind turns strict once, so the passes stop.
#include "weld.h"

#include <algorithm>
#include <array>
#include <numeric>
#include <tuple>
#include <utility>

namespace hedge::detail {
namespace {

using Key = std::uint64_t;
//! Keys of vertices that weld nothing start here (output vertex + kOwnKey): never an input id.
constexpr Key kOwnKey = Key(1) << 32;

//! Polygons over vertex keys; per corner, whether its vertex is watched and (for the output)
//! the mesh vertex it stands for.
struct Faces {
  std::vector<Key> keys;
  std::vector<char> watched;
  std::vector<std::uint32_t> mesh_vertex;
  std::vector<std::uint32_t> start{0};

  std::size_t size() const { return start.size() - 1; }
  std::uint32_t next(std::uint32_t c, std::size_t f) const { return c + 1 == start[f + 1] ? start[f] : c + 1; }
  bool any_watched(std::size_t f) const {
    return std::any_of(watched.begin() + start[f], watched.begin() + start[f + 1], [](char w) { return w; });
  }
  std::vector<Key> key_set(std::size_t f) const {
    std::vector<Key> set(keys.begin() + start[f], keys.begin() + start[f + 1]);
    std::sort(set.begin(), set.end());
    set.erase(std::unique(set.begin(), set.end()), set.end());
    return set;
  }
};

//! A face side between two different keys, one of them watched; `corner` is where it starts.
struct Side {
  Key lo, hi;
  std::uint32_t face, corner;
};

//! The defects around watched vertices.
struct Defects {
  std::vector<Side> sides;                                        // by (lo, hi, face)
  std::vector<std::pair<std::uint32_t, std::uint32_t>> nm_edges;  // runs of 3+ sides in `sides`
  struct Fans {
    Key key;
    std::vector<std::pair<std::uint32_t, std::uint32_t>> faces;  // (face, fan), fans numbered from 0
  };
  std::vector<Fans> nm_vertices;
  std::vector<std::vector<std::uint32_t>> duplicates;  // faces sharing one key set, ascending
  std::vector<std::vector<std::uint32_t>> repeating;   // faces listing a key twice, by key set
};

Defects find_defects(const Faces& faces) {
  Defects d;
  for (std::uint32_t f = 0; f < faces.size(); ++f)
    for (std::uint32_t c = faces.start[f]; c < faces.start[f + 1]; ++c) {
      const std::uint32_t n = faces.next(c, f);
      const Key a = faces.keys[c], b = faces.keys[n];
      if (a != b && (faces.watched[c] || faces.watched[n])) d.sides.push_back({std::min(a, b), std::max(a, b), f, c});
    }
  std::sort(d.sides.begin(), d.sides.end(), [](const Side& x, const Side& y) {
    return std::tie(x.lo, x.hi, x.face, x.corner) < std::tie(y.lo, y.hi, y.face, y.corner);
  });
  std::vector<std::pair<std::uint32_t, std::uint32_t>> runs;  // sides of one edge
  for (std::uint32_t i = 0; i < d.sides.size();) {
    std::uint32_t j = i + 1;
    while (j < d.sides.size() && d.sides[j].lo == d.sides[i].lo && d.sides[j].hi == d.sides[i].hi) ++j;
    runs.emplace_back(i, j);
    if (j - i >= 3) d.nm_edges.emplace_back(i, j);
    i = j;
  }

  // Fans: a watched vertex's faces are one fan when edges through the vertex join them.
  std::vector<std::pair<Key, std::uint32_t>> incidences;  // (key, face)
  for (std::uint32_t f = 0; f < faces.size(); ++f)
    for (std::uint32_t c = faces.start[f]; c < faces.start[f + 1]; ++c)
      if (faces.watched[c]) incidences.emplace_back(faces.keys[c], f);
  std::sort(incidences.begin(), incidences.end());
  incidences.erase(std::unique(incidences.begin(), incidences.end()), incidences.end());
  std::vector<std::uint32_t> parent(incidences.size());
  std::iota(parent.begin(), parent.end(), 0u);
  auto root = [&](std::uint32_t x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  };
  auto incidence = [&](Key key, std::uint32_t f) -> std::uint32_t {
    auto it = std::lower_bound(incidences.begin(), incidences.end(), std::make_pair(key, f));
    return it != incidences.end() && *it == std::make_pair(key, f) ? std::uint32_t(it - incidences.begin()) : ~0u;
  };
  for (auto [i, j] : runs)
    for (const Key end : {d.sides[i].lo, d.sides[i].hi}) {
      const std::uint32_t first = incidence(end, d.sides[i].face);
      if (first == ~0u) continue;  // not watched
      for (std::uint32_t k = i + 1; k < j; ++k) parent[root(incidence(end, d.sides[k].face))] = root(first);
    }
  for (std::uint32_t i = 0; i < incidences.size();) {
    std::uint32_t j = i;
    while (j < incidences.size() && incidences[j].first == incidences[i].first) ++j;
    std::vector<std::uint32_t> roots;
    for (std::uint32_t k = i; k < j; ++k) roots.push_back(root(k));
    std::vector<std::uint32_t> distinct = roots;
    std::sort(distinct.begin(), distinct.end());
    distinct.erase(std::unique(distinct.begin(), distinct.end()), distinct.end());
    if (distinct.size() > 1) {
      Defects::Fans fans{incidences[i].first, {}};
      for (std::uint32_t k = i; k < j; ++k)
        fans.faces.emplace_back(
            incidences[k].second,
            std::uint32_t(std::lower_bound(distinct.begin(), distinct.end(), roots[k - i]) - distinct.begin()));
      d.nm_vertices.push_back(std::move(fans));
    }
    i = j;
  }

  // Duplicates: faces with a watched vertex and one key set. Faces repeating a key (only a
  // weld can: a watched one), grouped the same way.
  std::vector<std::pair<std::vector<Key>, std::uint32_t>> sets, repeats;
  for (std::uint32_t f = 0; f < faces.size(); ++f)
    if (faces.any_watched(f)) {
      sets.emplace_back(faces.key_set(f), f);
      if (sets.back().first.size() < faces.start[f + 1] - faces.start[f]) repeats.push_back(sets.back());
    }
  auto group = [](std::vector<std::pair<std::vector<Key>, std::uint32_t>>& by_set, std::size_t min,
                  std::vector<std::vector<std::uint32_t>>& groups) {
    std::sort(by_set.begin(), by_set.end());
    for (std::size_t i = 0; i < by_set.size();) {
      std::size_t j = i + 1;
      while (j < by_set.size() && by_set[j].first == by_set[i].first) ++j;
      if (j - i >= min) {
        groups.emplace_back();
        for (std::size_t k = i; k < j; ++k) groups.back().push_back(by_set[k].second);
      }
      i = j;
    }
  };
  group(sets, 2, d.duplicates);
  group(repeats, 1, d.repeating);
  return d;
}

//! The input's defects as keys, to tell the output's new ones from those it came with.
struct Baseline {
  std::vector<std::pair<Key, Key>> nm_edges;
  std::vector<Key> nm_vertices;
  std::vector<std::pair<std::vector<Key>, std::size_t>> duplicates, repeating;  // (key set, faces with it)

  Baseline(const Faces& faces, const Defects& d) {
    for (auto [i, j] : d.nm_edges) nm_edges.emplace_back(d.sides[i].lo, d.sides[i].hi);
    for (const auto& fans : d.nm_vertices) nm_vertices.push_back(fans.key);
    for (const auto& group : d.duplicates) duplicates.emplace_back(faces.key_set(group[0]), group.size());
    for (const auto& group : d.repeating) repeating.emplace_back(faces.key_set(group[0]), group.size());
    std::sort(nm_edges.begin(), nm_edges.end());
    std::sort(nm_vertices.begin(), nm_vertices.end());
    std::sort(duplicates.begin(), duplicates.end());
    std::sort(repeating.begin(), repeating.end());
  }
  template <class T>
  static bool has(const std::vector<T>& sorted, const T& value) {
    return std::binary_search(sorted.begin(), sorted.end(), value);
  }
  //! How many faces of `groups` (duplicates or repeating) the input has with this key set.
  static std::size_t faces_with(const std::vector<std::pair<std::vector<Key>, std::size_t>>& groups,
                                const std::vector<Key>& set, std::size_t otherwise) {
    auto it = std::lower_bound(groups.begin(), groups.end(), set,
                               [](const auto& entry, const std::vector<Key>& s) { return entry.first < s; });
    return it != groups.end() && it->first == set ? it->second : otherwise;
  }
};

class Guard {
 public:
  Guard(const Mesh& mesh, const std::vector<std::uint32_t>& source, const Soup& input, Weld& weld)
      : mesh_(mesh),
        source_(source),
        input_(input),
        weld_(weld),
        group_size_(weld.order.size(), 0),
        moved_flag_(mesh.vertices_size(), 0) {
    for (Vertex v : mesh.vertices()) ++group_size_[weld.vmap[v.idx()]];
  }

  std::size_t run() {
    if (!watch()) return 0;
    const Faces input = input_faces();
    const Defects input_defects = find_defects(input);
    const Baseline baseline(input, input_defects);
    const Counts limit = counts(input, input_defects);
    std::array<bool, 4> strict{};  // by kind: every defect of it counts as new
    std::size_t moved = 0;
    for (;;) {
      for (std::uint32_t v : moved_now_) moved_flag_[v] = 0;
      moved_now_.clear();
      const Faces faces = output_faces();
      const Defects found = find_defects(faces);
      const std::size_t before = moved;
      for (auto [i, j] : found.nm_edges) {
        const Side& s = found.sides[i];
        if (!ours(s.lo) || !ours(s.hi) || (!strict[0] && Baseline::has(baseline.nm_edges, {s.lo, s.hi}))) continue;
        moved += split_edge(faces, found, i, j);
      }
      for (const auto& fans : found.nm_vertices)
        if (strict[1] || !Baseline::has(baseline.nm_vertices, fans.key)) moved += split_fans(faces, fans);
      // A key set the input had on several faces may come back on as many, no more.
      for (const auto& group : found.duplicates) {
        const std::vector<Key> set = faces.key_set(group[0]);
        const std::size_t keep = strict[2] ? 1 : Baseline::faces_with(baseline.duplicates, set, 1);
        if (all_ours(set) && group.size() > keep) moved += split_duplicate(faces, group, keep);
      }
      // Faces repeating a vertex, as often as the input had their key set (an Euler edit or
      // an operation can cut a face build() let repeat its vertex into pieces that repeat it).
      for (const auto& group : found.repeating) {
        const std::size_t keep = strict[3] ? 0 : Baseline::faces_with(baseline.repeating, faces.key_set(group[0]), 0);
        for (std::size_t k = keep; k < group.size(); ++k) moved += split_repeat(faces, group[k]);
      }
      if (moved != before) continue;
      // Settled by key; now by count.
      const Counts now = counts(faces, found);
      bool stricter = false;
      for (std::size_t k = 0; k < now.size(); ++k)
        if (now[k] > limit[k] && !strict[k]) strict[k] = stricter = true;
      if (!stricter) return moved;
    }
  }

 private:
  // ---- pass 1: watch -----------------------------------------------------------------
  //! Marks the input vertices whose copies weld, and the mesh faces around them.
  bool watch() {
    watched_input_.assign(input_.n_vertices(), 0);
    bool any = false;
    for (std::uint32_t o = 0; o < weld_.n_sourced; ++o) {
      if (group_size_[o] < 2) continue;
      any = true;
      if (const std::uint32_t s = source_[weld_.order[o]]; s < input_.n_vertices()) watched_input_[s] = 1;
    }
    if (!any) return false;
    for (Face f : mesh_.faces())
      for (Vertex v : mesh_.vertices(f))
        if (watched(weld_.vmap[v.idx()])) {
          suspects_.push_back(f);
          break;
        }
    return true;
  }
  //! Welds two or more copies (of an input vertex, of an operation's own source, or of a fan
  //! split off either).
  bool watched(std::uint32_t o) const { return group_size_[o] >= 2; }
  Key key(std::uint32_t o) const { return o < weld_.n_sourced ? Key(source_[weld_.order[o]]) : kOwnKey + o; }
  //! False for a source an operation made (past the input's vertices): the non-manifold
  //! edges and duplicate faces its welds make are the operation's own rule (subdivision
  //! splits such an edge in two, such a face in four). Its non-manifold vertices are not.
  bool ours(Key k) const { return k >= kOwnKey || k < input_.n_vertices(); }
  bool representative(std::uint32_t v) const { return weld_.order[weld_.vmap[v]] == v; }
  bool all_ours(const std::vector<Key>& set) const {
    return std::all_of(set.begin(), set.end(), [&](Key k) { return ours(k); });
  }

  // ---- pass 4: count -----------------------------------------------------------------
  //! How many of each kind (non-manifold edges and vertices, duplicate faces, faces
  //! repeating a vertex) the guard answers for: those step 3 would split if they were new.
  using Counts = std::array<std::size_t, 4>;
  Counts counts(const Faces& faces, const Defects& d) const {
    Counts n{};
    for (auto [i, j] : d.nm_edges) n[0] += ours(d.sides[i].lo) && ours(d.sides[i].hi);
    n[1] = d.nm_vertices.size();
    for (const auto& group : d.duplicates)
      if (all_ours(faces.key_set(group[0]))) n[2] += group.size() - 1;
    for (const auto& group : d.repeating) n[3] += group.size();
    return n;
  }

  // ---- pass 2: baseline --------------------------------------------------------------
  Faces input_faces() const {
    Faces faces;
    const std::vector<std::size_t> offsets = input_.face_offsets();
    for (std::size_t f = 0; f < input_.n_faces(); ++f) {
      const auto first = input_.corners.begin() + offsets[f], last = input_.corners.begin() + offsets[f + 1];
      if (std::none_of(first, last, [&](std::uint32_t v) { return watched_input_[v]; })) continue;
      for (auto it = first; it != last; ++it) {
        faces.keys.push_back(*it);
        faces.watched.push_back(watched_input_[*it]);
      }
      faces.start.push_back(std::uint32_t(faces.keys.size()));
    }
    return faces;
  }

  // ---- pass 3: find and split --------------------------------------------------------
  Faces output_faces() const {
    Faces faces;
    for (Face f : suspects_) {
      for (Vertex v : mesh_.vertices(f)) {
        const std::uint32_t o = weld_.vmap[v.idx()];
        faces.keys.push_back(key(o));
        faces.watched.push_back(watched(o));
        faces.mesh_vertex.push_back(v.idx());
      }
      faces.start.push_back(std::uint32_t(faces.keys.size()));
    }
    return faces;
  }

  //! Gives mesh vertex v an output vertex of its own.
  std::size_t move(std::uint32_t v) { return move_all({v}); }
  std::size_t move_all(const std::vector<std::uint32_t>& vs) {
    for (std::uint32_t v : vs) {
      moved_flag_[v] = 1;
      moved_now_.push_back(v);
    }
    const std::uint32_t o = std::uint32_t(weld_.order.size());
    weld_.order.push_back(vs.front());
    group_size_.push_back(0);
    for (std::uint32_t v : vs) {
      --group_size_[weld_.vmap[v]];
      weld_.vmap[v] = o;
      ++group_size_[o];
    }
    return vs.size();
  }
  bool movable(std::uint32_t v) const { return !representative(v); }
  //! True when a defect found at the start of this pass involves a copy moved since: it is
  //! looked at again in the next pass, as it is then.
  template <class Range>
  bool stale(const Range& vertices) const {
    return std::any_of(vertices.begin(), vertices.end(), [&](std::uint32_t v) { return moved_flag_[v]; });
  }

  //! A new edge of 3+ faces: keeps the mesh edge with the most representatives welded and
  //! moves an end of each other one that it does not share.
  std::size_t split_edge(const Faces& faces, const Defects& d, std::uint32_t i, std::uint32_t j) {
    std::vector<std::pair<std::uint32_t, std::uint32_t>> edges;
    for (std::uint32_t k = i; k < j; ++k) {
      const Side& s = d.sides[k];
      const std::uint32_t a = faces.mesh_vertex[s.corner], b = faces.mesh_vertex[faces.next(s.corner, s.face)];
      edges.emplace_back(std::min(a, b), std::max(a, b));
    }
    std::sort(edges.begin(), edges.end());
    edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
    std::vector<std::uint32_t> ends;
    for (auto e : edges) ends.insert(ends.end(), {e.first, e.second});
    if (stale(ends)) return 0;
    auto reps = [&](auto e) { return int(representative(e.first)) + int(representative(e.second)); };
    const auto keep = *std::max_element(edges.begin(), edges.end(), [&](auto x, auto y) { return reps(x) < reps(y); });
    std::size_t moved = 0;
    for (auto e : edges) {
      if (e == keep) continue;
      for (std::uint32_t v : {e.first, e.second})
        if (v != keep.first && v != keep.second && movable(v)) {
          moved += move(v);
          break;
        }
    }
    return moved;
  }

  //! A new vertex of 2+ fans: the fan of the weld's representative stays, each other fan
  //! gets one output vertex for all its copies.
  std::size_t split_fans(const Faces& faces, const Defects::Fans& fans) {
    std::vector<std::pair<std::uint32_t, std::uint32_t>> copies;  // (fan, mesh vertex)
    for (auto [f, fan] : fans.faces)
      for (std::uint32_t c = faces.start[f]; c < faces.start[f + 1]; ++c)
        if (faces.keys[c] == fans.key) copies.emplace_back(fan, faces.mesh_vertex[c]);
    std::sort(copies.begin(), copies.end());
    copies.erase(std::unique(copies.begin(), copies.end()), copies.end());
    std::vector<std::uint32_t> all;
    for (auto [fan, v] : copies) all.push_back(v);
    if (stale(all)) return 0;
    std::uint32_t kept = copies.front().first;
    for (auto [fan, v] : copies)
      if (representative(v)) kept = fan;
    std::size_t moved = 0;
    for (std::size_t i = 0; i < copies.size();) {
      std::size_t j = i;
      std::vector<std::uint32_t> group;
      while (j < copies.size() && copies[j].first == copies[i].first) group.push_back(copies[j++].second);
      // A copy in two fans (only possible through a face that repeats it) stays.
      if (copies[i].first != kept &&
          std::none_of(group.begin(), group.end(), [&](std::uint32_t v) { return representative(v); }))
        moved += move_all(group);
      i = j;
    }
    return moved;
  }

  //! Faces made one by the weld: all but `keep` of them move a copy, one that the faces kept
  //! do not use where there is one. Faces none of whose copies may move are kept first.
  std::size_t split_duplicate(const Faces& faces, const std::vector<std::uint32_t>& group, std::size_t keep) {
    std::vector<std::uint32_t> all;
    for (std::uint32_t f : group)
      all.insert(all.end(), faces.mesh_vertex.begin() + faces.start[f], faces.mesh_vertex.begin() + faces.start[f + 1]);
    if (stale(all)) return 0;
    std::vector<std::uint32_t> used;  // mesh vertices of the faces kept
    auto copy_to_move = [&](std::uint32_t f) -> std::uint32_t {
      std::uint32_t any = ~0u;
      for (std::uint32_t c = faces.start[f]; c < faces.start[f + 1]; ++c) {
        const std::uint32_t v = faces.mesh_vertex[c];
        if (!faces.watched[c] || !movable(v)) continue;
        if (std::find(used.begin(), used.end(), v) == used.end()) return v;
        if (any == ~0u) any = v;
      }
      return any;
    };
    std::vector<std::uint32_t> ranked;
    for (std::uint32_t f : group)
      if (copy_to_move(f) == ~0u) ranked.push_back(f);
    for (std::uint32_t f : group)
      if (copy_to_move(f) != ~0u) ranked.push_back(f);
    std::size_t moved = 0;
    for (std::size_t k = 0; k < ranked.size(); ++k) {
      const std::uint32_t f = ranked[k];
      if (k < keep) {
        used.insert(used.end(), faces.mesh_vertex.begin() + faces.start[f],
                    faces.mesh_vertex.begin() + faces.start[f + 1]);
      } else if (const std::uint32_t v = copy_to_move(f); v != ~0u) {
        moved += move(v);
      }
    }
    return moved;
  }

  //! A face listing a key twice or more: per key, the representative's copy (or the first)
  //! stays and the others move.
  std::size_t split_repeat(const Faces& faces, std::uint32_t f) {
    std::vector<std::pair<Key, std::uint32_t>> corners;  // (key, mesh vertex)
    for (std::uint32_t c = faces.start[f]; c < faces.start[f + 1]; ++c)
      corners.emplace_back(faces.keys[c], faces.mesh_vertex[c]);
    if (std::any_of(corners.begin(), corners.end(), [&](const auto& kv) { return moved_flag_[kv.second]; })) return 0;
    std::sort(corners.begin(), corners.end());
    std::size_t moved = 0;
    for (std::size_t i = 0; i < corners.size();) {
      std::size_t j = i + 1, keep = i;
      while (j < corners.size() && corners[j].first == corners[i].first) ++j;
      for (std::size_t k = i; k < j; ++k)
        if (representative(corners[k].second)) keep = k;
      for (std::size_t k = i; k < j; ++k)
        if (k != keep && movable(corners[k].second)) moved += move(corners[k].second);
      i = j;
    }
    return moved;
  }

  const Mesh& mesh_;
  const std::vector<std::uint32_t>& source_;
  const Soup& input_;
  Weld& weld_;
  std::vector<std::uint32_t> group_size_;
  std::vector<char> watched_input_;
  std::vector<Face> suspects_;
  std::vector<char> moved_flag_;
  std::vector<std::uint32_t> moved_now_;
};

}  // namespace

std::size_t keep_new_defects_apart(const Mesh& mesh, const std::vector<std::uint32_t>& source, const Soup& input,
                                   Weld& weld) {
  return Guard(mesh, source, input, weld).run();
}

}  // namespace hedge::detail
