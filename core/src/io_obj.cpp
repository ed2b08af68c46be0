// Wavefront OBJ files: positions (with optional vertex colours), per-corner texture
// coordinates and normals, polygons with absolute or relative indices, usemtl as a material id.
#include <algorithm>
#include <array>
#include <cstdint>
#include <cstring>
#include <string>
#include <unordered_map>
#include <vector>

#include "hedge/detail/memory.h"
#include "hedge/io.h"
#include "io_detail.h"

namespace hedge {

using namespace io_detail;

namespace {

constexpr std::uint32_t kNone = 0xffffffffu;

struct Reference {  // a vt or vn index that pointed past what the file had defined so far
  std::size_t line;
  std::uint64_t index;  // 0-based
};

enum Kind : std::uint8_t { kVertex, kTexcoord, kNormal };
constexpr const char* kKindNames[] = {"vertex", "texture coordinate", "normal"};

//! A relative index, which only the runs before its own can settle.
struct Relative {
  std::size_t corner;    // in its run
  std::uint64_t back;    // -index - 1
  std::uint64_t before;  // elements of its kind defined earlier in its run
  std::size_t line;
  Kind kind;
  std::string text;
};

//! What one run of whole lines of the file holds. Runs are read on several threads; what
//! depends on the lines before a run (relative indices, the material in use, whether any
//! vertex has a colour) is kept apart and settled when the runs are joined in order.
struct ObjRun {
  std::vector<Point> positions;
  std::vector<float> colors;     // 4 per vertex of the run once any of them has a colour
  std::vector<float> texcoords;  // 2 per vt
  std::vector<float> normals;    // 3 per vn
  std::vector<std::uint32_t> face_sizes, corners;
  std::vector<std::uint32_t> corner_vt, corner_vn;  // while every corner of the run has one
  bool all_vt = true, all_vn = true;
  std::vector<Reference> later_vt, later_vn;
  std::vector<Relative> relative;
  std::vector<std::string> material_names;  // by first use in the run
  std::size_t faces_before_material = 0;    // faces before the run's first usemtl
  std::vector<std::int32_t> materials;      // per face from there on: index into material_names
  std::int32_t last_material = -1;          // in use at the run's end (index into material_names)
  bool failed = false;                      // the run stopped at an error
  std::size_t lines = 0;                    // line breaks in the run
};

class RunReader {
 public:
  RunReader(std::string_view bytes, const std::string& name, std::size_t first_line, ObjRun& run)
      : in_(bytes, name, '#', true, first_line), run_(run) {}

  //! Reads the run; returns its line breaks, or marks it failed at its first error.
  std::size_t read() {
    const std::size_t first_line = in_.line();
    try {
      read_statements();
    } catch (const Error&) {
      run_.failed = true;
      return 0;
    }
    return in_.line() - first_line;
  }

  //! Reads the run again from its true first line, to throw its first error.
  [[noreturn]] void fail_again() {
    read_statements();
    throw Error("internal error: a run of the file failed only once");
  }

 private:
  void read_statements() {
    for (;;) {
      in_.skip_space();
      if (in_.at_end()) break;
      std::string_view keyword = in_.line_token();
      if (keyword == "v") {
        read_vertex();
      } else if (keyword == "vt") {
        read_texcoord();
      } else if (keyword == "vn") {
        read_floats(run_.normals, 3, "3 normal coordinates");
      } else if (keyword == "f") {
        read_face();
      } else if (keyword == "usemtl") {
        use_material();
      } else {
        // g, o, s, mtllib, l, p, vp and free-form geometry: nothing a Soup holds.
        while (!in_.at_line_end()) in_.line_token();
      }
      if (!in_.at_line_end()) in_.fail_expected("the end of the line", in_.line_token());
      in_.next_line();
    }
  }

