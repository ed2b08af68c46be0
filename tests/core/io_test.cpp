// Tests of the file readers and writers (core/src/io*.cpp): each format on small inputs,
// round trips, error messages that name the place, malformed input, and the real meshes.
#include "hedge/io.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <random>
#include <string>
#include <thread>
#include <tuple>
#include <variant>
#include <vector>

#include "hedge/error.h"
#include "hedge/soup.h"
#include "hedge/threads.h"
#include "parallel.h"

namespace hedge {
namespace {

using ::testing::HasSubstr;

// ---------------------------------------------------------------------------------------
// Helpers

//! Channels sorted by domain and name: readers and hand-built soups may list them in
//! different orders, which says nothing about the data.
Soup canonical(Soup soup) {
  std::sort(soup.channels.begin(), soup.channels.end(),
            [](const Channel& a, const Channel& b) { return std::tie(a.domain, a.name) < std::tie(b.domain, b.name); });
  return soup;
}

void expect_same(const Soup& a, const Soup& b) {
  Soup ca = canonical(a), cb = canonical(b);
  EXPECT_EQ(ca.positions, cb.positions);
  EXPECT_EQ(ca.face_sizes, cb.face_sizes);
  EXPECT_EQ(ca.corners, cb.corners);
  ASSERT_EQ(ca.channels.size(), cb.channels.size());
  for (std::size_t i = 0; i < ca.channels.size(); ++i) {
    EXPECT_EQ(ca.channels[i].name, cb.channels[i].name);
    EXPECT_EQ(ca.channels[i].domain, cb.channels[i].domain) << ca.channels[i].name;
    EXPECT_EQ(ca.channels[i].scalar, cb.channels[i].scalar) << ca.channels[i].name;
    EXPECT_EQ(ca.channels[i].components, cb.channels[i].components) << ca.channels[i].name;
    EXPECT_TRUE(ca.channels[i].data == cb.channels[i].data) << ca.channels[i].name;
  }
  EXPECT_TRUE(ca == cb);
}

//! The message of the hedge::Error `f` throws; fails the test when it throws nothing.
std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  ADD_FAILURE() << "expected a hedge::Error";
  return "";
}

template <class T>
std::vector<T> values(const Channel& c) {
  std::vector<T> v(c.data.size() / sizeof(T));
  std::memcpy(v.data(), c.data.data(), c.data.size());
  return v;
}

const Channel& channel(const Soup& soup, const std::string& name, Domain domain) {
  const Channel* c = soup.find(name, domain);
  if (!c) throw std::runtime_error("no " + std::string(domain_name(domain)) + " channel " + name);
  return *c;
}

template <class T>
Channel make_channel(const std::string& name, Domain domain, ScalarType scalar, int components,
                     const std::vector<T>& v) {
  Channel c = Channel::make(name, domain, scalar, components, 0);
  c.data.resize(v.size() * sizeof(T));
  std::memcpy(c.data.data(), v.data(), c.data.size());
  return c;
}

//! Binary data as PLY and STL lay it out.
template <class T>
void put(std::string& out, T v, bool big_endian = false) {
  auto bytes = std::bit_cast<std::array<char, sizeof(T)>>(v);
  if (big_endian) std::reverse(bytes.begin(), bytes.end());
  out.append(bytes.data(), bytes.size());
}

//! Every prefix of `bytes` must either read or throw hedge::Error (never crash or hang).
void read_every_truncation(const std::string& bytes, Soup (*reader)(std::string_view, const std::string&)) {
  std::size_t errors = 0;
  for (std::size_t n = 0; n <= bytes.size(); ++n) {
    try {
      Soup s = reader(bytes.substr(0, n), "cut");
      s.check();
    } catch (const Error&) {
      ++errors;
    }
  }
  EXPECT_GT(errors, 0u);
}

//! A small mixed mesh: a quad, two triangles and a pentagon over 7 vertices.
Soup sample_soup() {
  Soup s;
  s.positions = {{{0, 0, 0}},
                 {{1, 0, 0}},
                 {{1, 1, 0}},
                 {{0, 1, 0}},
                 {{0.5f, 2, 0.25f}},
                 {{-1e-7f, 3.14159274f, -0.0f}},
                 {{1e30f, -2.5e-20f, 7}}};
  s.add_face({0, 1, 2, 3});
  s.add_face({3, 2, 4});
  s.add_face({4, 5, 6});
  s.add_face({0, 3, 4, 5, 6});
  return s;
}

std::string temp_dir() {
  auto dir = std::filesystem::temp_directory_path() / ("hedge_io_test_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  return dir.string();
}

// ---------------------------------------------------------------------------------------
// File names and whole files

TEST(IoFiles, FormatFromPath) {
  EXPECT_EQ(format_from_path("a/b/bunny.off"), FileFormat::off);
  EXPECT_EQ(format_from_path("X.OBJ"), FileFormat::obj);
  EXPECT_EQ(format_from_path("dragon.Ply"), FileFormat::ply);
  EXPECT_EQ(format_from_path("part.v2.stl"), FileFormat::stl);
  EXPECT_THAT(error_of([] { format_from_path("mesh.xyz"); }), HasSubstr("mesh.xyz: unknown file extension '.xyz'"));
  EXPECT_THAT(error_of([] { format_from_path("dir.d/mesh"); }), HasSubstr("no extension"));
}

TEST(IoFiles, WriteAndReadThroughFiles) {
  std::string dir = temp_dir();
  Soup soup = sample_soup();
  for (const char* ext : {".off", ".obj", ".ply"}) {
    std::string path = dir + "/mesh" + ext;
    write_mesh(soup, path);
    expect_same(read_mesh(path), soup);
  }
  WriteOptions ascii;
  ascii.binary = false;
  write_mesh(soup, dir + "/ascii.ply", ascii);
  expect_same(read_mesh(dir + "/ascii.ply"), soup);
  // Overwriting replaces the file and leaves no temporary files behind.
  write_mesh(soup, dir + "/mesh.off");
  std::size_t files = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    EXPECT_THAT(entry.path().filename().string(), ::testing::Not(HasSubstr(".tmp"))) << entry.path();
    ++files;
  }
  EXPECT_EQ(files, 4u);
  std::filesystem::remove_all(dir);
}

// Regular files are mapped; pipes and empty files are read the other way, with the same result.
TEST(IoFiles, ReadsPipesAndEmptyFiles) {
  std::string dir = temp_dir();
  write_mesh(sample_soup(), dir + "/mesh.ply");
  std::string bytes;
  {
    std::ifstream in(dir + "/mesh.ply", std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(in), {});
  }
  std::string fifo = dir + "/pipe.ply";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  std::thread writer([&] { std::ofstream(fifo, std::ios::binary) << bytes; });
  Soup piped = read_mesh(fifo);
  writer.join();
  expect_same(piped, sample_soup());
  { std::ofstream(dir + "/empty.off"); }
  EXPECT_THAT(error_of([&] { read_mesh(dir + "/empty.off"); }), HasSubstr(dir + "/empty.off"));
  std::filesystem::remove_all(dir);
}

TEST(IoFiles, Errors) {
  EXPECT_THAT(error_of([] { read_mesh("/nonexistent/dir/x.ply"); }),
              HasSubstr("cannot open /nonexistent/dir/x.ply: No such file or directory"));
  EXPECT_THAT(error_of([] { write_mesh(sample_soup(), "/nonexistent/dir/x.ply"); }),
              HasSubstr("cannot write /nonexistent/dir/x.ply"));
  std::string dir = temp_dir();
  // A directory where the file should be: the write fails and leaves nothing behind.
  std::filesystem::create_directories(dir + "/taken.off");
  EXPECT_THAT(error_of([&] { write_mesh(sample_soup(), dir + "/taken.off"); }),
              HasSubstr("cannot write " + dir + "/taken.off"));
  EXPECT_THAT(error_of([&] { read_mesh(dir + "/taken.off"); }), HasSubstr("cannot open " + dir + "/taken.off"));
  std::size_t files = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    (void)entry;
    ++files;
  }
  EXPECT_EQ(files, 1u);
  // A soup the writer refuses leaves an existing file untouched.
  write_mesh(sample_soup(), dir + "/keep.off");
  Soup bad = sample_soup();
  bad.corners[0] = 99;
  EXPECT_THAT(error_of([&] { write_mesh(bad, dir + "/keep.off"); }), HasSubstr("uses vertex 99"));
  expect_same(read_mesh(dir + "/keep.off"), sample_soup());
  // Read errors carry the path.
  { std::ofstream(dir + "/bad.obj") << "v 1 2 3\nv 1 x 3\n"; }
  EXPECT_THAT(error_of([&] { read_mesh(dir + "/bad.obj"); }),
              HasSubstr(dir + "/bad.obj: line 2: expected 3 coordinates, found 'x'"));
  std::filesystem::remove_all(dir);
}

// ---------------------------------------------------------------------------------------
// OFF

