// STL files, ASCII and binary. STL stores each triangle with its own three positions;
// the reader welds equal positions into shared vertices, the writer fans polygons.
#include <algorithm>
#include <cctype>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "hedge/detail/memory.h"
#include "hedge/io.h"
#include "hedge/limits.h"
#include "io_detail.h"

namespace hedge {

using namespace io_detail;

namespace {

constexpr std::size_t kHeaderBytes = 84;    // 80 bytes of text and the triangle count
constexpr std::size_t kTriangleBytes = 50;  // normal, three corners, a 16-bit attribute

bool iequal(std::string_view a, std::string_view b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i) {
    char c = a[i];
    if (c >= 'A' && c <= 'Z') c = static_cast<char>(c - 'A' + 'a');
    if (c != b[i]) return false;
  }
  return true;
}

//! Equal positions (as floats compare, so 0 and -0 too) become one vertex, numbered in
//! order of first appearance. Open addressing on the coordinate bits: expected O(1) per
//! corner, and the outcome does not depend on the hash.
void weld(const std::vector<Point>& raw, Soup& soup) {
  using Key = std::array<std::uint32_t, 3>;
  auto key_of = [](const Point& p) {
    Key k;
    for (int i = 0; i < 3; ++i) {
      float c = p[i] == 0.0f ? 0.0f : p[i];  // -0 -> +0
      std::memcpy(&k[i], &c, sizeof c);
    }
    return k;
  };
  auto hash = [](const Key& k) {
    std::uint64_t h =
        (static_cast<std::uint64_t>(k[0]) << 32 | k[1]) ^ (static_cast<std::uint64_t>(k[2]) * 0x9e3779b97f4a7c15ull);
    h ^= h >> 30;
    h *= 0xbf58476d1ce4e5b9ull;
    h ^= h >> 27;
    h *= 0x94d049bb133111ebull;
    return h ^ (h >> 31);
  };
  constexpr std::uint32_t kEmpty = 0xffffffffu;
  std::size_t capacity = 16;
  while (capacity < 2 * raw.size()) capacity *= 2;
  const std::size_t mask = capacity - 1;
  std::vector<std::uint32_t> table(capacity, kEmpty);
  std::vector<Key> keys;
  keys.reserve(raw.size() / 4);
  detail::reserve_on_huge_pages(soup.positions, raw.size() / 4);
  detail::resize_on_huge_pages(soup.corners, raw.size());
  for (std::size_t i = 0; i < raw.size(); ++i) {
    Key k = key_of(raw[i]);
    std::size_t slot = hash(k) & mask;
    auto other = [&](std::uint32_t id) {  // element by element: std::array's == calls memcmp
      return keys[id][0] != k[0] || keys[id][1] != k[1] || keys[id][2] != k[2];
    };
    while (table[slot] != kEmpty && other(table[slot])) slot = (slot + 1) & mask;
    if (table[slot] == kEmpty) {
      table[slot] = static_cast<std::uint32_t>(keys.size());
      keys.push_back(k);
      soup.positions.push_back(raw[i]);
    }
    soup.corners[i] = table[slot];
  }
}

Soup read_binary(std::string_view bytes, std::uint32_t triangles, const std::string& name) {
  if (triangles > kMaxFaces) fail_byte(name, 80, limit_message(triangles, kMaxFaces, "triangles"));
  const auto* p = reinterpret_cast<const unsigned char*>(bytes.data()) + kHeaderBytes;
  std::vector<Point> raw(3 * std::size_t{triangles});
  for (std::size_t t = 0; t < triangles; ++t, p += kTriangleBytes)
    for (int c = 0; c < 3; ++c)
      for (int k = 0; k < 3; ++k) raw[3 * t + c][k] = load<float>(p + 12 + 12 * c + 4 * k, false);
  Soup soup;
  soup.face_sizes.assign(triangles, 3);
  weld(raw, soup);
  check_soup(soup, name);
  return soup;
}

//! Reads facets into `raw` and `sizes`. The whole file (`first` and `last`), or a run of
//! it: a run after the first starts at a facet, and one before the last may end after any
//! facet; where the run's end would be an error to one pass, or a run ends after 'endsolid',
//! it throws Irregular, and the file is read in one pass.
void read_ascii_facets(std::string_view text, const std::string& name, bool first, bool last, std::vector<Point>& raw,
                       std::vector<std::uint32_t>& sizes) {
  TextScanner in(text, name);
  auto expect = [&](const char* keyword) {
    std::string_view t = in.token();
    if (!iequal(t, keyword)) {
      std::string quoted(keyword);  // built step by step: GCC 12 warns falsely on "'" + std::string(...)
      quoted.insert(quoted.begin(), '\'');
      quoted += '\'';
      in.fail_expected(quoted, t);
    }
  };
  if (first) {
    expect("solid");
    in.next_line();  // the solid's name
  }
  for (;;) {
    std::string_view t = in.token();
    if (!last && t.empty() && in.at_end()) break;
    if (iequal(t, "endsolid")) {
      in.next_line();
      in.skip_space();
      if (in.at_end()) {
        if (!last) throw Irregular{};  // the next run's facet would follow it
        break;
      }
      t = in.token();
      if (!iequal(t, "solid")) in.fail_expected("'solid' or the end of the file", t);
      in.next_line();
      continue;
    }
    if (!iequal(t, "facet")) in.fail_expected("'facet' or 'endsolid'", t);
    const std::size_t facet = sizes.size();
    expect("normal");
    for (int k = 0; k < 3; ++k) {
      float v;
      t = in.token();
      if (!parse_number(t, v)) in.fail_expected("3 normal coordinates for facet " + std::to_string(facet), t);
    }
    expect("outer");
    expect("loop");
    std::uint32_t corners = 0;
    for (;;) {
      t = in.token();
      if (iequal(t, "endloop")) break;
      if (!iequal(t, "vertex")) in.fail_expected("'vertex' or 'endloop'", t);
      Point p;
      for (int k = 0; k < 3; ++k) {
        t = in.token();
        if (!parse_number(t, p[k])) in.fail_expected("3 coordinates for a vertex of facet " + std::to_string(facet), t);
      }
      raw.push_back(p);
      ++corners;
    }
    if (corners < 3)
      in.fail("facet " + std::to_string(facet) + " has " + plural(corners, "vertex", "vertices") + ", expected 3");
    expect("endfacet");
    sizes.push_back(corners);
  }
  if (raw.size() > 0xffffffffu) in.fail("more corners than hedge can index");
}

//! Big files are read in runs of about 1 MB, each starting at a facet, on all threads, and
//! joined in order; a run that fails or finds something one pass would read otherwise hands
//! the file to one pass, which names the error.
Soup read_ascii(std::string_view bytes, const std::string& name) {
  std::vector<Point> raw;
  Soup soup;
  bool in_runs = bytes.size() >= 2 * run_bytes() && resolve_thread_count(0) >= 2;
  if (in_runs) {
    const std::vector<std::string_view> text =
        cut_into_runs(bytes, run_bytes(), [](std::string_view t, std::size_t i) {  // before a line 'facet ...'
          std::size_t k = i + 1;
          while (k < t.size() && (t[k] == ' ' || t[k] == '\t' || t[k] == '\r')) ++k;
          return k + 5 <= t.size() && iequal(t.substr(k, 5), "facet") &&
                 (k + 5 == t.size() || std::isspace(static_cast<unsigned char>(t[k + 5])));
        });
    struct Run {
      std::vector<Point> raw;
      std::vector<std::uint32_t> sizes;
    };
    std::vector<Run> runs(text.size());
    in_runs = read_runs_or_give_way(runs.size(), [&](std::size_t r) {
      read_ascii_facets(text[r], name, r == 0, r + 1 == runs.size(), runs[r].raw, runs[r].sizes);
    });
    std::size_t corners = 0;
    for (const Run& run : runs) corners += run.raw.size();
    if (corners > 0xffffffffu) in_runs = false;
    if (in_runs) {
      raw.reserve(corners);
      for (Run& run : runs) {
        raw.insert(raw.end(), run.raw.begin(), run.raw.end());
        soup.face_sizes.insert(soup.face_sizes.end(), run.sizes.begin(), run.sizes.end());
        std::vector<Point>().swap(run.raw);
      }
    }
  }
  if (!in_runs) {
    raw.clear();
    soup.face_sizes.clear();
    read_ascii_facets(bytes, name, true, true, raw, soup.face_sizes);
  }
  weld(raw, soup);
  check_soup(soup, name);
  return soup;
}

bool starts_with_solid(std::string_view bytes) {
  std::size_t i = 0;
  while (i < bytes.size() && (bytes[i] == ' ' || bytes[i] == '\t' || bytes[i] == '\r' || bytes[i] == '\n')) ++i;
  if (!iequal(bytes.substr(i, 5), "solid")) return false;
  return i + 5 == bytes.size() || std::isspace(static_cast<unsigned char>(bytes[i + 5]));
}

}  // namespace