  void read_vertex() {
    Point p;
    for (int k = 0; k < 3; ++k) {
      std::string_view t = in_.line_token();
      if (!parse_number(t, p[k])) in_.fail_expected("3 coordinates", t);
    }
    // "v x y z w" carries a weight for rational curves, meaningless for polygons;
    // "v x y z r g b [a]" is the common vertex colour extension.
    float extra[4] = {1, 1, 1, 1};
    int n = 0;
    while (!in_.at_line_end()) {
      std::string_view t = in_.line_token();
      if (n == 4 || !parse_number(t, extra[n])) in_.fail_expected(n == 4 ? "" : "a number", t);
      ++n;
    }
    if (n == 2)
      in_.fail("expected 3 coordinates, optionally followed by a weight or by 3 or 4 colour values; found 5 values");
    std::vector<float>& colors = run_.colors;
    if (n >= 3) {
      if (colors.empty()) colors.assign(run_.positions.size() * 4, 1.0f);
      if (n == 3) extra[3] = 1.0f;
      colors.insert(colors.end(), extra, extra + 4);
    } else if (!colors.empty()) {
      colors.insert(colors.end(), {1.0f, 1.0f, 1.0f, 1.0f});
    }
    run_.positions.push_back(p);
  }

  void read_texcoord() {
    float uvw[3] = {0, 0, 0};
    int n = 0;
    while (!in_.at_line_end()) {
      std::string_view t = in_.line_token();
      if (n == 3 || !parse_number(t, uvw[n])) in_.fail_expected(n == 3 ? "" : "a texture coordinate", t);
      ++n;
    }
    if (n == 0) in_.fail("expected 1 to 3 texture coordinates, found end of line");
    run_.texcoords.push_back(uvw[0]);
    run_.texcoords.push_back(uvw[1]);
  }

  void read_floats(std::vector<float>& out, int n, const char* what) {
    for (int k = 0; k < n; ++k) {
      std::string_view t = in_.line_token();
      float v = 0;
      if (!parse_number(t, v)) in_.fail_expected(what, t);
      out.push_back(v);
    }
  }

  //! A 1-based index, 0-based; a negative (relative) one is recorded for the join to settle
  //! against everything defined before it, and kNone stands in for it until then.
  std::uint64_t resolve(std::string_view text, std::string_view token, std::size_t before, Kind kind) {
    const char* name = kKindNames[kind];
    std::int64_t i = 0;
    if (!parse_number(text, i))
      in_.fail("expected a " + std::string(name) + " index in " + quote(token) + ", found " + quote(text));
    if (i > 0) {
      if (static_cast<std::uint64_t>(i) > 0xffffffffu)
        in_.fail(std::string(name) + " index " + std::string(text) + " is too large");
      return static_cast<std::uint64_t>(i - 1);
    }
    if (i == 0) in_.fail("index 0 in " + quote(token) + " is invalid: OBJ indices start at 1");
    const std::size_t corner = run_.corners.size() - (kind == kVertex ? 0 : 1);
    run_.relative.push_back(
        {corner, static_cast<std::uint64_t>(-(i + 1)), before, in_.line(), kind, std::string(text)});
    return kNone;
  }

  std::uint32_t attribute(std::string_view text, std::string_view token, std::size_t before, Kind kind,
                          std::vector<Reference>& later) {
    const std::uint64_t index = resolve(text, token, before, kind);
    // Past what this run has defined so far: checked against the whole file at the end.
    if (index != kNone && index >= before) later.push_back({in_.line(), index});
    return static_cast<std::uint32_t>(index);
  }

  void read_face() {
    std::uint32_t size = 0;
    while (!in_.at_line_end()) {
      std::string_view token = in_.line_token();
      std::string_view parts[3];
      int n = 0;
      std::size_t start = 0;
      for (;;) {
        std::size_t slash = token.find('/', start);
        if (n == 3) in_.fail("expected at most v/vt/vn, found " + quote(token));
        parts[n++] = token.substr(start, slash == std::string_view::npos ? std::string_view::npos : slash - start);
        if (slash == std::string_view::npos) break;
        start = slash + 1;
      }
      const std::uint64_t v = resolve(parts[0], token, run_.positions.size(), kVertex);
      run_.corners.push_back(static_cast<std::uint32_t>(v));
      const bool has_vt = n > 1 && !parts[1].empty(), has_vn = n > 2 && !parts[2].empty();
      run_.all_vt = run_.all_vt && has_vt;
      run_.all_vn = run_.all_vn && has_vn;
      // Pushed before being resolved, so that a relative index names its corner.
      if (run_.all_vt) run_.corner_vt.push_back(kNone);
      if (has_vt) {
        const std::uint32_t vt = attribute(parts[1], token, run_.texcoords.size() / 2, kTexcoord, run_.later_vt);
        if (run_.all_vt) run_.corner_vt.back() = vt;
      }
      if (run_.all_vn) run_.corner_vn.push_back(kNone);
      if (has_vn) {
        const std::uint32_t vn = attribute(parts[2], token, run_.normals.size() / 3, kNormal, run_.later_vn);
        if (run_.all_vn) run_.corner_vn.back() = vn;
      }
      ++size;
    }
    if (size == 0) in_.fail("expected vertex indices after 'f', found end of line");
    run_.face_sizes.push_back(size);
    if (seen_material_) run_.materials.push_back(material_);
  }

