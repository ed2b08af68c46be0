// PLY files (Stanford polygon format) in ASCII, binary little endian and binary big endian:
// positions, faces with any list types, vertex normals/colours/quality/uv, face colours/
// quality/material, per-corner uv (MeshLab's texcoord list), and a vertex or face "selected"
// (any scalar, non-zero when selected; hedge's own convention); anything else is skipped.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "hedge/detail/memory.h"
#include "hedge/io.h"
#include "hedge/limits.h"
#include "io_detail.h"

namespace hedge {

using namespace io_detail;

namespace {

enum class PlyType : std::uint8_t { i8, u8, i16, u16, i32, u32, f32, f64 };

std::size_t type_size(PlyType t) {
  switch (t) {
    case PlyType::i8:
    case PlyType::u8:
      return 1;
    case PlyType::i16:
    case PlyType::u16:
      return 2;
    case PlyType::i32:
    case PlyType::u32:
    case PlyType::f32:
      return 4;
    case PlyType::f64:
      return 8;
  }
  return 1;
}

bool is_real(PlyType t) { return t == PlyType::f32 || t == PlyType::f64; }

bool parse_type(std::string_view s, PlyType& t) {
  static const struct {
    const char* name;
    PlyType type;
  } names[] = {{"char", PlyType::i8},   {"int8", PlyType::i8},     {"uchar", PlyType::u8},   {"uint8", PlyType::u8},
               {"short", PlyType::i16}, {"int16", PlyType::i16},   {"ushort", PlyType::u16}, {"uint16", PlyType::u16},
               {"int", PlyType::i32},   {"int32", PlyType::i32},   {"uint", PlyType::u32},   {"uint32", PlyType::u32},
               {"float", PlyType::f32}, {"float32", PlyType::f32}, {"double", PlyType::f64}, {"float64", PlyType::f64}};
  for (const auto& n : names)
    if (s == n.name) {
      t = n.type;
      return true;
    }
  return false;
}

const char* type_name(PlyType t) {
  switch (t) {
    case PlyType::i8:
      return "char";
    case PlyType::u8:
      return "uchar";
    case PlyType::i16:
      return "short";
    case PlyType::u16:
      return "ushort";
    case PlyType::i32:
      return "int";
    case PlyType::u32:
      return "uint";
    case PlyType::f32:
      return "float";
    case PlyType::f64:
      return "double";
  }
  return "?";
}

enum class Target : std::uint8_t { skip, position, normal, color, quality, uv, indices, texcoord, material, selected };

struct PlyProperty {
  std::string name;
  bool list = false;
  PlyType count_type = PlyType::u8;
  PlyType type = PlyType::f32;
  Target target = Target::skip;
  int component = 0;
};

enum class Kind : std::uint8_t { other, vertex, face };

struct PlyElement {
  std::string name;
  std::uint64_t count = 0;
  std::size_t line = 0;
  Kind kind = Kind::other;
  std::vector<PlyProperty> properties;