TEST(IoOff, ReadsPolygonsAndComments) {
  Soup s = read_off(
      "OFF # a comment\n"
      "# another comment\n"
      "\n"
      "5 2 0\n"
      "0 0 0\n"
      "1 0 0   # trailing comment\n"
      "1 1 0\n"
      "0 1 0\r\n"
      "+0.5 -2.5e-1 1E2\n"
      "4 0 1 2 3\n"
      "\n"
      "3 3 2 4\n",
      "t.off");
  ASSERT_EQ(s.n_vertices(), 5u);
  EXPECT_EQ(s.positions[4], (Point{{0.5f, -0.25f, 100.0f}}));
  EXPECT_EQ(s.face_sizes, (std::vector<std::uint32_t>{4, 3}));
  EXPECT_EQ(s.corners, (std::vector<std::uint32_t>{0, 1, 2, 3, 3, 2, 4}));
  EXPECT_TRUE(s.channels.empty());
}

TEST(IoOff, CountsOnTheKeywordLine) {
  Soup s = read_off("OFF 3 1\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n", "t.off");
  EXPECT_EQ(s.n_vertices(), 3u);
  EXPECT_EQ(s.n_faces(), 1u);
  // As ModelNet writes it, the count glued to the keyword.
  s = read_off("OFF3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n", "t.off");
  EXPECT_EQ(s.n_vertices(), 3u);
  EXPECT_EQ(s.n_faces(), 1u);
}

TEST(IoOff, VertexAndFaceColors) {
  Soup s = read_off(
      "COFF\n3 2 0\n"
      "0 0 0 255 0 0 255\n"
      "1 0 0 0 128 0\n"          // three integers: alpha is opaque
      "0 1 0 0.0 0.0 1.0 0.5\n"  // reals 0..1
      "3 0 1 2 10 20 30\n"
      "3 0 2 1\n",  // no colour on this face
      "c.off");
  auto vc = values<std::uint8_t>(channel(s, "color", Domain::vertex));
  EXPECT_EQ(vc, (std::vector<std::uint8_t>{255, 0, 0, 255, 0, 128, 0, 255, 0, 0, 255, 128}));
  auto fc = values<std::uint8_t>(channel(s, "color", Domain::face));
  EXPECT_EQ(fc, (std::vector<std::uint8_t>{10, 20, 30, 255, 255, 255, 255, 255}));
}

TEST(IoOff, NormalsAndTextureCoordinates) {
  Soup s = read_off("STCNOFF\n1 0 0\n1 2 3  0 0 1  255 255 255 255  0.25 0.75\n", "n.off");
  EXPECT_EQ(values<float>(channel(s, "normal", Domain::vertex)), (std::vector<float>{0, 0, 1}));
  EXPECT_EQ(values<float>(channel(s, "uv", Domain::vertex)), (std::vector<float>{0.25f, 0.75f}));
  EXPECT_EQ(values<std::uint8_t>(channel(s, "color", Domain::vertex)), (std::vector<std::uint8_t>{255, 255, 255, 255}));
}

TEST(IoOff, RoundTrip) {
  Soup soup = sample_soup();
  expect_same(read_off(write_off(soup), "r.off"), soup);
  std::vector<float> normals(3 * soup.n_vertices());
  std::vector<float> uvs(2 * soup.n_vertices());
  std::vector<std::uint8_t> colors(4 * soup.n_vertices()), face_colors(4 * soup.n_faces());
  for (std::size_t i = 0; i < normals.size(); ++i) normals[i] = 0.1f * static_cast<float>(i) - 0.7f;
  for (std::size_t i = 0; i < uvs.size(); ++i) uvs[i] = 1.0f / static_cast<float>(i + 3);
  for (std::size_t i = 0; i < colors.size(); ++i) colors[i] = static_cast<std::uint8_t>(37 * i);
  // Colours whose values are all 0 or 1 are ambiguous in OFF (reals or integers?).
  face_colors = {0, 1, 1, 0, 255, 0, 0, 255, 1, 1, 1, 1, 9, 8, 7, 6};
  soup.channels.push_back(make_channel("normal", Domain::vertex, ScalarType::f32, 3, normals));
  soup.channels.push_back(make_channel("uv", Domain::vertex, ScalarType::f32, 2, uvs));
  soup.channels.push_back(make_channel("color", Domain::vertex, ScalarType::u8, 4, colors));
  soup.channels.push_back(make_channel("color", Domain::face, ScalarType::u8, 4, face_colors));
  ASSERT_NO_THROW(soup.check());
  std::string text = write_off(soup);
  EXPECT_EQ(text.substr(0, 8), "STCNOFF\n");
  expect_same(read_off(text, "r.off"), soup);
}

TEST(IoOff, Errors) {
  auto err = [](const std::string& text) { return error_of([&] { read_off(text, "bad.off"); }); };
  EXPECT_THAT(err(""), HasSubstr("bad.off: line 1: expected the keyword OFF"));
  EXPECT_THAT(err("PLY\n"),
              HasSubstr("bad.off: line 1: expected the keyword OFF (or COFF, NOFF, STOFF and similar), found 'PLY'"));
  EXPECT_THAT(err("4OFF\n"), HasSubstr("bad.off: line 1: 4OFF"));
  EXPECT_THAT(err("OFF\n3 x\n"), HasSubstr("bad.off: line 2: expected the number of faces, found 'x'"));
  EXPECT_THAT(err("OFF\n1 0 0\n0 abc 0\n"),
              HasSubstr("bad.off: line 3: expected 3 coordinates for vertex 0, found 'abc'"));
  EXPECT_THAT(err("OFF\n1 0 0\n0 0\n# pad\n"),
              HasSubstr("bad.off: line 3: expected 3 coordinates for vertex 0, found end of"));
  EXPECT_THAT(err("OFF\n1 0 0\n0 0 0 7\n"),
              HasSubstr("bad.off: line 3: expected the end of the line after vertex 0, found '7'"));
  EXPECT_THAT(err("OFF\n2 0 0\n0 0 0\n# padding for the size check\n"),
              HasSubstr("bad.off: line 4: file ends at vertex 1 of 2"));
  EXPECT_THAT(err("OFF\n3 1 0\n0 0 0\n0 0 0\n0 0 0\n3 0 1\n"),
              HasSubstr("bad.off: line 6: expected 3 vertex indices for face 0, found end of"));
  EXPECT_THAT(err("OFF\n3 1 0\n0 0 0\n0 0 0\n0 0 0\n3 0 1 -2\n"),
              HasSubstr("bad.off: line 6: expected 3 vertex indices for face 0, found '-2'"));
  EXPECT_THAT(
      err("OFF\n3 1 0\n0 0 0\n0 0 0\n0 0 0\n3 0 1 2 4 5\n"),
      HasSubstr("bad.off: line 6: expected at most a colour (3 or 4 values) after the vertex indices of face 0"));
  EXPECT_THAT(err("OFF\n3 1 0\n0 0 0\n0 0 0\n0 0 0\n3 0 1 2\n3 0 1 2\n"),
              HasSubstr("bad.off: line 7: expected the end of the file after 1 face, found '3'"));
  // Topology is not the reader's business, but it reports what Soup::check() finds.
  EXPECT_THAT(err("OFF\n3 1 0\n0 0 0\n0 0 0\n0 0 0\n3 0 1 9\n"), HasSubstr("bad.off: soup: face 0 uses vertex 9"));
  EXPECT_THAT(err("OFF\n1 0 0\nnan 0 0\n"), HasSubstr("bad.off: soup: vertex 0 has a NaN coordinate (x = nan)"));
  EXPECT_THAT(err("OFF\n2 0 0\n0 0 0\n0 1 -inf\n"),
              HasSubstr("bad.off: soup: vertex 1 has an infinite coordinate (z = -inf)"));
  // A header claiming billions of elements in a tiny file is refused before allocating.
  EXPECT_THAT(err("OFF\n400000000 400000000 0\n0 0 0\n"),
              HasSubstr("bad.off: line 2: the header declares 400000000 vertices and 400000000 faces"));
  EXPECT_THAT(err("OFF\n4000000000 4000000000 0\n0 0 0\n"),
              HasSubstr("bad.off: line 2: 4,000,000,000 faces asked for, but hedge's 32-bit indices hold at most"));
  EXPECT_THAT(err("OFF\n99999999999999999999 1 0\n"), HasSubstr("bad.off: line 2: expected the number of vertices"));
}

// ---------------------------------------------------------------------------------------
// OBJ