  void use_material() {
    std::string_view name = in_.line_token();
    while (!in_.at_line_end()) in_.line_token();  // names with spaces: the first word decides
    auto [it, added] = material_ids_.try_emplace(std::string(name), static_cast<std::int32_t>(material_ids_.size()));
    if (added) run_.material_names.emplace_back(name);
    material_ = run_.last_material = it->second;
    if (!seen_material_) run_.faces_before_material = run_.face_sizes.size();
    seen_material_ = true;
  }

  TextScanner in_;
  ObjRun& run_;
  std::unordered_map<std::string, std::int32_t> material_ids_;  // the run's own numbering
  std::int32_t material_ = -1;
  bool seen_material_ = false;
};

//! Joins the runs in order: indices settled, materials numbered by first use in the file,
//! errors reported in the order the file has them.
class RunJoin {
 public:
  RunJoin(std::vector<ObjRun>& runs, const std::vector<std::string_view>& text, const std::string& name)
      : runs_(runs), text_(text), name_(name) {}

  Soup join() {
    std::uint64_t defined[3] = {0, 0, 0};
    bool colors = false, all_vt = true, all_vn = true;
    std::size_t lines_before = 0;
    for (std::size_t k = 0; k < runs_.size(); ++k) {
      ObjRun& run = runs_[k];
      for (Relative& r : run.relative) settle(run, r, defined[r.kind] + r.before, lines_before);
      if (run.failed) {
        ObjRun again;
        RunReader(text_[k], name_, lines_before + 1, again).fail_again();
      }
      for (Reference& r : run.later_vt) r.line += lines_before;
      for (Reference& r : run.later_vn) r.line += lines_before;
      lines_before += run.lines;
      Start& at = starts_.emplace_back();
      at.vertices = defined[kVertex], at.texcoords = defined[kTexcoord], at.normals = defined[kNormal];
      at.corners = corners_, at.faces = faces_;
      defined[kVertex] += run.positions.size();
      defined[kTexcoord] += run.texcoords.size() / 2;
      defined[kNormal] += run.normals.size() / 3;
      corners_ += run.corners.size();
      faces_ += run.face_sizes.size();
      colors = colors || !run.colors.empty();
      all_vt = all_vt && run.all_vt;
      all_vn = all_vn && run.all_vn;
      number_materials(run);
    }
    check_later(&ObjRun::later_vt, defined[kTexcoord], kTexcoord);
    check_later(&ObjRun::later_vn, defined[kNormal], kNormal);

    Soup soup;
    detail::resize_on_huge_pages(soup.positions, defined[kVertex]);
    detail::resize_on_huge_pages(soup.face_sizes, faces_);
    detail::resize_on_huge_pages(soup.corners, corners_);
    std::vector<float> texcoords(2 * defined[kTexcoord]), normals(3 * defined[kNormal]);
    float* color = colors ? soup.add_channel("color", Domain::vertex, ScalarType::f32, 4).as<float>() : nullptr;
    std::int32_t* material =
        seen_material_ ? soup.add_channel("material", Domain::face, ScalarType::i32, 1).as<std::int32_t>() : nullptr;
    each_run([&](ObjRun& run, const Start& at) {
      std::copy(run.positions.begin(), run.positions.end(), soup.positions.begin() + std::ptrdiff_t(at.vertices));
      std::copy(run.face_sizes.begin(), run.face_sizes.end(), soup.face_sizes.begin() + std::ptrdiff_t(at.faces));
      std::copy(run.corners.begin(), run.corners.end(), soup.corners.begin() + std::ptrdiff_t(at.corners));
      std::copy(run.texcoords.begin(), run.texcoords.end(), texcoords.begin() + std::ptrdiff_t(2 * at.texcoords));
      std::copy(run.normals.begin(), run.normals.end(), normals.begin() + std::ptrdiff_t(3 * at.normals));
      if (color) {
        float* out = color + 4 * at.vertices;
        if (run.colors.empty())
          std::fill(out, out + 4 * run.positions.size(), 1.0f);
        else
          std::copy(run.colors.begin(), run.colors.end(), out);
      }
      if (material) {
        std::int32_t* out = material + at.faces;
        const std::size_t inherited = run.materials.empty() ? run.face_sizes.size() : run.faces_before_material;
        std::fill(out, out + inherited, at.material);
        for (std::size_t f = inherited; f < run.face_sizes.size(); ++f)
          out[f] = at.material_ids[std::size_t(run.materials[f - inherited])];
      }
      // Copied: the run's memory goes now, not with the soup's peak (its corners' texture
      // coordinate and normal indices serve the gathers below).
      release(run.positions, run.face_sizes, run.corners, run.texcoords, run.normals, run.colors, run.materials);
    });
    if (all_vt && corners_ > 0)
      gather(soup.add_channel("uv", Domain::corner, ScalarType::f32, 2), texcoords, 2, &ObjRun::corner_vt);
    if (all_vn && corners_ > 0)
      gather(soup.add_channel("normal", Domain::corner, ScalarType::f32, 3), normals, 3, &ObjRun::corner_vn);
    check_soup(soup, name_);
    return soup;
  }