  PlyProperty* find(std::string_view n) {
    for (auto& p : properties)
      if (p.name == n) return &p;
    return nullptr;
  }
};

enum class Encoding { ascii, binary_little_endian, binary_big_endian };

struct Header {
  Encoding encoding = Encoding::ascii;
  std::vector<PlyElement> elements;
  std::size_t body = 0;       // offset of the first byte after end_header
  std::size_t body_line = 0;  // line number of that byte
};

std::vector<std::string_view> split(std::string_view line) {
  std::vector<std::string_view> words;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
    std::size_t start = i;
    while (i < line.size() && line[i] != ' ' && line[i] != '\t') ++i;
    if (i > start) words.push_back(line.substr(start, i - start));
  }
  return words;
}

Header parse_header(std::string_view bytes, const std::string& name) {
  Header header;
  std::size_t pos = 0;
  std::size_t line_number = 0;
  bool have_format = false;
  for (;;) {
    ++line_number;
    if (pos >= bytes.size()) {
      if (line_number == 1) fail_line(name, 1, "expected 'ply', found an empty file");
      fail_line(name, line_number, "the header ends without 'end_header'");
    }
    std::size_t nl = bytes.find('\n', pos);
    std::string_view line(bytes.data() + pos, (nl == std::string_view::npos ? bytes.size() : nl) - pos);
    pos = nl == std::string_view::npos ? bytes.size() : nl + 1;
    while (!line.empty() && (line.back() == '\r' || line.back() == ' ' || line.back() == '\t')) line.remove_suffix(1);
    auto fail = [&](const std::string& what) { fail_line(name, line_number, what); };

    if (line_number == 1) {
      if (line != "ply") fail("expected 'ply' (this is not a PLY file), found " + quote(line));
      continue;
    }
    std::vector<std::string_view> w = split(line);
    if (w.empty() || w[0] == "comment" || w[0] == "obj_info") continue;
    if (w[0] == "format") {
      if (w.size() != 3) fail("expected 'format ascii 1.0' or 'format binary_little_endian 1.0', found " + quote(line));
      if (w[1] == "ascii")
        header.encoding = Encoding::ascii;
      else if (w[1] == "binary_little_endian")
        header.encoding = Encoding::binary_little_endian;
      else if (w[1] == "binary_big_endian")
        header.encoding = Encoding::binary_big_endian;
      else
        fail("expected ascii, binary_little_endian or binary_big_endian, found " + quote(w[1]));
      have_format = true;
    } else if (w[0] == "element") {
      PlyElement e;
      if (w.size() != 3 || !parse_number(w[2], e.count))
        fail("expected 'element <name> <count>', found " + quote(line));
      e.name = std::string(w[1]);
      e.line = line_number;
      header.elements.push_back(std::move(e));
    } else if (w[0] == "property") {
      if (header.elements.empty()) fail("property before the first element");
      PlyProperty p;
      if (w.size() >= 2 && w[1] == "list") {
        if (w.size() != 5) fail("expected 'property list <count type> <value type> <name>', found " + quote(line));
        p.list = true;
        if (!parse_type(w[2], p.count_type)) fail("unknown property type " + quote(w[2]));
        if (is_real(p.count_type)) fail("the count type of a list must be an integer type, found " + quote(w[2]));
        if (!parse_type(w[3], p.type)) fail("unknown property type " + quote(w[3]));
        p.name = std::string(w[4]);
      } else {
        if (w.size() != 3) fail("expected 'property <type> <name>', found " + quote(line));
        if (!parse_type(w[1], p.type)) fail("unknown property type " + quote(w[1]));
        p.name = std::string(w[2]);
      }
      header.elements.back().properties.push_back(std::move(p));
    } else if (w[0] == "end_header") {
      if (!have_format) fail("the header has no 'format' line");
      header.body = pos;
      header.body_line = line_number + 1;
      return header;
    } else {
      fail("expected comment, element, property or end_header, found " + quote(w[0]));
    }
  }
}

//! Points the properties PLY files commonly use at the soup channels they fill.
void assign_targets(Header& header, const std::string& name) {
  bool have_vertex = false, have_face = false;
  for (PlyElement& e : header.elements) {
    auto fail = [&](const std::string& what) { fail_line(name, e.line, what); };
    auto scalar = [&](std::string_view n) {
      PlyProperty* p = e.find(n);
      return p && !p->list && p->target == Target::skip ? p : nullptr;
    };
    // A group of scalar properties that only counts when all its members are there.
    auto group = [&](std::initializer_list<const char*> names, Target target) {
      std::vector<PlyProperty*> found;
      for (const char* n : names) {
        PlyProperty* p = scalar(n);
        if (!p) return false;
        found.push_back(p);
      }
      for (std::size_t k = 0; k < found.size(); ++k) {
        found[k]->target = target;
        found[k]->component = static_cast<int>(k);
      }
      return true;
    };
    auto color = [&] {
      if (group({"red", "green", "blue"}, Target::color) ||
          group({"diffuse_red", "diffuse_green", "diffuse_blue"}, Target::color)) {
        if (PlyProperty* a = scalar("alpha")) {
          a->target = Target::color;
          a->component = 3;
        }
      }
    };
    if (e.name == "vertex") {
      if (have_vertex) fail("a second element 'vertex'");
      have_vertex = true;
      e.kind = Kind::vertex;
      if (e.count > kMaxElements) fail(limit_message(e.count, kMaxElements, "vertices"));
      for (const char* axis : {"x", "y", "z"})
        if (!scalar(axis)) fail("element 'vertex' has no scalar property '" + std::string(axis) + "'");
      group({"x", "y", "z"}, Target::position);
      group({"nx", "ny", "nz"}, Target::normal);
      color();
      if (PlyProperty* q = scalar("quality"))
        q->target = Target::quality;
      else if (PlyProperty* c = scalar("confidence"))
        c->target = Target::quality;
      group({"texture_u", "texture_v"}, Target::uv) || group({"u", "v"}, Target::uv) || group({"s", "t"}, Target::uv);
      if (PlyProperty* s = scalar("selected")) s->target = Target::selected;
    } else if (e.name == "face") {
      if (have_face) fail("a second element 'face'");
      have_face = true;
      e.kind = Kind::face;
      if (e.count > kMaxFaces) fail(limit_message(e.count, kMaxFaces, "faces"));
      PlyProperty* indices = e.find("vertex_indices");
      if (!indices) indices = e.find("vertex_index");
      if (indices && indices->list)
        indices->target = Target::indices;
      else if (e.count > 0)
        fail("element 'face' has no list property 'vertex_indices'");
      color();
      if (PlyProperty* q = scalar("quality")) q->target = Target::quality;
      if (PlyProperty* m = scalar("material_index")) m->target = Target::material;
      if (PlyProperty* t = e.find("texcoord"); t && t->list) t->target = Target::texcoord;
      if (PlyProperty* s = scalar("selected")) s->target = Target::selected;
    }
  }
}

//! Refuses counts the rest of the file cannot hold before anything is allocated.
void check_counts(const Header& header, std::size_t body_bytes, const std::string& name) {
  bool ascii = header.encoding == Encoding::ascii;
  std::uint64_t total = 0;
  for (const PlyElement& e : header.elements) {
    std::uint64_t per_instance = 0;
    for (const PlyProperty& p : e.properties)
      per_instance += ascii ? 2 : type_size(p.list ? p.count_type : p.type);  // a value and a space at least
    std::uint64_t bytes = 0;
    if (__builtin_mul_overflow(per_instance, e.count, &bytes) || __builtin_add_overflow(total, bytes, &total) ||
        total > body_bytes + (ascii ? 1 : 0))
      fail_line(name, e.line,
                "element '" + e.name + "' declares " + std::to_string(e.count) +
                    " instances, more than the rest of the file can hold (only " + plural(body_bytes, "byte") +
                    " follow the header): the file is truncated or its header is wrong");
  }
}

//! Where values go while reading; channels are made from these at the end.
struct Sink {
  explicit Sink(Soup& s) : soup(s) {}
  Soup& soup;
  std::vector<float> normals, vertex_quality, vertex_uv, face_quality, corner_uv, texcoord;
  std::vector<std::uint8_t> vertex_color, face_color, vertex_selected, face_selected;
  std::vector<std::int32_t> material;
  bool has_normal = false, has_vertex_color = false, has_vertex_quality = false, has_vertex_uv = false;
  bool has_face_color = false, has_face_quality = false, has_material = false, has_texcoord = false;
  bool has_vertex_selected = false, has_face_selected = false;
  // The first vertex and face these arrays hold (a run of the file holds a range of each).
  std::uint64_t vertex_base = 0, face_base = 0;