TEST(IoObj, ReadsAllFaceForms) {
  Soup s = read_obj(
      "# comment\n"
      "mtllib x.mtl\n"
      "o thing\n"
      "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
      "vt 0 0\nvt 1 0\nvt 1 1 0\n"
      "vn 0 0 1\n"
      "g group\ns off\n"
      "f 1 2 3\n"
      "f 1/1 2/2 3/3\n"
      "f 1//1 3//1 4//1\n"
      "f 1/1/1 2/2/1 3/3/1 4/1/1\n"
      "f -4 -3 -2 -1\n"
      "f -4/-3/-1 -3/-2/-1 -2/-1/-1\n"
      "l 1 2\n",
      "t.obj");
  ASSERT_EQ(s.n_vertices(), 4u);
  EXPECT_EQ(s.face_sizes, (std::vector<std::uint32_t>{3, 3, 3, 4, 4, 3}));
  EXPECT_EQ(s.corners, (std::vector<std::uint32_t>{0, 1, 2, 0, 1, 2, 0, 2, 3, 0, 1, 2, 3, 0, 1, 2, 3, 0, 1, 2}));
  // Not every corner has a vt or vn, so there are no corner channels.
  EXPECT_TRUE(s.channels.empty());
}

TEST(IoObj, CornerTexcoordsAndNormals) {
  Soup s = read_obj(
      "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
      "vt 0 0\nvt 1 0\nvt 1 1\nvt 0.5\n"
      "vn 0 0 1\nvn 0 0 -1\n"
      "f 1/1/1 2/2/1 3/3/1\n"
      "f 1/-1/-1 3/-2/-1 4/-3/-1\n",
      "t.obj");
  EXPECT_EQ(values<float>(channel(s, "uv", Domain::corner)),
            (std::vector<float>{0, 0, 1, 0, 1, 1, 0.5f, 0, 1, 1, 1, 0}));
  EXPECT_EQ(values<float>(channel(s, "normal", Domain::corner)),
            (std::vector<float>{0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, -1, 0, 0, -1, 0, 0, -1}));
}

TEST(IoObj, ContinuationColorsAndMaterials) {
  Soup s = read_obj(
      "v 0 0 0 1 0 0\n"
      "v 1 0 0 0 1 0\n"
      "v 1 1 0 1.0\n"  // a weight, not a colour
      "v 0 1 0 0.5 0.5 0.5 0.25\n"
      "f 1 2 \\\n"
      "  3\n"
      "usemtl red\n"
      "f 1 3\\\r\n 4\n"
      "usemtl blue\n"
      "f 4 3 2\n"
      "usemtl red\n"
      "f 2 3 4 \\\n"
      "\n",
      "t.obj");
  EXPECT_EQ(s.face_sizes, (std::vector<std::uint32_t>{3, 3, 3, 3}));
  EXPECT_EQ(s.corners, (std::vector<std::uint32_t>{0, 1, 2, 0, 2, 3, 3, 2, 1, 1, 2, 3}));
  EXPECT_EQ(values<float>(channel(s, "color", Domain::vertex)),
            (std::vector<float>{1, 0, 0, 1, 0, 1, 0, 1, 1, 1, 1, 1, 0.5f, 0.5f, 0.5f, 0.25f}));
  EXPECT_EQ(values<std::int32_t>(channel(s, "material", Domain::face)), (std::vector<std::int32_t>{-1, 0, 1, 0}));
}

TEST(IoObj, ForwardReferencesToTexcoords) {
  // Indices may point at vt lines further down the file.
  Soup s = read_obj("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/1 2/2 3/1\nvt 0.25 0.5\nvt 1 1\n", "t.obj");
  EXPECT_EQ(values<float>(channel(s, "uv", Domain::corner)), (std::vector<float>{0.25f, 0.5f, 1, 1, 0.25f, 0.5f}));
}

TEST(IoObj, RoundTrip) {
  Soup soup = sample_soup();
  expect_same(read_obj(write_obj(soup), "r.obj"), soup);

  const std::size_t nc = soup.n_corners();
  std::vector<float> uv(2 * nc), normal(3 * nc), color(4 * soup.n_vertices());
  for (std::size_t i = 0; i < uv.size(); ++i) uv[i] = static_cast<float>(i % 5) / 3.0f;
  for (std::size_t i = 0; i < normal.size(); ++i) normal[i] = (i % 7 == 0) ? -0.0f : static_cast<float>(i % 4) * 0.3f;
  for (std::size_t i = 0; i < color.size(); ++i) color[i] = i % 4 == 3 ? 1.0f : static_cast<float>(i) / 29.0f;
  soup.channels.push_back(make_channel("color", Domain::vertex, ScalarType::f32, 4, color));
  soup.channels.push_back(make_channel("uv", Domain::corner, ScalarType::f32, 2, uv));
  soup.channels.push_back(make_channel("normal", Domain::corner, ScalarType::f32, 3, normal));
  soup.channels.push_back(
      make_channel("material", Domain::face, ScalarType::i32, 1, std::vector<std::int32_t>{-1, 0, 1, 0}));
  ASSERT_NO_THROW(soup.check());
  std::string text = write_obj(soup);
  expect_same(read_obj(text, "r.obj"), soup);
  // Equal values are written once.
  std::size_t vt_lines = 0;
  for (std::size_t p = text.find("\nvt "); p != std::string::npos; p = text.find("\nvt ", p + 1)) ++vt_lines;
  EXPECT_EQ(vt_lines, 5u);
}

//! A soup, or the message of the error reading it gave.
using ReadResult = std::variant<Soup, std::string>;

template <class Reader>
ReadResult read_result(Reader reader, const std::string& text) {
  try {
    return reader(text);
  } catch (const Error& e) {
    return std::string(e.what());
  }
}

//! Reads each text whole, then in runs of 1 to 64 bytes on two threads: the same soup or the
//! same error each time. Returns how many reads in runs split work across threads.
template <class Reader>
std::size_t expect_same_in_runs(const std::vector<std::string>& files, Reader reader) {
  std::size_t split = 0;
  for (const std::string& text : files) {
    const ReadResult whole = read_result(reader, text);
    for (std::size_t run_bytes : {1, 2, 3, 5, 8, 13, 21, 64}) {
      set_thread_count(2);
      testing::set_parallel_grain(run_bytes);
      const std::size_t splits = testing::parallel_splits();
      const ReadResult in_runs = read_result(reader, text);
      split += testing::parallel_splits() > splits;
      set_thread_count(0);
      testing::set_parallel_grain(0);
      EXPECT_EQ(whole.index(), in_runs.index()) << text << "\nruns of " << run_bytes << " bytes";
      if (whole.index() != in_runs.index()) continue;
      if (whole.index() == 0)
        EXPECT_TRUE(std::get<Soup>(whole) == std::get<Soup>(in_runs)) << text << "\nruns of " << run_bytes << " bytes";
      else
        EXPECT_EQ(std::get<std::string>(whole), std::get<std::string>(in_runs)) << "runs of " << run_bytes << " bytes";
    }
  }
  return split;
}

TEST(IoOff, BodyInRunsReadsAsTheWholeFile) {
  // The body is cut into runs of lines, each run's elements numbered by the element lines
  // (neither blank nor a comment) before it: every run size gives the soup, or the error,
  // of the file read whole.
  const std::string vertices = "0 0 0 255 0 0\n1 0 0 0 255 0\n# a comment\n0 1 0 0 0 255\n\n1 1 0.5 9 9 9\n";
  const std::vector<std::string> files = {
      "COFF\n4 3 0\n" + vertices + "3 0 1 2\n3 1 3 2 1 0 0\n  4 0 1 3 2 # a quad\n",
      "COFF\n4 3 0\n" + vertices + "3 0 1 2 0.5 0.5 0.5 1\n3 1 3 2\n4 0 1 3 2 7\n\n# the end\n",
      "COFF\n4 3\n" + vertices + "3 0 1 2\r\n3 1 3 2\r\n4 0 1 3 2",
      "NOFF\n3 1\n0 0 0 0 0 1\n1 0 0 0 0 1\n0 1 0 0 0 1\n3 0 1 2\n",
      // Errors: truncated, one element too many, a bad number, too many values, a face on two
      // lines, more indices than the file can hold.
      "COFF\n4 3 0\n" + vertices + "3 0 1 2\n3 1 3 2\n",
      "COFF\n4 3 0\n" + vertices + "3 0 1 2\n3 1 3 2\n4 0 1 3 2\n3 0 1 2\n",
      "COFF\n4 3 0\n" + vertices + "3 0 1 2\n3 1 x 2\n4 0 1 3 2\n",
      "COFF\n4 3 0\n" + vertices + "3 0 1 2\n3 1 3 2 1 1 1 1 1\n4 0 1 3 2\n",
      "COFF\n4 3 0\n" + vertices + "3 0 1 2\n3 1 3\n2\n4 0 1 3 2\n",
      "COFF\n4 3 0\n" + vertices + "3 0 1 2\n4000000000 1 3 2\n4 0 1 3 2\n",
      "COFF\n4 3 0\n0 0 0 255 0 0\n1 0 0\n0 1 0 0 0 255\n1 1 0.5 9 9 9\n3 0 1 2\n3 1 3 2\n4 0 1 3 2\n",
  };
  auto read = [](const std::string& text) { return read_off(text, "runs.off"); };
  EXPECT_GT(expect_same_in_runs(files, read), 0u);
  // What the first two files hold, read whole.
  const Soup s = read(files[0]);
  EXPECT_EQ(s.corners, (std::vector<std::uint32_t>{0, 1, 2, 1, 3, 2, 0, 1, 3, 2}));
  EXPECT_EQ(values<std::uint8_t>(channel(s, "color", Domain::face)),
            (std::vector<std::uint8_t>{255, 255, 255, 255, 255, 0, 0, 255, 255, 255, 255, 255}));
  EXPECT_EQ(values<std::uint8_t>(channel(read(files[1]), "color", Domain::face)),
            (std::vector<std::uint8_t>{128, 128, 128, 255, 255, 255, 255, 255, 255, 255, 255, 255}));
}

