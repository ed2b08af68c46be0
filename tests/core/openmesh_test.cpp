// hedge/openmesh.h: OpenMesh meshes to and from soups (properties by name, index order kept,
// every face of a non-manifold soup arrives) and .om files.
#include "hedge/openmesh.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <set>
#include <string>
#include <vector>

#include "hedge/catalogue.h"
#include "hedge/io.h"

namespace hedge {
namespace {

using PolyMesh = OpenMesh::PolyMesh_ArrayKernelT<>;
using TriMesh = OpenMesh::TriMesh_ArrayKernelT<>;
// Custom traits: double positions and float RGBA colours.
struct DoubleTraits : OpenMesh::DefaultTraits {
  typedef OpenMesh::Vec3d Point;
  typedef OpenMesh::Vec4f Color;
};
using DoublePolyMesh = OpenMesh::PolyMesh_ArrayKernelT<DoubleTraits>;

bool load_real(const std::string& name, Soup& soup) {
  const std::string path = std::string(HEDGE_MESH_DIR) + "/" + name;
  if (!std::filesystem::exists(path)) return false;
  soup = read_mesh(path);
  return true;
}

template <class OMesh>
std::vector<int> face_vertices(const OMesh& mesh, typename OMesh::FaceHandle face) {
  std::vector<int> out;
  for (auto v : mesh.fv_range(face)) out.push_back(v.idx());
  return out;
}

//! The soup's mesh built in OpenMesh with OpenMesh's own calls, given properties of every
//! kind: standard texcoords, custom scalars and vectors, a bool, and two that cannot travel.
struct Handles {
  OpenMesh::VPropHandleT<float> temperature;
  OpenMesh::VPropHandleT<OpenMesh::Vec3d> velocity;
  OpenMesh::VPropHandleT<bool> pinned;
  OpenMesh::VPropHandleT<std::string> label_text;
  OpenMesh::FPropHandleT<int> label;
  OpenMesh::HPropHandleT<OpenMesh::Vec2f> seam_uv;
  OpenMesh::EPropHandleT<float> crease;