Soup read_stl(std::string_view bytes, const std::string& name) {
  const std::size_t size = bytes.size();
  std::uint64_t triangles = 0, needed = 0;
  if (size >= kHeaderBytes) {
    triangles = load<std::uint32_t>(reinterpret_cast<const unsigned char*>(bytes.data()) + 80, false);
    needed = kHeaderBytes + kTriangleBytes * triangles;
    if (size == needed) return read_binary(bytes, static_cast<std::uint32_t>(triangles), name);
  }
  if (starts_with_solid(bytes)) {
    try {
      return read_ascii(bytes, name);
    } catch (const Error&) {
      // Some binary writers start their header with "solid" too; with a plausible count
      // and padding after the triangles, that is what this is.
      if (size >= kHeaderBytes && triangles > 0 && size > needed)
        return read_binary(bytes, static_cast<std::uint32_t>(triangles), name);
      throw;
    }
  }
  if (size < kHeaderBytes)
    fail_byte(
        name, size,
        "file ends inside the 84-byte header of a binary STL (and it does not start with 'solid', so it is not ASCII)");
  if (size < needed)
    fail_byte(name, size,
              "file ends inside triangle " + std::to_string((size - kHeaderBytes) / kTriangleBytes) + " of " +
                  std::to_string(triangles) + " (a binary STL of " + plural(triangles, "triangle") + " has " +
                  std::to_string(needed) + " bytes)");
  // Bytes after the last triangle are padding some writers add.
  return read_binary(bytes, static_cast<std::uint32_t>(triangles), name);
}