TEST(IoObj, RunsOfAnySizeReadAsTheWholeFile) {
  // The reader cuts a file into runs of lines, read on several threads and joined: every
  // run size gives the soup, or the error (line and message), of the file read whole.
  const std::vector<std::string> files = {
      "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0 0.5 0.25 1\nvt 0 0\nvt 1 0\nvn 0 0 1\n"
      "f 1/1/1 2/2/1 3/1/1\nusemtl a\nf -4/-2/-1 -3/-1/-1 -1/-2/-1\nf 2 4 3\n# a comment \\\nusemtl b\n"
      "f 1/3 2/4 3/3\nvt 0.5 0.5\nusemtl a\nf 2/1 4/2 \\\n 3/1\nvt 1 1\nusemtl c\n",
      "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nv 1 1 0\nf -1 -3 -2\nusemtl m\n",
      "v 0 0 0\r\nv 1 0 0\r\nv 0 1 \\\r\n 0\r\nf 1 2 3\r\n",
      // Errors: the first in the file wins, wherever the runs are cut.
      "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 -4\nf 1 2 x\n",
      "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 x\nf 1 2 -4\n",
      "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/1 2/1 3/9\nv 1 2\n",
      "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/1 2/1 3/9\nvt 0 0\n",
      "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/-2 2/1 3/1\n",
      "v 0 0 0\nv 1 0 0\nf 1 2 3\n",
      "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nv 1 2 \\\n",
      "v 0 0 0\nv 1 0 0\nv 0 1 0\n\n\nf 1 2 3 junk/1/2/3\n",
  };
  auto read = [](const std::string& text) { return read_obj(text, "runs.obj"); };
  EXPECT_GT(expect_same_in_runs(files, read), 0u);
  // What the first file holds, read whole.
  const Soup s = read(files[0]);
  EXPECT_EQ(s.n_faces(), 5u);
  EXPECT_EQ(values<std::int32_t>(channel(s, "material", Domain::face)), (std::vector<std::int32_t>{-1, 0, 0, 1, 0}));
  EXPECT_EQ(s.corners, (std::vector<std::uint32_t>{0, 1, 2, 0, 1, 3, 1, 3, 2, 0, 1, 2, 1, 3, 2}));
}

TEST(IoObj, Errors) {
  auto err = [](const std::string& text) { return error_of([&] { read_obj(text, "bad.obj"); }); };
  EXPECT_THAT(err("v 1 2\n"), HasSubstr("bad.obj: line 1: expected 3 coordinates, found end of"));
  EXPECT_THAT(err("\n\nv 1 2 abc\n"), HasSubstr("bad.obj: line 3: expected 3 coordinates, found 'abc'"));
  EXPECT_THAT(err("v 0 0 0\nv 1 2 3 4 5\n"), HasSubstr("bad.obj: line 2: expected 3 coordinates, optionally followed"));
  EXPECT_THAT(err("v 0 0 0\nf 1 0 1\n"),
              HasSubstr("bad.obj: line 2: index 0 in '0' is invalid: OBJ indices start at 1"));
  EXPECT_THAT(err("v 0 0 0\nf 1 -2 1\n"),
              HasSubstr("bad.obj: line 2: relative vertex index -2 points before the first vertex"));
  EXPECT_THAT(err("v 0 0 0\nf 1 x 1\n"), HasSubstr("bad.obj: line 2: expected a vertex index in 'x'"));
  EXPECT_THAT(err("v 0 0 0\nf 1/1/1/1\n"), HasSubstr("bad.obj: line 2: expected at most v/vt/vn"));
  EXPECT_THAT(err("v 0 0 0\nf\n"), HasSubstr("bad.obj: line 2: expected vertex indices after 'f'"));
  EXPECT_THAT(err("v 0 0 0\n\nf 1/3 1/1 1/1\nvt 0 0\n"),
              HasSubstr("bad.obj: line 3: texture coordinate index 3 is out of range: the file defines 1"));
  EXPECT_THAT(err("v 0 0 0\nvn 0 0 1\nf 1//2 1//1 1//1\n"),
              HasSubstr("bad.obj: line 3: normal index 2 is out of range"));
  EXPECT_THAT(err("v 0 0 0\nf 1 2 99999999999\n"), HasSubstr("bad.obj: line 2: vertex index 99999999999 is too large"));
  EXPECT_THAT(err("v 0 0 0\nf 1 2 3\n"),
              HasSubstr("bad.obj: soup: face 0 uses vertex 1 but there are only 1 vertices"));
  EXPECT_THAT(err("vn 0 0\n"), HasSubstr("bad.obj: line 1: expected 3 normal coordinates, found end of"));
  EXPECT_THAT(err("vt\n"), HasSubstr("bad.obj: line 1: expected 1 to 3 texture coordinates"));
  EXPECT_THAT(err("v 0 0 \\\n x\n"), HasSubstr("bad.obj: line 2: expected 3 coordinates, found 'x'"));
}

// ---------------------------------------------------------------------------------------
// PLY

const char* kAsciiPly =
    "ply\n"
    "format ascii 1.0\n"
    "comment made by hand\n"
    "obj_info nothing\n"
    "element camera 1\n"
    "property float view_px\n"
    "property list uchar int junk\n"
    "element vertex 4\n"
    "property float x\n"
    "property double y\n"
    "property int z\n"
    "property list int float extra\n"
    "property uchar red\n"
    "property uchar green\n"
    "property uchar blue\n"
    "property float confidence\n"
    "property float nx\n"
    "property float ny\n"
    "property float nz\n"
    "element face 2\n"
    "property uchar flags\n"
    "property list uchar uint vertex_indices\n"
    "property float red\n"
    "property float green\n"
    "property float blue\n"
    "property float alpha\n"
    "element edge 1\n"
    "property int vertex1\n"
    "property int vertex2\n"
    "end_header\n"
    "1.5 3 4 5 6\n"
    "0 0 0 0 255 0 0 0.5 0 0 1\n"
    "1 0 0 2 7.5 8.5 0 255 0 1 0 0 1\n"
    "1 1.25 0 1 1 0 0 255 1.5 0 0 1\n"
    "0 1 -3 0 10 20 30 2 0 0 1\n"
    "0 4 0 1 2 3 1 0 0 1\n"
    "7 3 3 2 1 0 0.5 1 0\n"
    "0 1\n";

TEST(IoPly, ReadsAsciiWithUnknownElementsAndProperties) {
  Soup s = read_ply(kAsciiPly, "t.ply");
  ASSERT_EQ(s.n_vertices(), 4u);
  EXPECT_EQ(s.positions[2], (Point{{1, 1.25f, 0}}));
  EXPECT_EQ(s.positions[3], (Point{{0, 1, -3}}));
  EXPECT_EQ(s.face_sizes, (std::vector<std::uint32_t>{4, 3}));
  EXPECT_EQ(s.corners, (std::vector<std::uint32_t>{0, 1, 2, 3, 3, 2, 1}));
  EXPECT_EQ(values<std::uint8_t>(channel(s, "color", Domain::vertex)),
            (std::vector<std::uint8_t>{255, 0, 0, 255, 0, 255, 0, 255, 0, 0, 255, 255, 10, 20, 30, 255}));
  EXPECT_EQ(values<float>(channel(s, "quality", Domain::vertex)), (std::vector<float>{0.5f, 1, 1.5f, 2}));
  EXPECT_EQ(values<float>(channel(s, "normal", Domain::vertex)),
            (std::vector<float>{0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1}));
  EXPECT_EQ(values<std::uint8_t>(channel(s, "color", Domain::face)),
            (std::vector<std::uint8_t>{255, 0, 0, 255, 0, 128, 255, 0}));
  EXPECT_EQ(s.channels.size(), 4u);
}