  //! Which channels the header's properties fill.
  void take_targets(const Header& header) {
    for (const PlyElement& e : header.elements)
      for (const PlyProperty& p : e.properties) {
        if (e.kind == Kind::vertex) {
          has_normal |= p.target == Target::normal;
          has_vertex_color |= p.target == Target::color;
          has_vertex_quality |= p.target == Target::quality;
          has_vertex_uv |= p.target == Target::uv;
          has_vertex_selected |= p.target == Target::selected;
        } else if (e.kind == Kind::face) {
          has_face_color |= p.target == Target::color;
          has_face_quality |= p.target == Target::quality;
          has_material |= p.target == Target::material;
          has_texcoord |= p.target == Target::texcoord;
          has_face_selected |= p.target == Target::selected;
        }
      }
  }
  //! Room for nv vertices and nf faces, with their defaults.
  void size(std::uint64_t nv, std::uint64_t nf) {
    using detail::resize_on_huge_pages;
    resize_on_huge_pages(soup.positions, nv);
    if (has_normal) resize_on_huge_pages(normals, 3 * nv);
    if (has_vertex_color) resize_on_huge_pages(vertex_color, 4 * nv, 255);
    if (has_vertex_quality) resize_on_huge_pages(vertex_quality, nv);
    if (has_vertex_uv) resize_on_huge_pages(vertex_uv, 2 * nv);
    if (has_face_color) resize_on_huge_pages(face_color, 4 * nf, 255);
    if (has_face_quality) resize_on_huge_pages(face_quality, nf);
    if (has_material) resize_on_huge_pages(material, nf);
    if (has_vertex_selected) resize_on_huge_pages(vertex_selected, nv);
    if (has_face_selected) resize_on_huge_pages(face_selected, nf);
    detail::reserve_on_huge_pages(soup.face_sizes, nf);
  }
};

//! Context for error messages: which element, instance and property is being read.
struct Place {
  const PlyElement* element = nullptr;
  std::uint64_t instance = 0;
  const PlyProperty* property = nullptr;