  //! Looks up, by name, every property that travels (pinned must be declared as a bool).
  template <class OMesh>
  bool find(const OMesh& mesh) {
    return mesh.get_property_handle(temperature, "temperature") && mesh.get_property_handle(velocity, "velocity") &&
           mesh.get_property_handle(pinned, "pinned") && mesh.get_property_handle(label, "label") &&
           mesh.get_property_handle(seam_uv, "seam_uv") && mesh.has_vertex_texcoords2D() &&
           mesh.has_halfedge_texcoords2D();
  }
};

template <class OMesh>
Handles make_openmesh(const Soup& soup, OMesh& mesh) {
  for (const Point& p : soup.positions) mesh.add_vertex(typename OMesh::Point(p[0], p[1], p[2]));
  std::size_t at = 0;
  for (std::uint32_t size : soup.face_sizes) {
    std::vector<typename OMesh::VertexHandle> face;
    for (std::uint32_t k = 0; k < size; ++k) face.emplace_back(static_cast<int>(soup.corners[at + k]));
    at += size;
    EXPECT_TRUE(mesh.add_face(face).is_valid());
  }
  Handles h;
  mesh.add_property(h.temperature, "temperature");
  mesh.add_property(h.velocity, "velocity");
  mesh.add_property(h.pinned, "pinned");
  mesh.add_property(h.label_text, "label_text");
  mesh.add_property(h.label, "label");
  mesh.add_property(h.seam_uv, "seam_uv");
  mesh.add_property(h.crease, "crease");
  mesh.request_vertex_texcoords2D();
  mesh.request_halfedge_texcoords2D();
  for (auto v : mesh.vertices()) {
    const auto p = mesh.point(v);
    mesh.property(h.temperature, v) = static_cast<float>(v.idx() % 11) - 5;  // -5 .. 5: 0 inside
    mesh.property(h.velocity, v) = OpenMesh::Vec3d(p[0], -p[1], 2.0);
    mesh.property(h.pinned, v) = v.idx() % 3 == 0;
    mesh.set_texcoord2D(v, OpenMesh::Vec2f(0.25f, 0.75f));
  }
  for (auto f : mesh.faces()) mesh.property(h.label, f) = f.idx() % 7;
  for (auto he : mesh.halfedges()) {
    mesh.property(h.seam_uv, he) = OpenMesh::Vec2f(0.5f, static_cast<float>(he.idx() % 2));
    mesh.set_texcoord2D(he, OpenMesh::Vec2f(0.125f, 0.5f));
  }
  return h;
}

std::set<std::string> names(const std::vector<openmesh::SkippedProperty>& skipped) {
  std::set<std::string> out;
  for (const auto& s : skipped) out.insert(s.name);
  return out;
}

//! A small closed mesh (an octahedron) when the real meshes are not there.
Soup octahedron() {
  Soup s;
  s.positions = {Point{{1, 0, 0}},  Point{{-1, 0, 0}}, Point{{0, 1, 0}},
                 Point{{0, -1, 0}}, Point{{0, 0, 1}},  Point{{0, 0, -1}}};
  for (auto f : std::vector<std::vector<std::uint32_t>>{
           {0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4}, {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}})
    s.add_face(f);
  return s;
}

TEST(OpenMesh, PropertiesTravelByNameAndANoOpRoundTripKeepsIndexOrder) {
  Soup input;
  if (!load_real("bunny.off", input)) input = octahedron();
  PolyMesh mesh;
  const Handles handles = make_openmesh(input, mesh);

  std::vector<openmesh::SkippedProperty> skipped;
  const Soup soup = openmesh::to_soup(mesh, &skipped);
  EXPECT_EQ(soup.positions, input.positions);
  EXPECT_EQ(soup.face_sizes, input.face_sizes);
  EXPECT_EQ(soup.corners, input.corners);  // OpenMesh's face order and corner order
  const auto expect_channel = [&](const char* name, Domain domain, ScalarType scalar, int components) {
    const Channel* c = soup.find(name, domain);
    ASSERT_NE(c, nullptr) << name << " " << domain_name(domain);
    EXPECT_EQ(c->scalar, scalar) << name;
    EXPECT_EQ(c->components, components) << name;
  };
  expect_channel("temperature", Domain::vertex, ScalarType::f32, 1);
  expect_channel("velocity", Domain::vertex, ScalarType::f64, 3);
  expect_channel("pinned", Domain::vertex, ScalarType::u8, 1);
  expect_channel("label", Domain::face, ScalarType::i32, 1);
  expect_channel("seam_uv", Domain::corner, ScalarType::f32, 2);
  expect_channel("uv", Domain::vertex, ScalarType::f32, 2);
  expect_channel("uv", Domain::corner, ScalarType::f32, 2);
  // A string and an edge property cannot travel, and are named.
  EXPECT_EQ(names(skipped), (std::set<std::string>{"label_text", "crease"}));

  // Corner k of face f is the half-edge pointing to it: its values follow.
  const Channel& seam = *soup.find("seam_uv", Domain::corner);
  std::size_t corner = 0;
  for (auto f : mesh.faces())
    for (auto he : mesh.fh_range(f)) {
      EXPECT_EQ(seam.as<float>()[2 * corner + 1], static_cast<float>(he.idx() % 2));
      ++corner;
    }

  // Back into OpenMesh (a different kernel, double positions): same indices, same values.
  DoublePolyMesh back;
  OpenMesh::VPropHandleT<bool> pinned;
  back.add_property(pinned, "pinned");  // a declared property keeps its type
  const openmesh::FromSoupReport report = openmesh::from_soup(soup, back);
  EXPECT_EQ(report.vertex_copies, 0u);
  EXPECT_TRUE(report.skipped.empty());
  ASSERT_EQ(back.n_vertices(), mesh.n_vertices());
  ASSERT_EQ(back.n_faces(), mesh.n_faces());
  for (auto v : mesh.vertices()) {
    const auto a = mesh.point(v);
    const auto b = back.point(DoublePolyMesh::VertexHandle(v.idx()));
    for (int k = 0; k < 3; ++k) EXPECT_EQ(static_cast<float>(b[k]), a[k]);
  }
  for (auto f : mesh.faces())
    ASSERT_EQ(face_vertices(back, DoublePolyMesh::FaceHandle(f.idx())), face_vertices(mesh, f));
  Handles found;
  ASSERT_TRUE(found.find(back));
  const auto& [temperature, velocity, pinned_, label_text, label, seam_uv, crease] = found;
  for (auto v : back.vertices()) {
    EXPECT_EQ(back.property(pinned, v), v.idx() % 3 == 0);
    EXPECT_EQ(back.property(velocity, v)[2], 2.0);
    EXPECT_EQ(back.texcoord2D(v), OpenMesh::Vec2f(0.25f, 0.75f));
  }
  for (auto f : back.faces()) {
    EXPECT_EQ(back.property(label, f), f.idx() % 7);
    for (auto he : back.fh_range(f)) {
      EXPECT_EQ(back.texcoord2D(he), OpenMesh::Vec2f(0.125f, 0.5f));
      const auto original = mesh.find_halfedge(PolyMesh::VertexHandle(back.from_vertex_handle(he).idx()),
                                               PolyMesh::VertexHandle(back.to_vertex_handle(he).idx()));
      EXPECT_EQ(back.property(seam_uv, he), mesh.property(handles.seam_uv, original));
    }
  }
  // And the soup of that mesh is the soup again.
  const Soup again = openmesh::to_soup(back);
  EXPECT_EQ(again.corners, soup.corners);
  for (const Channel& c : soup.channels) {
    const Channel* d = again.find(c.name, c.domain);
    ASSERT_NE(d, nullptr) << c.name;
    EXPECT_EQ(*d, c) << c.name;
  }
}

TEST(OpenMesh, EveryOperationCarriesThePropertiesByName) {
  Soup input;
  if (!load_real("bunny.off", input)) input = octahedron();
  PolyMesh mesh;
  make_openmesh(input, mesh);
  const Soup soup = openmesh::to_soup(mesh);
  for (const Operation& op : catalogue()) {
    SCOPED_TRACE(op.id);
    Progress progress;
    RunResult result = run_operation(op, soup, resolve_params(op, std::map<std::string, std::string>{}), progress);
    if (!op.changes_mesh) continue;
    PolyMesh out;
    OpenMesh::VPropHandleT<bool> pinned;
    out.add_property(pinned, "pinned");
    const openmesh::FromSoupReport report = openmesh::from_soup(result.soup, out);
    EXPECT_TRUE(report.skipped.empty());
    EXPECT_TRUE(report.skipped_faces.empty());
    ASSERT_EQ(out.n_faces(), result.soup.n_faces());
    ASSERT_GT(out.n_faces(), 0u);
    Handles found;
    ASSERT_TRUE(found.find(out));
    const auto& [temperature, velocity, pinned_, label_text, label, seam_uv, crease] = found;
    // Interpolated values stay within what went in; labels stay labels.
    for (auto v : out.vertices()) {
      EXPECT_GE(out.property(temperature, v), -5.001f);
      EXPECT_LE(out.property(temperature, v), 5.001f);
      EXPECT_NEAR(out.property(velocity, v)[2], 2.0, 1e-5);
      EXPECT_NEAR(out.texcoord2D(v)[0], 0.25f, 1e-5);
    }
    for (auto f : out.faces()) {
      EXPECT_GE(out.property(label, f), 0);
      EXPECT_LT(out.property(label, f), 7);
      for (auto he : out.fh_range(f)) {
        EXPECT_NEAR(out.texcoord2D(he)[1], 0.5f, 1e-5);
        EXPECT_NEAR(out.property(seam_uv, he)[0], 0.5f, 1e-5);
      }
    }
    // A TriMesh takes the same soup, polygons split into fans that name their source face.
    TriMesh triangles;
    const openmesh::FromSoupReport tri = openmesh::from_soup(result.soup, triangles);
    ASSERT_GE(triangles.n_faces(), result.soup.n_faces());
    EXPECT_EQ(std::set<std::uint32_t>(tri.face_source.begin(), tri.face_source.end()).size(), result.soup.n_faces());
  }
}

//! Three faces on edge 0-1, a closed fan around vertex 5 with one more face touching it
//! there, and a face of two distinct vertices.
Soup non_manifold_soup() {
  Soup s;
  s.positions = {Point{{0, 0, 0}},    Point{{1, 0, 0}},  Point{{0.5f, 1, 0}}, Point{{0.5f, -1, 0}},
                 Point{{0.5f, 0, 1}}, Point{{3, 0, 0}},  Point{{4, 0, 0}},    Point{{3, 1, 0}},
                 Point{{2, 0, 0}},    Point{{3, -1, 0}}, Point{{3, 0, 1}},    Point{{3, 1, 1}}};
  s.add_face({0, 1, 2});
  s.add_face({1, 0, 3});
  s.add_face({0, 1, 4});  // the third face on edge 0-1
  s.add_face({5, 6, 7});  // closed fan around 5
  s.add_face({5, 7, 8});
  s.add_face({5, 8, 9});
  s.add_face({5, 9, 6});
  s.add_face({5, 10, 11});  // touches the closed fan at 5
  s.add_face({0, 0, 1});    // not a polygon
  Channel& corner = s.add_channel("corner_id", Domain::corner, ScalarType::i32, 1);
  for (std::size_t i = 0; i < s.n_corners(); ++i) corner.as<std::int32_t>()[i] = static_cast<std::int32_t>(i);
  Channel& face = s.add_channel("face_id", Domain::face, ScalarType::u16, 1);
  for (std::size_t i = 0; i < s.n_faces(); ++i) face.as<std::uint16_t>()[i] = static_cast<std::uint16_t>(i);
  return s;
}

TEST(OpenMesh, NonManifoldSoupArrivesWithEveryFace) {
  const Soup soup = non_manifold_soup();
  // OpenMesh on its own refuses the third face on the edge and the face at the closed fan.
  {
    PolyMesh direct;
    for (const Point& p : soup.positions) direct.add_vertex(PolyMesh::Point(p[0], p[1], p[2]));
    const std::vector<std::size_t> offsets = soup.face_offsets();
    std::size_t refused = 0;
    ::omerr().disable();  // its "complex edge" and "complex vertex" are expected here
    for (std::size_t f = 0; f + 1 < soup.n_faces(); ++f) {
      std::vector<PolyMesh::VertexHandle> face;
      for (std::size_t k = offsets[f]; k < offsets[f + 1]; ++k) face.emplace_back(static_cast<int>(soup.corners[k]));
      refused += !direct.add_face(face).is_valid();
    }
    ::omerr().enable();
    EXPECT_EQ(refused, 2u);
    EXPECT_EQ(direct.n_faces(), soup.n_faces() - 1 - refused);
  }
  PolyMesh mesh;
  const openmesh::FromSoupReport report = openmesh::from_soup(soup, mesh);
  EXPECT_EQ(report.skipped_faces, std::vector<std::uint32_t>{8});
  ASSERT_EQ(mesh.n_faces(), soup.n_faces() - 1);
  EXPECT_GT(report.vertex_copies, 0u);
  EXPECT_EQ(report.vertex_copies, mesh.n_vertices() - soup.n_vertices());
  ASSERT_EQ(report.vertex_source.size(), mesh.n_vertices());
  for (std::size_t v = 0; v < soup.n_vertices(); ++v) EXPECT_EQ(report.vertex_source[v], v);
  // Each face in order, its corners in order, at copies of the soup's vertices.
  const std::vector<std::size_t> offsets = soup.face_offsets();
  OpenMesh::HPropHandleT<std::int32_t> corner_id;
  OpenMesh::FPropHandleT<std::uint16_t> face_id;
  ASSERT_TRUE(mesh.get_property_handle(corner_id, "corner_id"));
  ASSERT_TRUE(mesh.get_property_handle(face_id, "face_id"));
  for (auto f : mesh.faces()) {
    const std::uint32_t source = report.face_source[static_cast<std::size_t>(f.idx())];
    EXPECT_EQ(source, static_cast<std::uint32_t>(f.idx()));
    EXPECT_EQ(mesh.property(face_id, f), source);
    std::size_t k = offsets[source];
    for (auto he : mesh.fh_range(f)) {
      const auto v = static_cast<std::size_t>(mesh.to_vertex_handle(he).idx());
      EXPECT_EQ(report.vertex_source[v], soup.corners[k]);
      EXPECT_EQ(mesh.point(mesh.to_vertex_handle(he)), mesh.point(PolyMesh::VertexHandle(int(soup.corners[k]))));
      EXPECT_EQ(mesh.property(corner_id, he), static_cast<std::int32_t>(k));
      ++k;
    }
    EXPECT_EQ(k, offsets[source + 1]);
  }
}

TEST(OpenMesh, RealNonManifoldMeshArrivesWhole) {
  Soup soup;
  if (!load_real("dragon_res4.ply", soup)) GTEST_SKIP() << "dragon_res4.ply not in " << HEDGE_MESH_DIR;
  TriMesh mesh;
  const openmesh::FromSoupReport report = openmesh::from_soup(soup, mesh);
  EXPECT_GT(report.build.non_manifold_edges, 0u);
  ASSERT_EQ(mesh.n_faces() + report.skipped_faces.size(), soup.n_faces());
  for (auto v : mesh.vertices()) {
    const Point& p = soup.positions[report.vertex_source[static_cast<std::size_t>(v.idx())]];
    ASSERT_EQ(mesh.point(v), TriMesh::Point(p[0], p[1], p[2]));
  }
}

TEST(OpenMesh, OmFilesKeepChannelsAndRefuseBadInput) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "hedge_openmesh_test";
  std::filesystem::create_directories(dir);
  Soup soup = non_manifold_soup();
  Channel& color = soup.add_channel("color", Domain::vertex, ScalarType::u8, 4);
  for (std::size_t i = 0; i < color.data.size(); ++i) color.data[i] = std::byte(i % 251);
  const std::string path = (dir / "a.om").string();
  const openmesh::FromSoupReport written = openmesh::write_om(soup, path);
  const Soup read = openmesh::read_om(path);
  EXPECT_EQ(read.n_faces(), soup.n_faces() - 1);
  EXPECT_EQ(read.n_vertices(), soup.n_vertices() + written.vertex_copies);
  for (const char* name : {"corner_id", "face_id", "color"}) {
    bool found = false;
    for (const Channel& c : read.channels) found |= c.name == name;
    EXPECT_TRUE(found) << name;
  }
  const Channel* read_color = read.find("color", Domain::vertex);
  ASSERT_NE(read_color, nullptr);
  ASSERT_GE(read_color->data.size(), color.data.size());  // the soup's vertices, then copies
  for (std::size_t i = 0; i < color.data.size(); ++i)     // OpenMesh's .om keeps RGB; alpha reads back 255
    EXPECT_EQ(read_color->data[i], i % 4 == 3 ? std::byte(255) : color.data[i]) << i;