//! The same small mesh in binary PLY, with the given list types, and an unknown element
//! with a list before it.
std::string binary_ply(bool big, const std::string& count_type, const std::string& index_type) {
  std::string out = "ply\r\nformat ";
  out += big ? "binary_big_endian" : "binary_little_endian";
  out += " 1.0\r\n";
  out += "element material 2\nproperty list uchar double weights\nproperty int id\n";
  out += "element vertex 3\nproperty double x\nproperty float y\nproperty short z\nproperty list ushort char junk\n";
  out += "property float texture_u\nproperty float texture_v\n";
  out += "element face 2\nproperty list " + count_type + " " + index_type + " vertex_indices\n";
  out += "property list uchar float texcoord\nproperty int material_index\nproperty float quality\n";
  out += "end_header\n";
  // material: {1 weight, id}, {0 weights, id}
  put<std::uint8_t>(out, 1);
  put<double>(out, 0.5, big);
  put<std::int32_t>(out, 7, big);
  put<std::uint8_t>(out, 0);
  put<std::int32_t>(out, 8, big);
  const double xs[] = {0.0, 1.0, 0.0};
  const float ys[] = {0.0f, 0.0f, 1.0f};
  for (int v = 0; v < 3; ++v) {
    put<double>(out, xs[v], big);
    put<float>(out, ys[v], big);
    put<std::int16_t>(out, static_cast<std::int16_t>(-v), big);
    put<std::uint16_t>(out, static_cast<std::uint16_t>(v), big);
    for (int k = 0; k < v; ++k) put<std::int8_t>(out, static_cast<std::int8_t>(k));
    put<float>(out, 0.25f * static_cast<float>(v), big);
    put<float>(out, 1.0f, big);
  }
  auto put_count = [&](std::uint32_t n) {
    if (count_type == "uchar") put<std::uint8_t>(out, static_cast<std::uint8_t>(n));
    if (count_type == "ushort" || count_type == "uint16") put<std::uint16_t>(out, static_cast<std::uint16_t>(n), big);
    if (count_type == "int" || count_type == "int32") put<std::int32_t>(out, static_cast<std::int32_t>(n), big);
    if (count_type == "uint") put<std::uint32_t>(out, n, big);
  };
  auto put_index = [&](std::uint32_t i) {
    if (index_type == "uchar" || index_type == "uint8") put<std::uint8_t>(out, static_cast<std::uint8_t>(i));
    if (index_type == "ushort") put<std::uint16_t>(out, static_cast<std::uint16_t>(i), big);
    if (index_type == "short") put<std::int16_t>(out, static_cast<std::int16_t>(i), big);
    if (index_type == "int" || index_type == "int32") put<std::int32_t>(out, static_cast<std::int32_t>(i), big);
    if (index_type == "uint" || index_type == "uint32") put<std::uint32_t>(out, i, big);
    if (index_type == "float32") put<float>(out, static_cast<float>(i), big);
  };
  const std::uint32_t faces[2][3] = {{0, 1, 2}, {2, 1, 0}};
  for (int f = 0; f < 2; ++f) {
    put_count(3);
    for (std::uint32_t i : faces[f]) put_index(i);
    put<std::uint8_t>(out, 6);
    for (int k = 0; k < 6; ++k) put<float>(out, static_cast<float>(f * 6 + k) / 8.0f, big);
    put<std::int32_t>(out, f == 0 ? 3 : -1, big);
    put<float>(out, 2.5f * static_cast<float>(f), big);
  }
  return out;
}

void expect_binary_sample(const Soup& s) {
  ASSERT_EQ(s.n_vertices(), 3u);
  EXPECT_EQ(s.positions, (std::vector<Point>{{{0, 0, 0}}, {{1, 0, -1}}, {{0, 1, -2}}}));
  EXPECT_EQ(s.face_sizes, (std::vector<std::uint32_t>{3, 3}));
  EXPECT_EQ(s.corners, (std::vector<std::uint32_t>{0, 1, 2, 2, 1, 0}));
  EXPECT_EQ(values<float>(channel(s, "uv", Domain::vertex)), (std::vector<float>{0, 1, 0.25f, 1, 0.5f, 1}));
  std::vector<float> uv;
  for (int k = 0; k < 12; ++k) uv.push_back(static_cast<float>(k) / 8.0f);
  EXPECT_EQ(values<float>(channel(s, "uv", Domain::corner)), uv);
  EXPECT_EQ(values<std::int32_t>(channel(s, "material", Domain::face)), (std::vector<std::int32_t>{3, -1}));
  EXPECT_EQ(values<float>(channel(s, "quality", Domain::face)), (std::vector<float>{0, 2.5f}));
}

TEST(IoPly, ReadsBinaryWithAnyListTypes) {
  for (bool big : {false, true})
    for (const char* count : {"uchar", "ushort", "int", "uint"})
      for (const char* index : {"uchar", "ushort", "short", "int", "uint", "uint8", "int32", "uint32", "float32"}) {
        SCOPED_TRACE(std::string(big ? "big " : "little ") + count + " " + index);
        expect_binary_sample(read_ply(binary_ply(big, count, index), "b.ply"));
      }
}

TEST(IoPly, PointCloudWithoutFaces) {
  Soup s = read_ply(
      "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\nproperty float z\n"
      "end_header\n1 2 3\n4 5 6\n",
      "p.ply");
  EXPECT_EQ(s.n_vertices(), 2u);
  EXPECT_EQ(s.n_faces(), 0u);
}

Soup soup_with_all_ply_channels() {
  Soup soup = sample_soup();
  const std::size_t nv = soup.n_vertices(), nf = soup.n_faces(), nc = soup.n_corners();
  std::vector<float> normal(3 * nv), quality(nv), uv(2 * nv), face_quality(nf), corner_uv(2 * nc);
  std::vector<std::uint8_t> color(4 * nv), face_color(4 * nf);
  std::vector<std::int32_t> material(nf);
  for (std::size_t i = 0; i < normal.size(); ++i) normal[i] = std::sin(static_cast<float>(i));
  for (std::size_t i = 0; i < quality.size(); ++i) quality[i] = 1.0f / static_cast<float>(i + 1);
  for (std::size_t i = 0; i < uv.size(); ++i) uv[i] = static_cast<float>(i) * 0.1f;
  for (std::size_t i = 0; i < face_quality.size(); ++i) face_quality[i] = -static_cast<float>(i) / 3.0f;
  for (std::size_t i = 0; i < corner_uv.size(); ++i) corner_uv[i] = static_cast<float>(i) / 7.0f;
  for (std::size_t i = 0; i < color.size(); ++i) color[i] = static_cast<std::uint8_t>(i * 11);
  for (std::size_t i = 0; i < face_color.size(); ++i) face_color[i] = static_cast<std::uint8_t>(250 - i);
  for (std::size_t i = 0; i < material.size(); ++i) material[i] = static_cast<std::int32_t>(i) - 1;
  soup.channels.push_back(make_channel("normal", Domain::vertex, ScalarType::f32, 3, normal));
  soup.channels.push_back(make_channel("color", Domain::vertex, ScalarType::u8, 4, color));
  soup.channels.push_back(make_channel("quality", Domain::vertex, ScalarType::f32, 1, quality));
  soup.channels.push_back(make_channel("uv", Domain::vertex, ScalarType::f32, 2, uv));
  soup.channels.push_back(make_channel("color", Domain::face, ScalarType::u8, 4, face_color));
  soup.channels.push_back(make_channel("quality", Domain::face, ScalarType::f32, 1, face_quality));
  soup.channels.push_back(make_channel("material", Domain::face, ScalarType::i32, 1, material));
  soup.channels.push_back(make_channel("uv", Domain::corner, ScalarType::f32, 2, corner_uv));
  std::vector<std::uint8_t> selected(nv), face_selected(nf);
  for (std::size_t i = 0; i < nv; ++i) selected[i] = i % 2;
  for (std::size_t i = 0; i < nf; ++i) face_selected[i] = (i + 1) % 2;
  soup.channels.push_back(make_channel("selected", Domain::vertex, ScalarType::u8, 1, selected));
  soup.channels.push_back(make_channel("selected", Domain::face, ScalarType::u8, 1, face_selected));
  soup.check();
  return soup;
}

TEST(IoPly, RoundTrip) {
  for (bool binary : {true, false}) {
    SCOPED_TRACE(binary ? "binary" : "ascii");
    Soup plain = sample_soup();
    expect_same(read_ply(write_ply(plain, binary), "r.ply"), plain);
    Soup soup = soup_with_all_ply_channels();
    expect_same(read_ply(write_ply(soup, binary), "r.ply"), soup);
    // Channel order as the reader makes it: a second round trip is identical, bit for bit.
    Soup once = read_ply(write_ply(soup, binary), "r.ply");
    EXPECT_TRUE(read_ply(write_ply(once, binary), "r.ply") == once);
  }
  // Faces of more than 255 corners need a wider count type.
  Soup big;
  std::vector<std::uint32_t> ring;
  for (std::uint32_t i = 0; i < 300; ++i) {
    float a = static_cast<float>(i) * 0.02f;
    big.positions.push_back({{std::cos(a), std::sin(a), 0}});
    ring.push_back(i);
  }
  big.add_face(ring);
  expect_same(read_ply(write_ply(big, true), "big.ply"), big);
  expect_same(read_ply(write_ply(big, false), "big.ply"), big);
}