  std::string describe() const {
    return element->name + " " + std::to_string(instance) + " (of " + std::to_string(element->count) + "), property '" +
           property->name + "'";
  }
};

class AsciiSource {
 public:
  AsciiSource(std::string_view bytes, const Header& header, const std::string& name, const Place& place)
      : in_(bytes.substr(header.body), name), place_(place), line_offset_(header.body_line - 1) {}
  //! A run of the body's lines, one element each: a value past its line, or a line with
  //! values left after its element, throws Irregular.
  AsciiSource(std::string_view run, const std::string& name, const Place& place)
      : in_(run, name), place_(place), line_offset_(0), one_per_line_(true) {}

  //! After each element.
  void end_element() {
    if (!one_per_line_) return;
    if (!in_.at_line_end()) throw Irregular{};
    in_.next_line();
  }
  //! What follows a run's elements: blank lines only (the last run: the end of the file).
  void only_blank_lines() {
    in_.skip_space();
    if (!in_.at_end()) throw Irregular{};
  }

  double number(PlyType t) {
    std::string_view token = next(t);
    if (t == PlyType::f32) {
      float v;
      if (parse_number(token, v)) return v;
    } else if (t == PlyType::f64) {
      double v;
      if (parse_number(token, v)) return v;
    } else {
      std::int64_t v;
      if (parse_number(token, v)) return static_cast<double>(v);
      double d;  // some writers print integers as 3.0
      if (parse_number(token, d) && d == std::floor(d)) return d;
    }
    fail_expected(t, token);
  }

  std::uint64_t count(PlyType t) {
    std::string_view token = next(t);
    std::uint64_t v;
    if (!parse_number(token, v)) {
      std::int64_t s;
      if (parse_number(token, s)) fail("negative list length " + std::string(token) + " in " + place_.describe());
      fail_expected(t, token);
    }
    return v;
  }

  std::int64_t integer(PlyType t) {
    std::string_view token = next(t);
    std::int64_t v;
    if (parse_number(token, v)) return v;
    double d;
    if (parse_number(token, d) && d == std::floor(d) && std::abs(d) < 9e15) return static_cast<std::int64_t>(d);
    fail_expected(t, token);
  }

  void skip(PlyType t, std::uint64_t n = 1) {
    for (std::uint64_t i = 0; i < n; ++i) next(t);
  }

  //! After the last element only white space may follow: anything else means the header
  //! and the data disagree.
  void finish() {
    in_.skip_space();
    if (!in_.at_end())
      fail("expected the end of the file after the last element, found " + quote(in_.line_token()) +
           " (are there more values than the header declares?)");
  }

  [[noreturn]] void fail(const std::string& what) const {
    fail_line(in_.name(), in_.error_line() + line_offset_, what);
  }

 private:
  std::string_view next(PlyType t) {
    std::string_view token = one_per_line_ ? in_.line_token() : in_.token();
    if (token.empty()) {
      if (one_per_line_) throw Irregular{};
      fail("file ends, expected " + std::string(type_name(t)) + " for " + place_.describe());
    }
    return token;
  }

  [[noreturn]] void fail_expected(PlyType t, std::string_view token) const {
    fail("expected " + std::string(type_name(t)) + " for " + place_.describe() + ", found " + quote(token));
  }

  TextScanner in_;
  const Place& place_;
  std::size_t line_offset_;
  bool one_per_line_ = false;
};

template <bool BigEndian>
class BinarySource {
 public:
  BinarySource(std::string_view bytes, const Header& header, const std::string& name, const Place& place)
      : begin_(reinterpret_cast<const unsigned char*>(bytes.data())),
        p_(begin_ + header.body),
        end_(begin_ + bytes.size()),
        name_(name),
        place_(place) {}

  double number(PlyType t) {
    if (t == PlyType::f32) return get<float>();
    if (t == PlyType::f64) return get<double>();
    return static_cast<double>(integer(t));  // every integer type
  }

  std::uint64_t count(PlyType t) {
    const unsigned char* at = p_;
    std::int64_t v = integer(t);
    if (v < 0) fail_at(at, "negative list length " + std::to_string(v) + " in " + place_.describe());
    return static_cast<std::uint64_t>(v);
  }

  std::int64_t integer(PlyType t) {
    switch (t) {
      case PlyType::i8:
        return get<std::int8_t>();
      case PlyType::u8:
        return get<std::uint8_t>();
      case PlyType::i16:
        return get<std::int16_t>();
      case PlyType::u16:
        return get<std::uint16_t>();
      case PlyType::i32:
        return get<std::int32_t>();
      case PlyType::u32:
        return get<std::uint32_t>();
      default:
        break;
    }
    const unsigned char* at = p_;
    double d = number(t);
    if (!(d == std::floor(d) && std::abs(d) < 9e15)) fail_at(at, "expected a whole number for " + place_.describe());
    return static_cast<std::int64_t>(d);
  }