 private:
  struct Start {  // what the runs before a run define
    std::uint64_t vertices = 0, texcoords = 0, normals = 0, corners = 0, faces = 0;
    std::int32_t material = -1;              // in use where the run starts
    std::vector<std::int32_t> material_ids;  // the run's material numbers in the file's
  };

  void settle(ObjRun& run, const Relative& r, std::uint64_t defined, std::size_t lines_before) {
    const char* kind = kKindNames[r.kind];
    if (r.back >= defined)
      fail_line(name_, lines_before + r.line,
                "relative " + std::string(kind) + " index " + r.text + " points before the first " + kind + " (only " +
                    std::to_string(defined) + " defined so far)");
    const auto index = static_cast<std::uint32_t>(defined - r.back - 1);
    if (r.kind == kVertex) run.corners[r.corner] = index;
    std::vector<std::uint32_t>& of_corner = r.kind == kTexcoord ? run.corner_vt : run.corner_vn;
    if (r.kind != kVertex && r.corner < of_corner.size()) of_corner[r.corner] = index;
  }

  void number_materials(const ObjRun& run) {
    Start& at = starts_.back();
    at.material = material_;
    for (const std::string& m : run.material_names) {
      auto it = material_ids_.try_emplace(m, static_cast<std::int32_t>(material_ids_.size())).first;
      at.material_ids.push_back(it->second);
    }
    if (run.last_material >= 0) {
      seen_material_ = true;
      material_ = at.material_ids[std::size_t(run.last_material)];
    }
  }

  void check_later(std::vector<Reference> ObjRun::*later, std::uint64_t count, Kind kind) {
    for (const ObjRun& run : runs_)
      for (const Reference& r : run.*later)
        if (r.index >= count)
          fail_line(name_, r.line,
                    std::string(kKindNames[kind]) + " index " + std::to_string(r.index + 1) +
                        " is out of range: the file defines " + std::to_string(count));
  }

  template <class... Vectors>
  static void release(Vectors&... v) {
    (Vectors().swap(v), ...);
  }

  template <class Fn>
  void each_run(Fn&& fn) {
    parallel_for(
        runs_.size(), 0,
        [&](std::size_t begin, std::size_t end) {
          for (std::size_t r = begin; r < end; ++r) fn(runs_[r], starts_[r]);
        },
        1);
  }