TEST(IoPly, TextInRunsReadsAsTheWholeFile) {
  // A text body of one element a line is read in runs of lines on several threads; any
  // other body, or an error, is read in one pass. Every run size gives the soup, or the
  // error, of the file read whole.
  const std::string head =
      "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
      "property uchar red\nproperty uchar green\nproperty uchar blue\nelement face 3\n"
      "property list uchar int vertex_indices\nproperty list uchar float texcoord\nproperty int material_index\n"
      "element note 2\nproperty float weight\nend_header\n";
  const std::string vertices = "0 0 0 255 0 0\n1 0 0 0 255 0\n0 1 0 0 0 255\n1 1 0.5 9 9 9\n";
  const std::vector<std::string> files = {
      head + vertices + "3 0 1 2 6 0 0 1 0 0 1 7\n3 1 3 2 0 -1\n4 0 1 3 2 8 0 0 1 0 1 1 0 1 2\n0.5\n0.25\n",
      head + vertices + "3 0 1 2 6 0 0 1 0 0 1 7\n3 1 3 2 0 -1\n4 0 1 3 2 8 0 0 1 0 1 1 0 1 2\n0.5\n0.25",
      head + vertices + "3 0 1 2 6 0 0 1 0 0 1 7\n3 1 3 2 0 -1\n4 0 1 3 2 8 0 0 1 0 1 1 0 1 2\n0.5\n0.25\n\n\n",
      // Elements over several lines, several on one, blank lines between: one pass.
      head +
          "0 0 0 255 0 0 1 0 0\n0 255 0\n0 1 0 0 0 255\n1 1 0.5 9 9 9\n3 0 1 2 6 0 0 1 0 0 1 7\n3 1 3 2 0 -1\n"
          "4 0 1 3 2 8 0 0 1 0 1 1 0 1 2\n0.5 0.25\n",
      head + vertices + "\n3 0 1 2 6 0 0 1 0 0 1 7\n3 1 3 2 0 -1\n4 0 1 3 2 8 0 0 1 0 1 1 0 1 2\n0.5\n0.25\n",
      // Errors: truncated, too many values, a bad number, a bad index, a texcoord mismatch.
      head + vertices + "3 0 1 2 6 0 0 1 0 0 1 7\n3 1 3 2 0 -1\n",
      head + vertices + "3 0 1 2 6 0 0 1 0 0 1 7\n3 1 3 2 0 -1\n4 0 1 3 2 8 0 0 1 0 1 1 0 1 2\n0.5\n0.25\n7\n",
      head + vertices + "3 0 1 2 6 0 0 1 0 0 1 7\n3 1 3 x 0 -1\n4 0 1 3 2 8 0 0 1 0 1 1 0 1 2\n0.5\n0.25\n",
      head + vertices + "3 0 1 9 6 0 0 1 0 0 1 7\n3 1 3 2 0 -1\n4 0 1 3 2 8 0 0 1 0 1 1 0 1 2\n0.5\n0.25\n",
      head + vertices + "3 0 1 2 4 0 0 1 0 7\n3 1 3 2 0 -1\n4 0 1 3 2 8 0 0 1 0 1 1 0 1 2\n0.5\n0.25\n",
  };
  auto read = [](const std::string& text) { return read_ply(text, "runs.ply"); };
  EXPECT_GT(expect_same_in_runs(files, read), 0u);
  const Soup s = read(files[0]);
  EXPECT_EQ(s.corners, (std::vector<std::uint32_t>{0, 1, 2, 1, 3, 2, 0, 1, 3, 2}));
  EXPECT_EQ(values<std::int32_t>(channel(s, "material", Domain::face)), (std::vector<std::int32_t>{7, -1, 2}));
}

TEST(IoPly, HeaderErrors) {
  auto err = [](const std::string& text) { return error_of([&] { read_ply(text, "bad.ply"); }); };
  const std::string start = "ply\nformat ascii 1.0\n";
  EXPECT_THAT(err(""), HasSubstr("bad.ply: line 1: expected 'ply', found an empty file"));
  EXPECT_THAT(err("OFF\n"), HasSubstr("bad.ply: line 1: expected 'ply' (this is not a PLY file), found 'OFF'"));
  EXPECT_THAT(err("ply\nformat ascii 1.0\nelement vertex 1\n"),
              HasSubstr("bad.ply: line 4: the header ends without 'end_header'"));
  EXPECT_THAT(err("ply\nformat utf8 1.0\n"),
              HasSubstr("bad.ply: line 2: expected ascii, binary_little_endian or binary_big_endian"));
  EXPECT_THAT(err("ply\nelement vertex 0\nend_header\n"),
              HasSubstr("bad.ply: line 3: the header has no 'format' line"));
  EXPECT_THAT(err(start + "property float x\n"), HasSubstr("bad.ply: line 3: property before the first element"));
  EXPECT_THAT(err(start + "element vertex x\n"), HasSubstr("bad.ply: line 3: expected 'element <name> <count>'"));
  EXPECT_THAT(err(start + "element vertex 1\nproperty quad x\n"),
              HasSubstr("bad.ply: line 4: unknown property type 'quad'"));
  EXPECT_THAT(err(start + "element face 1\nproperty list float int vertex_indices\n"),
              HasSubstr("bad.ply: line 4: the count type of a list must be an integer type"));
  EXPECT_THAT(err(start + "element vertex 1\nproperty float x\nproperty float y\nend_header\n0 0\n"),
              HasSubstr("bad.ply: line 3: element 'vertex' has no scalar property 'z'"));
  EXPECT_THAT(err(start + "element face 1\nproperty int vertex_indices\nend_header\n1\n"),
              HasSubstr("bad.ply: line 3: element 'face' has no list property 'vertex_indices'"));
  EXPECT_THAT(err(start + "bogus line\n"),
              HasSubstr("bad.ply: line 3: expected comment, element, property or end_header, found 'bogus'"));
  // Counts the file cannot hold: refused before anything is allocated.
  EXPECT_THAT(
      err(start +
          "element vertex 4000000000\nproperty float x\nproperty float y\nproperty float z\nend_header\n0 0 0\n"),
      HasSubstr("bad.ply: line 3: element 'vertex' declares 4000000000 instances, more than the rest of the file"));
  EXPECT_THAT(err("ply\nformat binary_little_endian 1.0\nelement vertex 1000\nproperty float x\nproperty float y\n"
                  "property float z\nend_header\n" +
                  std::string(1000, '\0')),
              HasSubstr("bad.ply: line 3: element 'vertex' declares 1000 instances"));
  EXPECT_THAT(err(start + "element junk 18446744073709551615\nproperty list uchar int x\nend_header\n"),
              HasSubstr("bad.ply: line 3: element 'junk' declares 18446744073709551615 instances"));
  EXPECT_THAT(err(start + "element vertex 5000000000\nend_header\n"),
              HasSubstr("bad.ply: line 3: 5,000,000,000 vertices asked for"));
}

TEST(IoPly, BodyErrors) {
  auto err = [](const std::string& text) { return error_of([&] { read_ply(text, "bad.ply"); }); };
  const std::string header =
      "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\nproperty float z\n"
      "element face 1\nproperty list uchar int vertex_indices\nend_header\n";
  EXPECT_THAT(err(header + "0 0 0\n0 abc 0\n3 0 1 1\n"),
              HasSubstr("bad.ply: line 11: expected float for vertex 1 (of 2), property 'y', found 'abc'"));
  EXPECT_THAT(err(header + "0 0 0\n0 0 0\n3 0 1.5 1\n"),
              HasSubstr("bad.ply: line 12: expected int for face 0 (of 1), property 'vertex_indices', found '1.5'"));
  EXPECT_THAT(err(header + "0 0 0\n0 0 0\n3 0 1\n"),
              HasSubstr("bad.ply: line 12: file ends, expected int for face 0 (of 1), property 'vertex_indices'"));
  EXPECT_THAT(err(header + "0 0 0\n0 0 0\n3 0 -1 1\n"),
              HasSubstr("bad.ply: line 12: vertex index -1 cannot be an index"));
  EXPECT_THAT(err(header + "0 0 0\n0 0 0\n3 0 1 1 5\n"),
              HasSubstr("bad.ply: line 12: expected the end of the file after the last element, found '5'"));
  EXPECT_THAT(err(header + "0 0 0\n0 0 0\n3 0 1 2\n"),
              HasSubstr("bad.ply: soup: face 0 uses vertex 2 but there are only 2 vertices"));

  // Binary: byte offsets. The body starts right after the header.
  std::string binary = binary_ply(false, "int", "int");
  const std::size_t body = binary.find("end_header\n") + 11;
  // Too short for what the header declares: refused up front.
  EXPECT_THAT(
      err(binary.substr(0, body + 10)),
      HasSubstr("element 'vertex' declares 3 instances, more than the rest of the file can hold (only 10 bytes"));
  // Long enough for the smallest possible faces, but these are bigger.
  EXPECT_THAT(err(binary.substr(0, body + 150)),
              HasSubstr("bad.ply: byte " + std::to_string(body + 150) +
                        ": file ends inside face 1 (of 2), property 'vertex_indices'"));
  // A negative list count.
  std::string negative = binary;
  std::size_t face0 = binary.size() - 2 * (4 + 12 + 1 + 24 + 4 + 4);
  std::int32_t minus = -5;
  std::memcpy(&negative[face0], &minus, 4);
  EXPECT_THAT(err(negative),
              HasSubstr("bad.ply: byte " + std::to_string(face0) + ": negative list length -5 in face 0 (of 2)"));
  // A list that claims more values than there are bytes.
  std::string huge = binary_ply(false, "int", "uint");  // unsigned indices: any bytes will do
  std::int32_t lots = 2000000000;
  std::memcpy(&huge[huge.size() - (binary.size() - face0)], &lots, 4);
  EXPECT_THAT(err(huge),
              HasSubstr("bad.ply: byte " + std::to_string(huge.size()) + ": file ends inside face 0 (of 2)"));
  // Texture coordinates that do not match the corners.
  std::string texcoords = binary;
  texcoords[face0 + 16] = 4;
  EXPECT_THAT(err(texcoords), HasSubstr("bad.ply: byte"));
  EXPECT_THAT(err(texcoords), HasSubstr("face 0 has 3 corners but 4 texture coordinates (expected two per corner)"));
}

