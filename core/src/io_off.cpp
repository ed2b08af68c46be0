// OFF files (Geomview): [ST][C][N]OFF headers, polygons of any size, optional vertex
// normals, colours and texture coordinates, optional face colours after the indices.
#include <algorithm>
#include <cstdint>
#include <cstring>
#include <string>
#include <utility>
#include <vector>

#include "hedge/detail/memory.h"
#include "hedge/io.h"
#include "hedge/limits.h"
#include "io_detail.h"

namespace hedge {

using namespace io_detail;

namespace {

struct OffHeader {
  bool texture = false;  // ST: s t after each vertex
  bool color = false;    // C: r g b [a] after each vertex
  bool normal = false;   // N: nx ny nz after each vertex
};

//! Parses "[ST][C][N]OFF"; the letters may come in any order, each at most once.
bool parse_keyword(std::string_view keyword, OffHeader& header, bool& homogeneous, bool& dimension) {
  if (keyword.size() < 3 || keyword.substr(keyword.size() - 3) != "OFF") return false;
  std::string_view prefix = keyword.substr(0, keyword.size() - 3);
  while (!prefix.empty()) {
    bool* flag = nullptr;
    std::size_t length = 1;
    if (prefix.substr(0, 2) == "ST") {
      flag = &header.texture;
      length = 2;
    } else if (prefix[0] == 'C') {
      flag = &header.color;
    } else if (prefix[0] == 'N') {
      flag = &header.normal;
    } else if (prefix[0] == '4') {
      flag = &homogeneous;
    } else if (prefix[0] == 'n') {
      flag = &dimension;
    }
    if (!flag || *flag) return false;
    *flag = true;
    prefix.remove_prefix(length);
  }
  return true;
}

//! Reads 3 or 4 colour values from `tokens`: reals 0..1 when any is written as a real or
//! all are at most 1 (as MeshLab reads them), else integers 0..255.
bool parse_color(const std::string_view* tokens, std::size_t n, std::uint8_t* rgba) {
  double v[4] = {0, 0, 0, 255};
  bool real = false;
  bool all_small = true;
  for (std::size_t k = 0; k < n; ++k) {
    if (!parse_number(tokens[k], v[k])) return false;
    if (tokens[k].find_first_of(".eE") != std::string_view::npos) real = true;
    if (v[k] > 1.0) all_small = false;
  }
  if (n == 3) v[3] = real || all_small ? 1.0 : 255.0;
  real = real || all_small;
  for (int k = 0; k < 4; ++k) rgba[k] = real ? color_from_real(v[k]) : color_from_integer(v[k]);
  return true;
}

constexpr std::size_t kMaxLineTokens = 64;

//! The tokens left on a line. Kept from line to line by its reader, so that its 64 views
//! are not cleared for every line.
struct LineRest {
  std::string_view tokens[kMaxLineTokens];
  std::size_t n = 0;

  [[gnu::always_inline]] void read(TextScanner& in) {
    n = 0;
    while (n < kMaxLineTokens && !in.at_line_end()) tokens[n++] = in.line_token();
  }
};

//! The vertex arrays, sized for every vertex: one pass and the runs write each vertex at its
//! index.
struct OffVertices {
  OffHeader header;
  Point* positions;
  float* normals;
  std::uint8_t* colors;
  float* uvs;