  void skip(PlyType t, std::uint64_t n = 1) {
    std::size_t size = type_size(t);
    if (n > static_cast<std::size_t>(end_ - p_) / size) fail_at(end_, "file ends inside " + place_.describe());
    p_ += n * size;
  }

  void finish() {}  // bytes after the last element are padding some writers add
  void end_element() {}

  [[noreturn]] void fail(const std::string& what) const { fail_at(p_, what); }

 private:
  template <class T>
  T get() {
    if (static_cast<std::size_t>(end_ - p_) < sizeof(T)) fail_at(end_, "file ends inside " + place_.describe());
    T v = load<T>(p_, BigEndian);
    p_ += sizeof(T);
    return v;
  }

  [[noreturn]] void fail_at(const unsigned char* at, const std::string& what) const {
    fail_byte(name_, static_cast<std::size_t>(at - begin_), what);
  }

  const unsigned char* begin_;
  const unsigned char* p_;
  const unsigned char* end_;
  const std::string& name_;
  const Place& place_;
};

//! Reads the body's elements [first, last), counted over every element with data, into
//! `sink` (whose arrays start at its vertex and face bases).
template <class Source>
void read_body(Source& in, const Header& header, Place& place, Sink& sink, std::uint64_t first = 0,
               std::uint64_t last = std::numeric_limits<std::uint64_t>::max()) {
  Soup& soup = sink.soup;
  std::uint64_t before = 0;  // instances of the elements before e
  for (const PlyElement& e : header.elements) {
    place.element = &e;
    if (e.properties.empty()) continue;  // no data at all, whatever the count
    const std::uint64_t begin = std::clamp(first, before, before + e.count) - before;
    const std::uint64_t end = std::clamp(last, before, before + e.count) - before;
    before += e.count;
    const std::uint64_t base = e.kind == Kind::vertex ? sink.vertex_base : e.kind == Kind::face ? sink.face_base : 0;
    for (std::uint64_t i = begin; i < end; ++i) {
      place.instance = i;
      const std::uint64_t at = i - base;
      std::uint32_t face_size = 0;
      if (e.kind == Kind::face) sink.texcoord.clear();
      for (const PlyProperty& p : e.properties) {
        place.property = &p;
        if (p.list) {
          std::uint64_t n = in.count(p.count_type);
          if (p.target == Target::indices) {
            if (n > 0xffffffffu) in.fail("a face of " + std::to_string(n) + " vertices in " + place.describe());
            for (std::uint64_t k = 0; k < n; ++k) {
              std::int64_t v = in.integer(p.type);
              if (v < 0 || v > 0xffffffffll)
                in.fail("vertex index " + std::to_string(v) + " cannot be an index, in " + place.describe());
              soup.corners.push_back(static_cast<std::uint32_t>(v));
            }
            face_size = static_cast<std::uint32_t>(n);
          } else if (p.target == Target::texcoord) {
            for (std::uint64_t k = 0; k < n; ++k) sink.texcoord.push_back(static_cast<float>(in.number(p.type)));
          } else {
            in.skip(p.type, n);
          }
          continue;
        }
        if (p.target == Target::skip) {
          in.skip(p.type);
          continue;
        }
        double v = in.number(p.type);
        const int k = p.component;
        if (e.kind == Kind::vertex) {
          switch (p.target) {
            case Target::position:
              soup.positions[at][k] = static_cast<float>(v);
              break;
            case Target::normal:
              sink.normals[3 * at + k] = static_cast<float>(v);
              break;
            case Target::color:
              sink.vertex_color[4 * at + k] = is_real(p.type) ? color_from_real(v) : color_from_integer(v);
              break;
            case Target::quality:
              sink.vertex_quality[at] = static_cast<float>(v);
              break;
            case Target::uv:
              sink.vertex_uv[2 * at + k] = static_cast<float>(v);
              break;
            case Target::selected:
              sink.vertex_selected[at] = v != 0;
              break;
            default:
              break;
          }
        } else {
          switch (p.target) {
            case Target::color:
              sink.face_color[4 * at + k] = is_real(p.type) ? color_from_real(v) : color_from_integer(v);
              break;
            case Target::quality:
              sink.face_quality[at] = static_cast<float>(v);
              break;
            case Target::material:
              sink.material[at] = static_cast<std::int32_t>(std::clamp(v, -2147483648.0, 2147483647.0));
              break;
            case Target::selected:
              sink.face_selected[at] = v != 0;
              break;
            default:
              break;
          }
        }
      }
      if (e.kind == Kind::face) {
        soup.face_sizes.push_back(face_size);
        if (sink.has_texcoord) {
          // MeshLab writes two values per corner; a face without texture has none.
          if (sink.texcoord.empty()) {
            sink.corner_uv.resize(sink.corner_uv.size() + 2 * std::size_t{face_size}, 0.0f);
          } else if (sink.texcoord.size() == 2 * std::size_t{face_size}) {
            sink.corner_uv.insert(sink.corner_uv.end(), sink.texcoord.begin(), sink.texcoord.end());
          } else {
            in.fail("face " + std::to_string(i) + " has " + std::to_string(face_size) + " corners but " +
                    plural(sink.texcoord.size(), "texture coordinate") + " (expected two per corner)");
          }
        }
      }
      in.end_element();
    }
  }
}

//! The text body read in runs of about 1 MB of lines on all threads, each line one element:
//! the arrays one pass would fill, in `sink`. False, with `sink` as it was, when the body is
//! small, there is one thread, or the body holds an element over several lines or several on
//! one, or has an error: one pass then reads it (and names the error).
bool read_text_in_runs(std::string_view bytes, const Header& header, const std::string& name, Sink& sink) {
  const std::string_view body = bytes.substr(header.body);
  // On one thread the runs' joining would only add to one pass.
  if (body.size() < 2 * run_bytes() || resolve_thread_count(0) < 2) return false;
  // The instances in body order, and where the vertices and the faces start among them.
  std::uint64_t total = 0, first_vertex = 0, first_face = 0, nv = 0, nf = 0;
  for (const PlyElement& e : header.elements) {
    if (e.properties.empty()) {
      if (e.count > 0) return false;
      continue;
    }
    if (e.kind == Kind::vertex) first_vertex = total, nv = e.count;
    if (e.kind == Kind::face) first_face = total, nf = e.count;
    total += e.count;
  }
  // One element a line.
  const LineRuns lines = cut_into_line_runs(body, [](std::string_view run) {
    return std::uint64_t(std::count(run.begin(), run.end(), '\n')) + (run.back() != '\n');
  });
  const std::vector<std::string_view>& text = lines.text;
  const std::vector<std::uint64_t>& first = lines.first;
  if (first.back() < total) return false;  // fewer lines than elements

  struct Run {
    Soup soup;
    Sink sink{soup};
  };
  std::vector<std::unique_ptr<Run>> runs(text.size());
  const bool regular = read_runs_or_give_way(runs.size(), [&](std::size_t r) {
    runs[r] = std::make_unique<Run>();
    Run& run = *runs[r];
    const std::uint64_t a = std::min(first[r], total), b = std::min(first[r + 1], total);
    auto range = [&](std::uint64_t start, std::uint64_t n, std::uint64_t x) {
      return std::clamp(x, start, start + n) - start;
    };
    Sink& s = run.sink;
    s.take_targets(header);
    s.vertex_base = range(first_vertex, nv, a), s.face_base = range(first_face, nf, a);
    s.size(range(first_vertex, nv, b) - s.vertex_base, range(first_face, nf, b) - s.face_base);
    s.soup.corners.reserve(3 * (range(first_face, nf, b) - s.face_base));  // triangles need no regrowth
    Place place;
    AsciiSource in(text[r], name, place);
    read_body(in, header, place, s, a, b);
    in.only_blank_lines();
  });
  if (!regular) return false;

  // Joined in order: vertex and face arrays at their bases, corners one after another.
  std::vector<std::uint64_t> corners_before(runs.size() + 1, 0);
  for (std::size_t r = 0; r < runs.size(); ++r)
    corners_before[r + 1] = corners_before[r] + runs[r]->soup.corners.size();
  Soup& soup = sink.soup;
  soup.face_sizes.resize(nf);
  soup.corners.resize(corners_before.back());
  if (sink.has_texcoord) sink.corner_uv.resize(2 * corners_before.back());
  parallel_for(
      runs.size(), 0,
      [&](std::size_t begin, std::size_t end) {
        for (std::size_t r = begin; r < end; ++r) {
          const Sink& s = runs[r]->sink;
          const std::uint64_t v = s.vertex_base, f = s.face_base, c = corners_before[r];
          auto put = [](const auto& from, auto& to, std::uint64_t at) {
            if (!from.empty()) std::copy(from.begin(), from.end(), to.begin() + std::ptrdiff_t(at));
          };
          put(s.soup.positions, soup.positions, v);
          put(s.normals, sink.normals, 3 * v);
          put(s.vertex_color, sink.vertex_color, 4 * v);
          put(s.vertex_quality, sink.vertex_quality, v);
          put(s.vertex_uv, sink.vertex_uv, 2 * v);
          put(s.vertex_selected, sink.vertex_selected, v);
          put(s.soup.face_sizes, soup.face_sizes, f);
          put(s.face_color, sink.face_color, 4 * f);
          put(s.face_quality, sink.face_quality, f);
          put(s.material, sink.material, f);
          put(s.face_selected, sink.face_selected, f);
          put(s.soup.corners, soup.corners, c);
          put(s.corner_uv, sink.corner_uv, 2 * c);
        }
      },
      1);
  return true;
}

}  // namespace