TEST(IoPly, EveryTruncationIsAnErrorOrAMesh) {
  read_every_truncation(binary_ply(false, "uchar", "int"), read_ply);
  read_every_truncation(binary_ply(true, "ushort", "uint"), read_ply);
  read_every_truncation(write_ply(soup_with_all_ply_channels(), true), read_ply);
  read_every_truncation(write_ply(soup_with_all_ply_channels(), false), read_ply);
  read_every_truncation(kAsciiPly, read_ply);
}

// ---------------------------------------------------------------------------------------
// STL

std::string binary_stl(const std::vector<std::array<Point, 3>>& triangles, const std::string& header = "binary") {
  std::string out = header;
  out.resize(80, ' ');
  put<std::uint32_t>(out, static_cast<std::uint32_t>(triangles.size()));
  for (const auto& t : triangles) {
    for (int k = 0; k < 3; ++k) put<float>(out, 0.0f);
    for (const Point& p : t)
      for (int k = 0; k < 3; ++k) put<float>(out, p[k]);
    put<std::uint16_t>(out, 0);
  }
  return out;
}

std::vector<std::array<Point, 3>> cube_triangles() {
  std::vector<Point> c;
  for (int i = 0; i < 8; ++i) c.push_back({{float(i & 1), float((i >> 1) & 1), float((i >> 2) & 1)}});
  const int quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  std::vector<std::array<Point, 3>> t;
  for (const auto& q : quads) {
    t.push_back({c[q[0]], c[q[1]], c[q[2]]});
    t.push_back({c[q[0]], c[q[2]], c[q[3]]});
  }
  return t;
}

TEST(IoStl, BinaryWeldsEqualPositions) {
  Soup s = read_stl(binary_stl(cube_triangles()), "cube.stl");
  EXPECT_EQ(s.n_vertices(), 8u);
  EXPECT_EQ(s.n_faces(), 12u);
  EXPECT_EQ(s.n_corners(), 36u);
  // Vertices in order of first appearance.
  EXPECT_EQ(s.positions[0], (Point{{0, 0, 0}}));
  EXPECT_EQ(s.positions[1], (Point{{0, 1, 0}}));
  EXPECT_EQ(s.positions[2], (Point{{1, 1, 0}}));
  EXPECT_EQ((std::vector<std::uint32_t>(s.corners.begin(), s.corners.begin() + 6)),
            (std::vector<std::uint32_t>{0, 1, 2, 0, 2, 3}));
  for (const Point& p : s.positions) EXPECT_EQ(std::count(s.positions.begin(), s.positions.end(), p), 1);
}

TEST(IoStl, WeldsNegativeZeroButNotNearbyValues) {
  const float next = std::nextafter(1.0f, 2.0f);
  Soup s = read_stl(
      binary_stl({{{{{0, 0, 0}}, {{1, 0, 0}}, {{0, 1, 0}}}}, {{{{-0.0f, 0, -0.0f}}, {{0, 1, 0}}, {{next, 0, 0}}}}}),
      "z.stl");
  EXPECT_EQ(s.n_vertices(), 4u);
  EXPECT_EQ(s.corners, (std::vector<std::uint32_t>{0, 1, 2, 0, 2, 3}));
}

TEST(IoStl, Ascii) {
  Soup s = read_stl(
      "solid my part\n"
      "  facet normal 0 0 1\n"
      "    outer loop\n"
      "      vertex 0 0 0\n"
      "      vertex 1 0 0\n"
      "      vertex 1 1 0\n"
      "    endloop\n"
      "  endfacet\n"
      "  FACET NORMAL 0 0 1\n"
      "    OUTER LOOP\n"
      "      VERTEX 0 0 0\n"
      "      VERTEX 1 1 0\n"
      "      VERTEX 0 1 0\n"
      "    ENDLOOP\n"
      "  ENDFACET\n"
      "endsolid my part\n"
      "solid second\n"
      "facet normal 0 0 0 outer loop vertex 0 0 0 vertex 0 1 0 vertex 0 0 5 endloop endfacet\n"
      "endsolid\n",
      "a.stl");
  EXPECT_EQ(s.n_vertices(), 5u);
  EXPECT_EQ(s.face_sizes, (std::vector<std::uint32_t>{3, 3, 3}));
  EXPECT_EQ(s.corners, (std::vector<std::uint32_t>{0, 1, 2, 0, 2, 3, 0, 3, 4}));
}

TEST(IoStl, AsciiInRunsReadsAsTheWholeFile) {
  // Text STL is read in runs starting at a facet on several threads; a run that fails, or
  // ends where one pass would read on, hands the file to one pass. Every run size gives the
  // soup, or the error, of the file read whole.
  auto facet = [](int i, int corners = 3) {
    std::string t = "  facet normal 0 0 1\n    outer loop\n";
    for (int c = 0; c < corners; ++c)
      t += "      vertex " + std::to_string(i + c % 2) + " " + std::to_string(c) + " " + std::to_string(i % 3) + "\n";
    return t + "    endloop\n  endfacet\n";
  };
  std::string facets;
  for (int i = 0; i < 6; ++i) facets += facet(i, i == 4 ? 4 : 3);
  const std::vector<std::string> files = {
      "solid a\n" + facets + "endsolid a\n",
      "solid a\n" + facets + "endsolid a\nsolid b\n" + facet(7) + "endsolid b\n",
      "SOLID a\r\n" + facets + "ENDSOLID\r\n\r\n",
      "solid a\n" + facets + "endsolid a\n" + facet(9),
      "solid a\n" + facets + "endsolid a\n" + facet(9) + "endsolid a\n",
      "solid a\n" + facets,
      "solid a\n" + facets + facet(8, 2) + "endsolid a\n",
      "solid a\n" + facets + "  facet normal 0 0 x\n" + facets + "endsolid a\n",
      "solid a\n" + facets + "endsolid a\nsolid\n",
      "solid a\n" + facets + "endsolid a\njunk\n",
  };
  auto read = [](const std::string& text) { return read_stl(text, "runs.stl"); };
  EXPECT_GT(expect_same_in_runs(files, read), 0u);
  EXPECT_EQ(read(files[1]).n_faces(), 7u);
}

TEST(IoStl, BinaryHeaderStartingWithSolid) {
  Soup s = read_stl(binary_stl(cube_triangles(), "solid but binary"), "s.stl");
  EXPECT_EQ(s.n_faces(), 12u);
  // Padding after the triangles, with a "solid" header: still read as binary.
  std::string padded = binary_stl(cube_triangles(), "solid but binary") + std::string(7, '\0');
  EXPECT_EQ(read_stl(padded, "s.stl").n_faces(), 12u);
}

TEST(IoStl, RoundTrip) {
  // STL keeps triangles and positions only; vertices come back in first-use order.
  Soup soup;
  soup.positions = {{{0, 0, 0}}, {{1, 0, 0}}, {{1, 1, 0}}, {{0.1f, 1, 1e-9f}}, {{-3, 2.5f, 1e20f}}};
  soup.add_face({0, 1, 2});
  soup.add_face({0, 2, 3});
  soup.add_face({3, 2, 4});
  for (bool binary : {true, false}) expect_same(read_stl(write_stl(soup, binary), "r.stl"), soup);
  // Polygons are fanned into triangles.
  Soup s = read_stl(write_stl(sample_soup(), true), "fan.stl");
  EXPECT_EQ(s.n_faces(), 2u + 1 + 1 + 3);
  EXPECT_EQ(s.n_vertices(), 7u);
  // Facet normals are computed.
  std::string bytes = write_stl(soup, true);
  float n[3];
  std::memcpy(n, bytes.data() + 84, 12);
  EXPECT_EQ(n[0], 0.0f);
  EXPECT_EQ(n[1], 0.0f);
  EXPECT_EQ(n[2], 1.0f);
  EXPECT_NE(bytes.substr(0, 5), "solid");
}