  //! Vertex v: one line, `in` at its first token.
  [[gnu::always_inline]] void read(TextScanner& in, std::uint64_t v, LineRest& rest) const {
    for (int k = 0; k < 3; ++k) {
      std::string_view t = in.line_token();
      if (!parse_number(t, positions[v][k])) in.fail_expected("3 coordinates for vertex " + std::to_string(v), t);
    }
    if (header.normal)
      for (int k = 0; k < 3; ++k) {
        std::string_view t = in.line_token();
        if (!parse_number(t, normals[3 * v + k]))
          in.fail_expected("3 normal coordinates for vertex " + std::to_string(v), t);
      }
    rest.read(in);
    const std::string_view* tokens = rest.tokens;
    const std::size_t n = rest.n;
    std::size_t expected_extra = header.texture ? 2 : 0;
    if (header.color) {
      if (n < expected_extra + 3 || n > expected_extra + 4)
        in.fail("expected 3 or 4 colour values" + std::string(header.texture ? " and 2 texture coordinates" : "") +
                " for vertex " + std::to_string(v) + ", found " + plural(n, "value"));
      if (!parse_color(tokens, n - expected_extra, &colors[4 * v]))
        in.fail("expected colour values for vertex " + std::to_string(v) + ", found " + quote(tokens[0]));
    } else if (n != expected_extra) {
      if (n < expected_extra) in.fail("expected 2 texture coordinates for vertex " + std::to_string(v));
      in.fail_expected("the end of the line after vertex " + std::to_string(v), tokens[expected_extra]);
    }
    if (header.texture)
      for (int k = 0; k < 2; ++k)
        if (!parse_number(tokens[n - 2 + k], uvs[2 * v + k]))
          in.fail_expected("2 texture coordinates for vertex " + std::to_string(v), tokens[n - 2 + k]);
    in.next_line();
  }
};

//! Face f's vertex count: `in` at its first token.
[[gnu::always_inline]] inline std::uint32_t read_face_size(TextScanner& in, std::uint64_t f) {
  std::string_view t = in.line_token();
  std::uint32_t size = 0;
  if (!parse_number(t, size)) in.fail_expected("the number of vertices of face " + std::to_string(f), t);
  return size;
}

//! Face f's `size` vertex indices, each handed to `put`: `in` after its size.
template <class Put>
void read_face_corners(TextScanner& in, std::uint64_t f, std::uint32_t size, Put&& put) {
  for (std::uint32_t k = 0; k < size; ++k) {
    std::string_view t = in.line_token();
    std::uint32_t index = 0;
    if (!parse_number(t, index))
      in.fail_expected(std::to_string(size) + " vertex indices for face " + std::to_string(f), t);
    put(index);
  }
}

//! What follows face f's indices, the face being the `here`-th of `colors`: nothing, a colour
//! map index (which has no meaning without the map, so it is skipped), or a colour. `colors`
//! holds none until a face has one, then 4 a face (255 for none). Moves to the next line.
[[gnu::always_inline]] inline void read_face_rest(TextScanner& in, std::uint64_t f, std::size_t here,
                                                  std::vector<std::uint8_t>& colors, LineRest& rest) {
  rest.read(in);
  const std::string_view* tokens = rest.tokens;
  const std::size_t n = rest.n;
  if (n == 3 || n == 4) {
    if (colors.empty()) colors.assign(here * 4, 255);
    colors.resize(here * 4 + 4);
    if (!parse_color(tokens, n, &colors[here * 4]))
      in.fail("expected a colour after the vertex indices of face " + std::to_string(f) + ", found " +
              quote(tokens[0]));
  } else if (n > 1) {
    in.fail("expected at most a colour (3 or 4 values) after the vertex indices of face " + std::to_string(f) +
            ", found " + plural(n, "value"));
  } else if (!colors.empty()) {
    colors.resize(here * 4 + 4, 255);
  }
  in.next_line();
}

//! The faces as the soup holds them.
struct OffFaces {
  std::vector<std::uint32_t> sizes, corners;
  std::vector<std::uint8_t> colors;  //!< none until a face has one, then 4 a face (255 for none)
};

//! Lines of `text` that hold an element: neither blank nor a comment.
std::uint64_t count_element_lines(std::string_view text) {
  std::uint64_t n = 0;
  const char *p = text.data(), *end = p + text.size();
  while (p < end) {
    while (p < end && (*p == ' ' || *p == '\t' || *p == '\r' || *p == '\v' || *p == '\f')) ++p;
    if (p < end && *p != '\n' && *p != '#') ++n;
    const void* nl = std::memchr(p, '\n', std::size_t(end - p));
    p = nl ? static_cast<const char*>(nl) + 1 : end;
  }
  return n;
}

//! The body read in runs of about 1 MB of lines on all threads, in three passes that write
//! every element at its place, so that no run holds a copy (memory is the cost here): the
//! element lines of each run, the sizes of its faces, then the elements. False, with `faces`
//! empty, when the body is small, there is one thread, or it is not one element a line or
//! has an error (one pass then reads it and names the error).
bool read_body_in_runs(std::string_view body, const std::string& name, std::uint64_t nv, std::uint64_t nf,
                       const OffVertices& vertices, OffFaces& faces) {
  if (body.size() < 2 * run_bytes() || resolve_thread_count(0) < 2) return false;
  // Pass 1: the elements before each run.
  const LineRuns runs = cut_into_line_runs(body, count_element_lines);
  const std::vector<std::string_view>& text = runs.text;
  const std::vector<std::uint64_t>& first = runs.first;
  if (first.back() != nv + nf) return false;
  const std::size_t n = text.size();

  // Pass 2: each face's size, so each run knows where its corners go.
  faces.sizes.resize(nf);
  std::vector<std::uint64_t> corners_before(n + 1, 0);
  bool regular = read_runs_or_give_way(n, [&](std::size_t r) {
    if (first[r + 1] <= nv) return;
    TextScanner in(text[r], name, '#');
    for (std::uint64_t v = first[r]; v < nv; ++v) {
      in.skip_space();
      in.next_line();
    }
    std::uint64_t corners = 0;
    for (std::uint64_t f = std::max(first[r], nv) - nv; f < first[r + 1] - nv; ++f) {
      in.skip_space();
      corners += faces.sizes[f] = read_face_size(in, f);
      in.next_line();
    }
    // Each index takes a digit and a space: more than that is an error one pass names,
    // before anything is allocated for it.
    if (corners > text[r].size() / 2) throw Irregular{};
    corners_before[r + 1] = corners;
  });
  if (!regular) {
    faces = {};
    return false;
  }
  for (std::size_t r = 0; r < n; ++r) corners_before[r + 1] += corners_before[r];

  // Pass 3: the elements; face colours, which are rare, by run and joined after.
  detail::resize_on_huge_pages(faces.corners, corners_before.back());
  std::vector<std::vector<std::uint8_t>> colors(n);
  regular = read_runs_or_give_way(n, [&](std::size_t r) {
    TextScanner in(text[r], name, '#');
    LineRest rest;
    for (std::uint64_t v = first[r]; v < std::min(first[r + 1], nv); ++v) {
      in.skip_space();
      vertices.read(in, v, rest);
    }
    std::uint32_t* corners = faces.corners.data() + corners_before[r];
    const std::uint64_t run_first_face = std::max(first[r], nv) - nv;
    for (std::uint64_t f = run_first_face; f < std::max(first[r + 1], nv) - nv; ++f) {
      in.skip_space();
      if (read_face_size(in, f) != faces.sizes[f]) throw Irregular{};
      read_face_corners(in, f, faces.sizes[f], [&](std::uint32_t index) { *corners++ = index; });
      read_face_rest(in, f, f - run_first_face, colors[r], rest);
    }
  });
  if (!regular) {
    faces = {};
    return false;
  }
  const bool colored = std::any_of(colors.begin(), colors.end(), [](const auto& c) { return !c.empty(); });
  if (colored) {
    faces.colors.assign(4 * nf, 255);
    for (std::size_t r = 0; r < n; ++r)
      std::copy(colors[r].begin(), colors[r].end(),
                faces.colors.begin() + std::ptrdiff_t(4 * (std::max(first[r], nv) - nv)));
  }
  return true;
}

}  // namespace

Soup read_off(std::string_view bytes, const std::string& name) {
  TextScanner in(bytes, name, '#');
  Soup soup;

  in.skip_space();
  std::string_view keyword = in.line_token();
  // ModelNet and some other collections glue the vertex count to the keyword: "OFF490 518 0".
  std::string_view glued_count;
  if (std::size_t off = keyword.find("OFF"); off != std::string_view::npos && off + 3 < keyword.size()) {
    glued_count = keyword.substr(off + 3);
    keyword = keyword.substr(0, off + 3);
  }
  OffHeader header;
  bool homogeneous = false;
  bool dimension = false;
  if (!parse_keyword(keyword, header, homogeneous, dimension))
    in.fail_expected("the keyword OFF (or COFF, NOFF, STOFF and similar)", keyword);
  if (homogeneous) in.fail("4OFF files (homogeneous coordinates) are not supported");
  if (dimension) {
    std::string_view token = glued_count.empty() ? in.token() : std::exchange(glued_count, {});
    int n = 0;
    if (!parse_number(token, n)) in.fail_expected("the dimension of nOFF", token);
    if (n != 3) in.fail("only 3-dimensional nOFF files are supported, this one has dimension " + std::string(token));
  }

  std::uint64_t counts[2] = {0, 0};
  const char* what[2] = {"the number of vertices", "the number of faces"};
  for (int k = 0; k < 2; ++k) {
    std::string_view token = glued_count.empty() ? in.token() : std::exchange(glued_count, {});
    if (!parse_number(token, counts[k])) in.fail_expected(what[k], token);
  }
  // The edge count is optional and unused; it sits on the same line when present.
  if (!in.at_line_end()) {
    std::string_view token = in.line_token();
    std::uint64_t edges = 0;
    if (!parse_number(token, edges)) in.fail_expected("the number of edges", token);
  }
  if (!in.at_line_end()) in.fail_expected("the end of the line after the counts", in.line_token());
  const std::size_t counts_line = in.line();
  in.next_line();
  const std::uint64_t nv = counts[0], nf = counts[1];
  // A vertex takes at least "0 0 0\n", a face at least "0\n": counts the rest of the file
  // cannot hold are an error before anything is allocated.
  if (nv > kMaxElements) fail_line(name, counts_line, limit_message(nv, kMaxElements, "vertices"));
  if (nf > kMaxFaces) fail_line(name, counts_line, limit_message(nf, kMaxFaces, "faces"));
  const std::uint64_t room = in.remaining() + 1;
  if (nv > room / 6 || nf > room / 2 || nv * 6 + nf * 2 > room)
    fail_line(name, counts_line,
              "the header declares " + plural(nv, "vertex", "vertices") + " and " + plural(nf, "face") +
                  ", more than the rest of the file (" + plural(in.remaining(), "byte") + ") can hold");

  detail::resize_on_huge_pages(soup.positions, nv);
  std::vector<float> normals(header.normal ? nv * 3 : 0);
  std::vector<std::uint8_t> colors(header.color ? nv * 4 : 0);
  std::vector<float> uvs(header.texture ? nv * 2 : 0);
  const OffVertices vertices{header, soup.positions.data(), normals.data(), colors.data(), uvs.data()};
  OffFaces faces;

  if (!read_body_in_runs(bytes.substr(in.offset()), name, nv, nf, vertices, faces)) {
    LineRest rest;
    for (std::uint64_t v = 0; v < nv; ++v) {
      in.skip_space();
      if (in.at_end()) in.fail("file ends at vertex " + std::to_string(v) + " of " + std::to_string(nv));
      vertices.read(in, v, rest);
    }
    faces.sizes.reserve(nf);
    detail::reserve_on_huge_pages(faces.corners, std::min<std::uint64_t>(nf * 3, in.remaining() / 2));
    for (std::uint64_t f = 0; f < nf; ++f) {
      in.skip_space();
      if (in.at_end()) in.fail("file ends at face " + std::to_string(f) + " of " + std::to_string(nf));
      const std::uint32_t size = read_face_size(in, f);
      read_face_corners(in, f, size, [&](std::uint32_t index) { faces.corners.push_back(index); });
      faces.sizes.push_back(size);
      read_face_rest(in, f, f, faces.colors, rest);
    }
    in.skip_space();
    if (!in.at_end()) in.fail_expected("the end of the file after " + plural(nf, "face"), in.line_token());
  }
  soup.face_sizes = std::move(faces.sizes);
  soup.corners = std::move(faces.corners);

  auto add = [&](const char* channel_name, Domain domain, ScalarType scalar, int components, const void* data,
                 std::size_t size) {
    Channel& c = soup.add_channel(channel_name, domain, scalar, components);
    if (size) std::memcpy(c.data.data(), data, size);
  };
  if (header.normal) add("normal", Domain::vertex, ScalarType::f32, 3, normals.data(), normals.size() * sizeof(float));
  if (header.color) add("color", Domain::vertex, ScalarType::u8, 4, colors.data(), colors.size());
  if (header.texture) add("uv", Domain::vertex, ScalarType::f32, 2, uvs.data(), uvs.size() * sizeof(float));
  if (!faces.colors.empty()) add("color", Domain::face, ScalarType::u8, 4, faces.colors.data(), faces.colors.size());
  check_soup(soup, name);
  return soup;
}

namespace {

//! Colours go out as integers 0..255, except when all four are at most 1: readers (ours
//! and MeshLab's) take such values as reals 0..1, so those are written as reals.
void append_color(std::string& out, std::array<std::uint8_t, 4> rgba) {
  bool small = rgba[0] <= 1 && rgba[1] <= 1 && rgba[2] <= 1 && rgba[3] <= 1;
  for (int k = 0; k < 4; ++k) {
    out += ' ';
    if (small) {
      out += rgba[k] ? "0.00392157" : "0.0";
    } else {
      append_number(out, static_cast<unsigned>(rgba[k]));
    }
  }
}

}  // namespace

Pieces io_detail::format_off(const Soup& soup) {
  Pieces pieces;
  soup.check();
  const Channel* normals = find_channel(soup, "normal", Domain::vertex, ScalarType::f32, 3);
  const Channel* uvs = find_channel(soup, "uv", Domain::vertex, ScalarType::f32, 2);
  ColorView colors = find_color(soup, Domain::vertex);
  ColorView face_colors = find_color(soup, Domain::face);

  std::string out;
  if (uvs) out += "ST";
  if (colors) out += "C";
  if (normals) out += "N";
  out += "OFF\n";
  append_number(out, soup.n_vertices());
  out += ' ';
  append_number(out, soup.n_faces());
  out += " 0\n";
  append_elements(pieces, out, soup.n_vertices(), [&](std::string& text, std::size_t v) {
    for (int k = 0; k < 3; ++k) {
      if (k) text += ' ';
      append_number(text, soup.positions[v][k]);
    }
    if (normals)
      for (int k = 0; k < 3; ++k) {
        text += ' ';
        append_number(text, normals->as<float>()[3 * v + k]);
      }
    if (colors) append_color(text, colors[v]);
    if (uvs)
      for (int k = 0; k < 2; ++k) {
        text += ' ';
        append_number(text, uvs->as<float>()[2 * v + k]);
      }
    text += '\n';
  });
  const std::vector<std::size_t> offsets = soup.face_offsets();
  append_elements(pieces, out, soup.n_faces(), [&](std::string& text, std::size_t f) {
    append_number(text, soup.face_sizes[f]);
    for (std::size_t c = offsets[f]; c < offsets[f + 1]; ++c) {
      text += ' ';
      append_number(text, soup.corners[c]);
    }
    if (face_colors) append_color(text, face_colors[f]);
    text += '\n';
  });
  pieces.parts.push_back(std::move(out));
  return pieces;
}

std::string write_off(const Soup& soup) { return format_off(soup).joined(); }

}  // namespace hedge