Soup read_ply(std::string_view bytes, const std::string& name) {
  Header header = parse_header(bytes, name);
  assign_targets(header, name);
  const std::size_t body_bytes = bytes.size() - header.body;
  check_counts(header, body_bytes, name);

  Soup soup;
  Sink sink(soup);
  sink.take_targets(header);
  std::uint64_t nv = 0, nf = 0;
  for (const PlyElement& e : header.elements) {
    if (e.kind == Kind::vertex) nv = e.count;
    if (e.kind == Kind::face) nf = e.count;
  }
  // check_counts() bounds these by the file size.
  sink.size(nv, nf);
  std::size_t index_bytes = 2;
  for (const PlyElement& e : header.elements)
    if (e.kind == Kind::face)
      for (const PlyProperty& p : e.properties)
        if (p.target == Target::indices && header.encoding != Encoding::ascii) index_bytes = type_size(p.type);
  detail::reserve_on_huge_pages(soup.corners, std::min<std::uint64_t>(3 * nf, body_bytes / index_bytes));

  Place place;
  switch (header.encoding) {
    case Encoding::ascii: {
      if (read_text_in_runs(bytes, header, name, sink)) break;
      AsciiSource in(bytes, header, name, place);
      read_body(in, header, place, sink);
      in.finish();
      break;
    }
    case Encoding::binary_little_endian: {
      BinarySource<false> in(bytes, header, name, place);
      read_body(in, header, place, sink);
      break;
    }
    case Encoding::binary_big_endian: {
      BinarySource<true> in(bytes, header, name, place);
      read_body(in, header, place, sink);
      break;
    }
  }

  auto add = [&](const char* channel_name, Domain domain, ScalarType scalar, int components, const auto& values) {
    Channel& c = soup.add_channel(channel_name, domain, scalar, components);
    if (!c.data.empty()) std::memcpy(c.data.data(), values.data(), c.data.size());
  };
  if (sink.has_normal) add("normal", Domain::vertex, ScalarType::f32, 3, sink.normals);
  if (sink.has_vertex_color) add("color", Domain::vertex, ScalarType::u8, 4, sink.vertex_color);
  if (sink.has_vertex_quality) add("quality", Domain::vertex, ScalarType::f32, 1, sink.vertex_quality);
  if (sink.has_vertex_uv) add("uv", Domain::vertex, ScalarType::f32, 2, sink.vertex_uv);
  if (sink.has_face_color) add("color", Domain::face, ScalarType::u8, 4, sink.face_color);
  if (sink.has_face_quality) add("quality", Domain::face, ScalarType::f32, 1, sink.face_quality);
  if (sink.has_material) add("material", Domain::face, ScalarType::i32, 1, sink.material);
  if (sink.has_texcoord) add("uv", Domain::corner, ScalarType::f32, 2, sink.corner_uv);
  if (sink.has_vertex_selected) add("selected", Domain::vertex, ScalarType::u8, 1, sink.vertex_selected);
  if (sink.has_face_selected) add("selected", Domain::face, ScalarType::u8, 1, sink.face_selected);
  check_soup(soup, name);
  return soup;
}