TEST(IoStl, Errors) {
  auto err = [](const std::string& text) { return error_of([&] { read_stl(text, "x.stl"); }); };
  std::string cube = binary_stl(cube_triangles());
  EXPECT_THAT(err(cube.substr(0, 84 + 50 * 5 + 20)), HasSubstr("x.stl: byte 354: file ends inside triangle 5 of 12"));
  EXPECT_THAT(err("garbage"), HasSubstr("x.stl: byte 7: file ends inside the 84-byte header"));
  EXPECT_THAT(err(""), HasSubstr("x.stl: byte 0:"));
  EXPECT_THAT(err("solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 q 0\n"),
              HasSubstr("x.stl: line 5: expected 3 coordinates for a vertex of facet 0, found 'q'"));
  EXPECT_THAT(
      err("solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 1 1 0\nendloop\nendfacet\n"),
      HasSubstr("x.stl: line 8: expected 'facet' or 'endsolid', found end of file"));
  EXPECT_THAT(err("solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nendloop\nendfacet\nendsolid\n"),
              HasSubstr("x.stl: line 6: facet 0 has 2 vertices, expected 3"));
  EXPECT_THAT(err("solid x\nfacet 0 0 1\n"), HasSubstr("x.stl: line 2: expected 'normal', found '0'"));
  EXPECT_THAT(err("solid x\nendsolid x\nrubbish\n"),
              HasSubstr("x.stl: line 3: expected 'solid' or the end of the file, found 'rubbish'"));
  // NaN coordinates are reported (with the file name) by the soup check.
  EXPECT_THAT(err(binary_stl({{{{{0, 0, 0}}, {{1, 0, 0}}, {{std::nanf(""), 0, 0}}}}})),
              HasSubstr("x.stl: soup: vertex 2 has a NaN"));
}

TEST(IoStl, EveryTruncationIsAnErrorOrAMesh) {
  read_every_truncation(binary_stl(cube_triangles()), read_stl);
  read_every_truncation(write_stl(sample_soup(), false), read_stl);
}

// ---------------------------------------------------------------------------------------
// Malformed input in every reader

TEST(IoGarbage, TextTruncations) {
  read_every_truncation(write_off(sample_soup()), read_off);
  read_every_truncation(write_obj(sample_soup()), read_obj);
}

TEST(IoGarbage, RandomBytesAndMutations) {
  Soup (*readers[])(std::string_view, const std::string&) = {read_off, read_obj, read_ply, read_stl};
  std::vector<std::string> seeds = {write_off(soup_with_all_ply_channels()),
                                    write_obj(soup_with_all_ply_channels()),
                                    write_ply(soup_with_all_ply_channels(), true),
                                    write_ply(soup_with_all_ply_channels(), false),
                                    write_stl(sample_soup(), true),
                                    write_stl(sample_soup(), false),
                                    binary_ply(true, "uint", "ushort")};
  std::mt19937 rng(12345);
  for (int round = 0; round < 3000; ++round) {
    std::string bytes;
    if (round % 4 == 0) {
      bytes.resize(rng() % 300);
      for (char& c : bytes) c = static_cast<char>(rng());
      if (round % 8 == 0) bytes = "ply\nformat binary_big_endian 1.0\n" + bytes;
    } else {
      bytes = seeds[rng() % seeds.size()];
      int flips = 1 + static_cast<int>(rng() % 4);
      for (int k = 0; k < flips; ++k) bytes[rng() % bytes.size()] = static_cast<char>(rng());
    }
    for (auto reader : readers) {
      try {
        Soup s = reader(bytes, "fuzz");
        s.check();
      } catch (const Error&) {
      }
    }
  }
}

// ---------------------------------------------------------------------------------------
// Real meshes (fetched by scripts/fetch_meshes)

std::string mesh_path(const char* file) { return std::string(HEDGE_MESH_DIR) + "/" + file; }

TEST(IoRealMeshes, Bunny) {
  std::string path = mesh_path("bunny.off");
  if (!std::filesystem::exists(path)) GTEST_SKIP() << path << " is absent";
  Soup s = read_mesh(path);
  EXPECT_EQ(s.n_vertices(), 1839u);
  EXPECT_EQ(s.n_faces(), 3674u);
  expect_same(read_off(write_off(s), "bunny"), s);
}

TEST(IoRealMeshes, DragonRes4) {
  std::string path = mesh_path("dragon_res4.ply");
  if (!std::filesystem::exists(path)) GTEST_SKIP() << path << " is absent";
  Soup s = read_mesh(path);
  EXPECT_EQ(s.n_vertices(), 5205u);
  EXPECT_EQ(s.n_faces(), 11102u);
  for (std::uint32_t size : s.face_sizes) EXPECT_EQ(size, 3u);
  for (bool binary : {true, false}) {
    expect_same(read_ply(write_ply(s, binary), "d.ply"), s);
    Soup t = read_stl(write_stl(s, binary), "d.stl");
    ASSERT_EQ(t.n_faces(), s.n_faces());
    for (std::size_t c = 0; c < s.n_corners(); ++c) ASSERT_EQ(t.positions[t.corners[c]], s.positions[s.corners[c]]);
  }
  expect_same(read_obj(write_obj(s), "d.obj"), s);
}

TEST(IoRealMeshes, WritersGiveTheSameBytesInRunsOnAnyThreadCount) {
  // Writers format runs of elements on several threads: the dragon (coarse) with every
  // channel a writer carries, in one run and in runs of 7 elements on 1 to 8 threads.
  std::string path = mesh_path("dragon_res4.ply");
  if (!std::filesystem::exists(path)) GTEST_SKIP() << path << " is absent";
  Soup s = read_mesh(path);
  const std::size_t nv = s.n_vertices(), nc = s.n_corners(), nf = s.n_faces();
  std::vector<float> uv(2 * nc), normal(3 * nv), color(4 * nv);
  std::vector<std::int32_t> material(nf);
  for (std::size_t i = 0; i < uv.size(); ++i) uv[i] = s.positions[s.corners[i / 2]][i % 2];
  for (std::size_t i = 0; i < normal.size(); ++i) normal[i] = s.positions[i / 3][i % 3] * 0.5f;
  for (std::size_t i = 0; i < color.size(); ++i) color[i] = float(i % 255) / 255.0f;
  for (std::size_t f = 0; f < nf; ++f) material[f] = std::int32_t(f / 100 % 3) - 1;
  s.channels.push_back(make_channel("uv", Domain::corner, ScalarType::f32, 2, uv));
  s.channels.push_back(make_channel("normal", Domain::vertex, ScalarType::f32, 3, normal));
  s.channels.push_back(make_channel("color", Domain::vertex, ScalarType::f32, 4, color));
  s.channels.push_back(make_channel("material", Domain::face, ScalarType::i32, 1, material));
  ASSERT_NO_THROW(s.check());
  auto write_all = [&] {
    return std::vector<std::string>{write_off(s),       write_obj(s),        write_ply(s, false),
                                    write_ply(s, true), write_stl(s, false), write_stl(s, true)};
  };
  const std::vector<std::string> whole = write_all();
  for (unsigned threads : {1u, 2u, 3u, 8u}) {
    set_thread_count(threads);
    testing::set_parallel_grain(7);
    const std::size_t splits = testing::parallel_splits();
    const std::vector<std::string> in_runs = write_all();
    if (threads > 1) {
      EXPECT_GT(testing::parallel_splits(), splits);
    }
    set_thread_count(0);
    testing::set_parallel_grain(0);
    for (std::size_t i = 0; i < whole.size(); ++i)
      EXPECT_TRUE(in_runs[i] == whole[i]) << "writer " << i << ", " << threads << " threads";
  }
}

TEST(IoRealMeshes, Dragon) {
  std::string path = mesh_path("dragon.ply");
  if (!std::filesystem::exists(path)) GTEST_SKIP() << path << " is absent";
  auto start = std::chrono::steady_clock::now();
  Soup s = read_mesh(path);
  double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf("dragon.ply (ASCII, %zu vertices, %zu faces) read in %.3f s\n", s.n_vertices(), s.n_faces(), seconds);
  EXPECT_EQ(s.n_vertices(), 437645u);
  EXPECT_EQ(s.n_faces(), 871414u);
  EXPECT_EQ(s.n_corners(), 3u * 871414u);
  start = std::chrono::steady_clock::now();
  std::string binary = write_ply(s, true);
  Soup again = read_ply(binary, "dragon binary");
  seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf("dragon as binary PLY: written and read in %.3f s\n", seconds);
  EXPECT_TRUE(again == s);
}

}  // namespace
}  // namespace hedge
