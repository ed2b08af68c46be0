// Wavefront OBJ files: positions (with optional vertex colours), per-corner texture
// coordinates and normals, polygons with absolute or relative indices, usemtl as a material id.
#include <algorithm>
#include <array>
#include <cstdint>
#include <cstring>
#include <string>
#include <unordered_map>
#include <vector>

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

class ObjReader {
 public:
  ObjReader(std::string_view bytes, const std::string& name) : in_(bytes, name, '#', true), name_(name) {}

  Soup read() {
    for (;;) {
      in_.skip_space();
      if (in_.at_end()) break;
      std::string_view keyword = in_.line_token();
      if (keyword == "v") {
        read_vertex();
      } else if (keyword == "vt") {
        read_texcoord();
      } else if (keyword == "vn") {
        read_floats(normals_, 3, "3 normal coordinates");
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
    return finish();
  }

 private:
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
    if (n >= 3) {
      if (colors_.empty()) colors_.assign(soup_.positions.size() * 4, 1.0f);
      if (n == 3) extra[3] = 1.0f;
      colors_.insert(colors_.end(), extra, extra + 4);
    } else if (!colors_.empty()) {
      colors_.insert(colors_.end(), {1.0f, 1.0f, 1.0f, 1.0f});
    }
    soup_.positions.push_back(p);
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
    texcoords_.push_back(uvw[0]);
    texcoords_.push_back(uvw[1]);
  }

  void read_floats(std::vector<float>& out, int n, const char* what) {
    for (int k = 0; k < n; ++k) {
      std::string_view t = in_.line_token();
      float v = 0;
      if (!parse_number(t, v)) in_.fail_expected(what, t);
      out.push_back(v);
    }
  }

  //! A 1-based or negative (relative) index into `count` elements defined so far, 0-based.
  std::uint64_t resolve(std::string_view text, std::string_view token, std::size_t count, const char* kind) {
    std::int64_t i = 0;
    if (!parse_number(text, i))
      in_.fail("expected a " + std::string(kind) + " index in " + quote(token) + ", found " + quote(text));
    if (i > 0) {
      if (static_cast<std::uint64_t>(i) > 0xffffffffu)
        in_.fail(std::string(kind) + " index " + std::string(text) + " is too large");
      return static_cast<std::uint64_t>(i - 1);
    }
    if (i == 0) in_.fail("index 0 in " + quote(token) + " is invalid: OBJ indices start at 1");
    if (static_cast<std::uint64_t>(-(i + 1)) >= count)
      in_.fail("relative " + std::string(kind) + " index " + std::string(text) + " points before the first " + kind +
               " (only " + std::to_string(count) + " defined so far)");
    return count - static_cast<std::uint64_t>(-(i + 1)) - 1;
  }

  std::uint32_t attribute(std::string_view text, std::string_view token, std::size_t count, const char* kind,
                          std::vector<Reference>& later) {
    std::uint64_t index = resolve(text, token, count, kind);
    if (index >= count) later.push_back({in_.line(), index});
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
      std::uint64_t v = resolve(parts[0], token, soup_.positions.size(), "vertex");
      soup_.corners.push_back(static_cast<std::uint32_t>(v));
      std::uint32_t vt = kNone, vn = kNone;
      if (n > 1 && !parts[1].empty())
        vt = attribute(parts[1], token, texcoords_.size() / 2, "texture coordinate", later_vt_);
      if (n > 2 && !parts[2].empty()) vn = attribute(parts[2], token, normals_.size() / 3, "normal", later_vn_);
      all_vt_ = all_vt_ && vt != kNone;
      all_vn_ = all_vn_ && vn != kNone;
      if (all_vt_) corner_vt_.push_back(vt);
      if (all_vn_) corner_vn_.push_back(vn);
      ++size;
    }
    if (size == 0) in_.fail("expected vertex indices after 'f', found end of line");
    soup_.face_sizes.push_back(size);
    if (seen_material_) materials_.push_back(material_);
  }