namespace {

//! Appends values in the body's encoding: little-endian bytes, or text separated by spaces.
class Writer {
 public:
  Writer(std::string& out, bool binary) : out_(out), binary_(binary) {}

  template <class T>
  void value(T v) {
    if (binary_) {
      append_le(out_, v);
    } else {
      if (!first_) out_ += ' ';
      first_ = false;
      if constexpr (sizeof(T) == 1)
        append_number(out_, static_cast<int>(v));
      else
        append_number(out_, v);
    }
  }
  void end_element() {
    if (!binary_) out_ += '\n';
    first_ = true;
  }

 private:
  std::string& out_;
  bool binary_;
  bool first_ = true;
};

}  // namespace

Pieces io_detail::format_ply(const Soup& soup, bool binary) {
  Pieces pieces;
  soup.check();
  const Channel* normals = find_channel(soup, "normal", Domain::vertex, ScalarType::f32, 3);
  ColorView colors = find_color(soup, Domain::vertex);
  const Channel* quality = find_channel(soup, "quality", Domain::vertex, ScalarType::f32, 1);
  const Channel* uvs = find_channel(soup, "uv", Domain::vertex, ScalarType::f32, 2);
  ColorView face_colors = find_color(soup, Domain::face);
  const Channel* face_quality = find_channel(soup, "quality", Domain::face, ScalarType::f32, 1);
  const Channel* material = find_channel(soup, "material", Domain::face, ScalarType::i32, 1);
  const Channel* corner_uvs = find_channel(soup, "uv", Domain::corner, ScalarType::f32, 2);
  const Channel* selected = find_channel(soup, "selected", Domain::vertex, ScalarType::u8, 1);
  const Channel* face_selected = find_channel(soup, "selected", Domain::face, ScalarType::u8, 1);

  std::uint32_t max_size = 0;
  for (std::uint32_t s : soup.face_sizes) max_size = std::max(max_size, s);
  const bool small_faces = max_size <= 255;
  const bool small_texcoords = 2ull * max_size <= 255;
  const bool signed_indices = soup.n_vertices() <= 0x7fffffffu;

  std::string out;
  out += "ply\nformat ";
  out += binary ? "binary_little_endian" : "ascii";
  out += " 1.0\ncomment written by hedge\nelement vertex " + std::to_string(soup.n_vertices()) + "\n";
  out += "property float x\nproperty float y\nproperty float z\n";
  if (normals) out += "property float nx\nproperty float ny\nproperty float nz\n";
  if (colors) out += "property uchar red\nproperty uchar green\nproperty uchar blue\nproperty uchar alpha\n";
  if (quality) out += "property float quality\n";
  if (uvs) out += "property float texture_u\nproperty float texture_v\n";
  if (selected) out += "property uchar selected\n";
  out += "element face " + std::to_string(soup.n_faces()) + "\n";
  out += std::string("property list ") + (small_faces ? "uchar" : "uint") + (signed_indices ? " int" : " uint") +
         " vertex_indices\n";
  if (corner_uvs) out += std::string("property list ") + (small_texcoords ? "uchar" : "uint") + " float texcoord\n";
  if (face_colors) out += "property uchar red\nproperty uchar green\nproperty uchar blue\nproperty uchar alpha\n";
  if (face_quality) out += "property float quality\n";
  if (material) out += "property int material_index\n";
  if (face_selected) out += "property uchar selected\n";
  out += "end_header\n";
  append_elements(pieces, out, soup.n_vertices(), [&](std::string& text, std::size_t v) {
    Writer w(text, binary);
    for (int k = 0; k < 3; ++k) w.value(soup.positions[v][k]);
    if (normals)
      for (int k = 0; k < 3; ++k) w.value(normals->as<float>()[3 * v + k]);
    if (colors)
      for (std::uint8_t c : colors[v]) w.value(c);
    if (quality) w.value(quality->as<float>()[v]);
    if (uvs)
      for (int k = 0; k < 2; ++k) w.value(uvs->as<float>()[2 * v + k]);
    if (selected) w.value(selected->as<std::uint8_t>()[v]);
    w.end_element();
  });
  const std::vector<std::size_t> offsets = soup.face_offsets();
  append_elements(pieces, out, soup.n_faces(), [&](std::string& text, std::size_t f) {
    Writer w(text, binary);
    const std::size_t corner = offsets[f];
    const std::uint32_t size = soup.face_sizes[f];
    if (small_faces)
      w.value(static_cast<std::uint8_t>(size));
    else
      w.value(size);
    for (std::uint32_t k = 0; k < size; ++k) {
      if (signed_indices)
        w.value(static_cast<std::int32_t>(soup.corners[corner + k]));
      else
        w.value(soup.corners[corner + k]);
    }
    if (corner_uvs) {
      if (small_texcoords)
        w.value(static_cast<std::uint8_t>(2 * size));
      else
        w.value(2 * size);
      for (std::uint32_t k = 0; k < 2 * size; ++k) w.value(corner_uvs->as<float>()[2 * corner + k]);
    }
    if (face_colors)
      for (std::uint8_t c : face_colors[f]) w.value(c);
    if (face_quality) w.value(face_quality->as<float>()[f]);
    if (material) w.value(material->as<std::int32_t>()[f]);
    if (face_selected) w.value(face_selected->as<std::uint8_t>()[f]);
    w.end_element();
  });
  pieces.parts.push_back(std::move(out));
  return pieces;
}

std::string write_ply(const Soup& soup, bool binary) { return format_ply(soup, binary).joined(); }

}  // namespace hedge