  // Not .om, cut short, garbage: an Error naming the file, never a crash. OpenMesh's reader
  // stops quietly inside a property chunk, so a file cut there reads with its geometry whole.
  const std::string bad = (dir / "bad.om").string();
  const auto expect_refused = [&](const std::string& bytes, const std::string& what, bool or_whole = false) {
    std::ofstream(bad, std::ios::binary) << bytes;
    try {
      const Soup partial = openmesh::read_om(bad);
      EXPECT_TRUE(or_whole) << what << " was read";
      EXPECT_EQ(partial.n_faces(), read.n_faces()) << what;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(bad), std::string::npos) << e.what();
    }
  };
  expect_refused("ply\nformat ascii 1.0\n", "a PLY file");
  expect_refused("", "an empty file");
  std::ifstream in(path, std::ios::binary);
  const std::string whole((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  for (std::size_t length = 0; length < whole.size(); length += 7)
    expect_refused(whole.substr(0, length), "the first " + std::to_string(length) + " bytes", true);
  std::string huge = whole;
  huge[4] = huge[5] = huge[6] = huge[7] = char(0xff);  // 4 billion vertices promised
  expect_refused(huge, "a header promising too much");
  EXPECT_THROW(openmesh::read_om((dir / "missing.om").string()), Error);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace hedge