  void gather(Channel& c, const std::vector<float>& values, int n, std::vector<std::uint32_t> ObjRun::*of_corner) {
    float* out = c.as<float>();
    each_run([&](ObjRun& run, const Start& at) {
      const std::vector<std::uint32_t>& index = run.*of_corner;
      for (std::size_t i = 0; i < index.size(); ++i)
        std::memcpy(out + n * (at.corners + i), &values[std::size_t(n) * index[i]], n * sizeof(float));
    });
  }

  std::vector<ObjRun>& runs_;
  const std::vector<std::string_view>& text_;
  const std::string& name_;
  std::vector<Start> starts_;
  std::uint64_t corners_ = 0, faces_ = 0;
  std::unordered_map<std::string, std::int32_t> material_ids_;
  std::int32_t material_ = -1;
  bool seen_material_ = false;
};

//! Numbers values by first use, equal bit patterns sharing a number, so each distinct
//! uv or normal is written once. Open addressing over a flat table: a map of nodes spent
//! more time allocating than hashing.
template <int N>
class Dedup {
 public:
  std::uint32_t add(const float* v) {
    Key key{};
    std::memcpy(key.data(), v, N * sizeof(float));
    if (2 * (count() + 1) > slots_.size()) grow();
    const std::size_t mask = slots_.size() - 1;
    for (std::size_t i = hash(key) & mask;; i = (i + 1) & mask) {
      Slot& slot = slots_[i];
      if (slot.id == kEmpty) {
        slot = {key, count()};
        values_.insert(values_.end(), v, v + N);
        return slot.id;
      }
      if (slot.key[0] == key[0] && slot.key[1] == key[1] && slot.key[2] == key[2]) return slot.id;  // no memcmp call
    }
  }
  const std::vector<float>& values() const { return values_; }

 private:
  using Key = std::array<std::uint32_t, 3>;
  static constexpr std::uint32_t kEmpty = 0xffffffffu;
  struct Slot {
    Key key{};
    std::uint32_t id = kEmpty;
  };
  static std::size_t hash(const Key& k) {
    std::uint64_t h = (static_cast<std::uint64_t>(k[0]) << 32 | k[1]) * 0x9e3779b97f4a7c15ull ^ k[2];
    h ^= h >> 29;
    h *= 0xbf58476d1ce4e5b9ull;
    return static_cast<std::size_t>(h ^ (h >> 32));
  }
  std::uint32_t count() const { return static_cast<std::uint32_t>(values_.size() / N); }
  void grow() {
    std::vector<Slot> old(std::max<std::size_t>(1024, 2 * slots_.size()));
    old.swap(slots_);
    const std::size_t mask = slots_.size() - 1;
    for (const Slot& slot : old)
      if (slot.id != kEmpty) {
        std::size_t i = hash(slot.key) & mask;
        while (slots_[i].id != kEmpty) i = (i + 1) & mask;
        slots_[i] = slot;
      }
  }

