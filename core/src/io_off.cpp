// OFF files (Geomview): [ST][C][N]OFF headers, polygons of any size, optional vertex
// normals, colours and texture coordinates, optional face colours after the indices.
#include <algorithm>
#include <cstdint>
#include <cstring>
#include <string>
#include <utility>
#include <vector>

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

  soup.positions.resize(nv);
  std::vector<float> normals(header.normal ? nv * 3 : 0);
  std::vector<std::uint8_t> colors(header.color ? nv * 4 : 0);
  std::vector<float> uvs(header.texture ? nv * 2 : 0);
  std::string_view tokens[kMaxLineTokens];

  for (std::uint64_t v = 0; v < nv; ++v) {
    in.skip_space();
    if (in.at_end()) in.fail("file ends at vertex " + std::to_string(v) + " of " + std::to_string(nv));
    for (int k = 0; k < 3; ++k) {
      std::string_view t = in.line_token();
      if (!parse_number(t, soup.positions[v][k])) in.fail_expected("3 coordinates for vertex " + std::to_string(v), t);
    }
    if (header.normal)
      for (int k = 0; k < 3; ++k) {
        std::string_view t = in.line_token();
        if (!parse_number(t, normals[3 * v + k]))
          in.fail_expected("3 normal coordinates for vertex " + std::to_string(v), t);
      }
    std::size_t n = 0;
    while (n < kMaxLineTokens && !in.at_line_end()) tokens[n++] = in.line_token();
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

  soup.face_sizes.reserve(nf);
  soup.corners.reserve(std::min<std::uint64_t>(nf * 3, in.remaining() / 2));
  std::vector<std::uint8_t> face_colors;
  for (std::uint64_t f = 0; f < nf; ++f) {
    in.skip_space();
    if (in.at_end()) in.fail("file ends at face " + std::to_string(f) + " of " + std::to_string(nf));
    std::string_view t = in.line_token();
    std::uint32_t size = 0;
    if (!parse_number(t, size)) in.fail_expected("the number of vertices of face " + std::to_string(f), t);
    for (std::uint32_t k = 0; k < size; ++k) {
      t = in.line_token();
      std::uint32_t index = 0;
      if (!parse_number(t, index))
        in.fail_expected(std::to_string(size) + " vertex indices for face " + std::to_string(f), t);
      soup.corners.push_back(index);
    }
    soup.face_sizes.push_back(size);
    std::size_t n = 0;
    while (n < kMaxLineTokens && !in.at_line_end()) tokens[n++] = in.line_token();
    // After the indices: nothing, a colour map index (which has no meaning without the
    // map, so it is skipped), or a colour.
    if (n == 3 || n == 4) {
      if (face_colors.empty()) {
        face_colors.reserve(nf * 4);
        face_colors.assign(f * 4, 255);
      }
      face_colors.resize(f * 4 + 4);
      if (!parse_color(tokens, n, &face_colors[f * 4]))
        in.fail("expected a colour after the vertex indices of face " + std::to_string(f) + ", found " +
                quote(tokens[0]));
    } else if (n > 1) {
      in.fail("expected at most a colour (3 or 4 values) after the vertex indices of face " + std::to_string(f) +
              ", found " + plural(n, "value"));
    } else if (!face_colors.empty()) {
      face_colors.resize(f * 4 + 4, 255);
    }
    in.next_line();
  }
  in.skip_space();
  if (!in.at_end()) in.fail_expected("the end of the file after " + plural(nf, "face"), in.line_token());

  auto add = [&](const char* channel_name, Domain domain, ScalarType scalar, int components, const void* data,
                 std::size_t size) {
    Channel& c = soup.add_channel(channel_name, domain, scalar, components);
    if (size) std::memcpy(c.data.data(), data, size);
  };
  if (header.normal) add("normal", Domain::vertex, ScalarType::f32, 3, normals.data(), normals.size() * sizeof(float));
  if (header.color) add("color", Domain::vertex, ScalarType::u8, 4, colors.data(), colors.size());
  if (header.texture) add("uv", Domain::vertex, ScalarType::f32, 2, uvs.data(), uvs.size() * sizeof(float));
  if (!face_colors.empty()) add("color", Domain::face, ScalarType::u8, 4, face_colors.data(), face_colors.size());
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