Pieces io_detail::format_stl(const Soup& soup, bool binary) {
  Pieces pieces;
  soup.check();
  std::uint64_t triangles = 0;
  for (std::uint32_t s : soup.face_sizes)
    if (s >= 3) triangles += s - 2;
  if (binary && triangles > 0xffffffffu)
    throw Error("cannot write binary STL: " + std::to_string(triangles) +
                " triangles, the format holds at most 2^32 - 1");

  std::string out;
  if (binary) {
    // Not "solid ...": readers take a header starting with that for ASCII.
    std::string header = "binary STL written by hedge";
    header.resize(80, ' ');
    out += header;
    append_le(out, static_cast<std::uint32_t>(triangles));
  } else {
    out += "solid hedge\n";
  }
  const std::vector<std::size_t> offsets = soup.face_offsets();
  append_elements(pieces, out, soup.n_faces(), [&](std::string& text, std::size_t f) {
    // Three floats: little-endian bytes, or text after `keyword`, ending with `after`.
    auto three = [&](const char* keyword, const auto& v, const char* after) {
      if (binary) {
        for (int k = 0; k < 3; ++k) append_le(text, static_cast<float>(v[k]));
        return;
      }
      text += keyword;
      for (int k = 0; k < 3; ++k) {
        text += ' ';
        append_number(text, static_cast<float>(v[k]));
      }
      text += after;
    };
    const std::uint32_t* c = soup.corners.data() + offsets[f];
    for (std::uint32_t k = 1; k + 1 < soup.face_sizes[f]; ++k) {
      const Point& a = soup.positions[c[0]];
      const Point& b = soup.positions[c[k]];
      const Point& d = soup.positions[c[k + 1]];
      const Vec3f n = to_float(normalize(cross(to_double(b) - to_double(a), to_double(d) - to_double(a))));
      three("  facet normal", n, "\n    outer loop\n");
      for (const Point* p : {&a, &b, &d}) three("      vertex", *p, "\n");
      if (binary)
        append_le(text, std::uint16_t{0});
      else
        text += "    endloop\n  endfacet\n";
    }
  });
  if (!binary) out += "endsolid hedge\n";
  pieces.parts.push_back(std::move(out));
  return pieces;
}

std::string write_stl(const Soup& soup, bool binary) { return format_stl(soup, binary).joined(); }

}  // namespace hedge