  std::vector<Slot> slots_;
  std::vector<float> values_;
};

}  // namespace

Soup read_obj(std::string_view bytes, const std::string& name) {
  // Runs of about 1 MB, read on all threads, each numbering its lines from 1 (the join adds
  // the lines before it).
  // Cut after line breaks that no backslash continues.
  const std::vector<std::string_view> text = cut_into_runs(bytes, run_bytes(), [](std::string_view t, std::size_t i) {
    if (i > 0 && t[i - 1] == '\r') --i;
    return i == 0 || t[i - 1] != '\\';
  });
  std::vector<ObjRun> runs(text.size());
  read_runs(runs.size(), [&](std::size_t r) { runs[r].lines = RunReader(text[r], name, 1, runs[r]).read(); });
  return RunJoin(runs, text, name).join();
}

Pieces io_detail::format_obj(const Soup& soup) {
  Pieces pieces;
  soup.check();
  const std::size_t nc = soup.n_corners();
  std::vector<std::size_t> offsets = soup.face_offsets();
  auto face_of_corner = [&] {
    std::vector<std::uint32_t> face(nc);
    for (std::size_t f = 0; f < soup.n_faces(); ++f)
      for (std::size_t c = offsets[f]; c < offsets[f + 1]; ++c) face[c] = static_cast<std::uint32_t>(f);
    return face;
  };

  // Texture coordinates and normals per corner, from whichever domain the soup has them in.
  std::vector<std::uint32_t> vt, vn;
  Dedup<2> uvs;
  Dedup<3> normals;
  if (const Channel* c = find_channel(soup, "uv", Domain::corner, ScalarType::f32, 2)) {
    for (std::size_t i = 0; i < nc; ++i) vt.push_back(uvs.add(c->as<float>() + 2 * i));
  } else if (const Channel* c = find_channel(soup, "uv", Domain::vertex, ScalarType::f32, 2)) {
    for (std::size_t i = 0; i < nc; ++i) vt.push_back(uvs.add(c->as<float>() + 2 * soup.corners[i]));
  }
  if (const Channel* c = find_channel(soup, "normal", Domain::corner, ScalarType::f32, 3)) {
    for (std::size_t i = 0; i < nc; ++i) vn.push_back(normals.add(c->as<float>() + 3 * i));
  } else if (const Channel* c = find_channel(soup, "normal", Domain::vertex, ScalarType::f32, 3)) {
    for (std::size_t i = 0; i < nc; ++i) vn.push_back(normals.add(c->as<float>() + 3 * soup.corners[i]));
  } else if (const Channel* c = find_channel(soup, "normal", Domain::face, ScalarType::f32, 3)) {
    std::vector<std::uint32_t> face = face_of_corner();
    for (std::size_t i = 0; i < nc; ++i) vn.push_back(normals.add(c->as<float>() + 3 * face[i]));
  }
  const Channel* material = find_channel(soup, "material", Domain::face, ScalarType::i32, 1);
  const Channel* color = soup.find("color", Domain::vertex);
  if (color && !(color->components == 4 && (color->scalar == ScalarType::f32 || color->scalar == ScalarType::u8)))
    color = nullptr;

  std::string out = "# written by hedge\n";
  append_elements(pieces, out, soup.n_vertices(), [&](std::string& text, std::size_t v) {
    text += 'v';
    for (int k = 0; k < 3; ++k) {
      text += ' ';
      append_number(text, soup.positions[v][k]);
    }
    if (color) {
      // OBJ has no alpha: it is dropped.
      for (int k = 0; k < 3; ++k) {
        text += ' ';
        if (color->scalar == ScalarType::f32)
          append_number(text, color->as<float>()[4 * v + k]);
        else
          append_number(text, static_cast<float>(color->as<std::uint8_t>()[4 * v + k]) / 255.0f);
      }
    }
    text += '\n';
  });
  append_elements(pieces, out, uvs.values().size() / 2, [&](std::string& text, std::size_t i) {
    text += "vt ";
    append_number(text, uvs.values()[2 * i]);
    text += ' ';
    append_number(text, uvs.values()[2 * i + 1]);
    text += '\n';
  });
  append_elements(pieces, out, normals.values().size() / 3, [&](std::string& text, std::size_t i) {
    text += "vn";
    for (int k = 0; k < 3; ++k) {
      text += ' ';
      append_number(text, normals.values()[3 * i + k]);
    }
    text += '\n';
  });
  append_elements(pieces, out, soup.n_faces(), [&](std::string& text, std::size_t f) {
    if (material) {
      // A face opens a new material group where its material differs from the face before.
      const std::int32_t m = material->as<std::int32_t>()[f];
      if (m != (f == 0 ? -1 : material->as<std::int32_t>()[f - 1])) {
        text += "usemtl ";
        text += m >= 0 ? "material_" + std::to_string(m) : std::string("default");
        text += '\n';
      }
    }
    text += 'f';
    for (std::size_t c = offsets[f]; c < offsets[f + 1]; ++c) {
      text += ' ';
      append_number(text, soup.corners[c] + std::uint64_t{1});
      if (!vt.empty() || !vn.empty()) {
        text += '/';
        if (!vt.empty()) append_number(text, vt[c] + std::uint64_t{1});
        if (!vn.empty()) {
          text += '/';
          append_number(text, vn[c] + std::uint64_t{1});
        }
      }
    }
    text += '\n';
  });
  pieces.parts.push_back(std::move(out));
  return pieces;
}

std::string write_obj(const Soup& soup) { return format_obj(soup).joined(); }

}  // namespace hedge