  void use_material() {
    std::string_view name = in_.line_token();
    while (!in_.at_line_end()) in_.line_token();  // names with spaces: the first word decides
    auto [it, added] = material_ids_.try_emplace(std::string(name), static_cast<std::int32_t>(material_ids_.size()));
    material_ = it->second;
    if (!seen_material_) materials_.assign(soup_.face_sizes.size(), -1);
    seen_material_ = true;
  }

  void check_later(const std::vector<Reference>& later, std::size_t count, const char* kind) {
    for (const Reference& r : later)
      if (r.index >= count)
        fail_line(name_, r.line,
                  std::string(kind) + " index " + std::to_string(r.index + 1) + " is out of range: the file defines " +
                      std::to_string(count));
  }

  Soup finish() {
    check_later(later_vt_, texcoords_.size() / 2, "texture coordinate");
    check_later(later_vn_, normals_.size() / 3, "normal");
    if (!colors_.empty()) {
      Channel& c = soup_.add_channel("color", Domain::vertex, ScalarType::f32, 4);
      std::memcpy(c.data.data(), colors_.data(), colors_.size() * sizeof(float));
    }
    if (seen_material_) {
      Channel& c = soup_.add_channel("material", Domain::face, ScalarType::i32, 1);
      if (!materials_.empty()) std::memcpy(c.data.data(), materials_.data(), materials_.size() * sizeof(std::int32_t));
    }
    if (all_vt_ && soup_.n_corners() > 0) {
      Channel& c = soup_.add_channel("uv", Domain::corner, ScalarType::f32, 2);
      float* uv = c.as<float>();
      for (std::size_t i = 0; i < corner_vt_.size(); ++i)
        std::memcpy(uv + 2 * i, &texcoords_[2 * corner_vt_[i]], 2 * sizeof(float));
    }
    if (all_vn_ && soup_.n_corners() > 0) {
      Channel& c = soup_.add_channel("normal", Domain::corner, ScalarType::f32, 3);
      float* n = c.as<float>();
      for (std::size_t i = 0; i < corner_vn_.size(); ++i)
        std::memcpy(n + 3 * i, &normals_[3 * corner_vn_[i]], 3 * sizeof(float));
    }
    check_soup(soup_, name_);
    return std::move(soup_);
  }

  TextScanner in_;
  const std::string& name_;
  Soup soup_;
  std::vector<float> colors_;     // 4 per vertex once any vertex has a colour
  std::vector<float> texcoords_;  // 2 per vt
  std::vector<float> normals_;    // 3 per vn
  std::vector<std::uint32_t> corner_vt_, corner_vn_;
  std::vector<Reference> later_vt_, later_vn_;
  bool all_vt_ = true, all_vn_ = true;
  std::unordered_map<std::string, std::int32_t> material_ids_;
  std::vector<std::int32_t> materials_;
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

Soup read_obj(std::string_view bytes, const std::string& name) { return ObjReader(bytes, name).read(); }

std::string write_obj(const Soup& soup) {
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
  append_elements(out, soup.n_vertices(), [&](std::string& text, std::size_t v) {
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
  append_elements(out, uvs.values().size() / 2, [&](std::string& text, std::size_t i) {
    text += "vt ";
    append_number(text, uvs.values()[2 * i]);
    text += ' ';
    append_number(text, uvs.values()[2 * i + 1]);
    text += '\n';
  });
  append_elements(out, normals.values().size() / 3, [&](std::string& text, std::size_t i) {
    text += "vn";
    for (int k = 0; k < 3; ++k) {
      text += ' ';
      append_number(text, normals.values()[3 * i + k]);
    }
    text += '\n';
  });
  append_elements(out, soup.n_faces(), [&](std::string& text, std::size_t f) {
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
  return out;
}

}  // namespace hedge
