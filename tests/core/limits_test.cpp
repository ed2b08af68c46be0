// The 32-bit limits: files, soups, meshes and subdivisions too large for the indices are
// refused up front with the limit and the count asked for, never wrapped and never
// attempted (no std::bad_alloc, no gigabytes allocated).
#include "hedge/limits.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstring>
#include <limits>
#include <string>

#include "hedge/build.h"
#include "hedge/error.h"
#include "hedge/io.h"
#include "hedge/mesh.h"
#include "hedge/subdivide.h"
#include "test_meshes.h"

namespace hedge {
namespace {

using ::testing::AllOf;
using ::testing::HasSubstr;

//! The message of the hedge::Error that `f` throws (fails the test if it throws nothing or
//! anything else, std::bad_alloc included).
template <class F>
std::string error_of(F&& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  } catch (const std::exception& e) {
    ADD_FAILURE() << "not a hedge::Error: " << e.what();
    return {};
  }
  ADD_FAILURE() << "nothing thrown";
  return {};
}

TEST(Limits, TheLimitsFollowFromThe32BitIndices) {
  EXPECT_EQ(kMaxElements, 4294967294u);  // all ones is the invalid handle
  EXPECT_EQ(kMaxHalfedges, 4294967294u);
  EXPECT_EQ(kMaxCorners, 2147483647u);  // a corner may need two half-edges
  EXPECT_EQ(kMaxFaces, 715827882u);
  EXPECT_EQ(with_commas(0), "0");
  EXPECT_EQ(with_commas(999), "999");
  EXPECT_EQ(with_commas(1000), "1,000");
  EXPECT_EQ(with_commas(3000000000u), "3,000,000,000");
}

TEST(Limits, PlyHeaderWithThreeBillionFacesIsRefusedBeforeAllocating) {
  for (const char* format : {"ascii", "binary_little_endian"}) {
    const std::string ply = std::string("ply\nformat ") + format +
                            " 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                            "element face 3000000000\nproperty list uchar int vertex_indices\nend_header\n";
    const std::string message = error_of([&] { read_ply(ply, "huge.ply"); });
    EXPECT_THAT(message,
                AllOf(HasSubstr("huge.ply"), HasSubstr("3,000,000,000 faces"), HasSubstr("at most 715,827,882 faces")))
        << format;
  }
  const std::string vertices =
      "ply\nformat binary_little_endian 1.0\nelement vertex 5000000000\nproperty float x\nproperty float y\n"
      "property float z\nend_header\n";
  EXPECT_THAT(error_of([&] { read_ply(vertices, "v.ply"); }),
              AllOf(HasSubstr("5,000,000,000 vertices"), HasSubstr("at most 4,294,967,294 vertices")));
}

TEST(Limits, PlyHeaderWithinTheLimitsButLargerThanTheFileIsRefused) {
  // 700 million faces fit the indices, not the 60 bytes that follow: refused, not allocated.
  const std::string ply =
      "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nelement face 700000000\nproperty list uchar int vertex_indices\nend_header\n" +
      std::string(60, '\0');
  EXPECT_THAT(error_of([&] { read_ply(ply, "short.ply"); }), HasSubstr("700000000"));
}

TEST(Limits, OffHeaderWithHugeCountsIsRefused) {
  EXPECT_THAT(error_of([] { read_off("OFF\n3 3000000000 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n", "huge.off"); }),
              AllOf(HasSubstr("huge.off"), HasSubstr("3,000,000,000 faces"), HasSubstr("715,827,882")));
  EXPECT_THAT(error_of([] { read_off("OFF\n6000000000 1 0\n0 0 0\n", "huge.off"); }),
              AllOf(HasSubstr("6,000,000,000 vertices"), HasSubstr("4,294,967,294")));
}

TEST(Limits, BinaryStlAnnouncingBillionsOfTrianglesIsRefused) {
  std::string stl(84, '\0');
  const std::uint32_t triangles = 3000000000u;
  std::memcpy(&stl[80], &triangles, 4);
  stl += std::string(50, '\0');  // one triangle's worth
  EXPECT_THAT(error_of([&] { read_stl(stl, "huge.stl"); }), HasSubstr("3000000000"));
}

TEST(Limits, SoupWhoseFaceSizesOverflow32BitsIsRefused) {
  // 4,294,967,295 + 4 wraps to 3 in 32 bits, the number of corners: the sum must not wrap.
  Soup soup;
  soup.positions = {Point{{0, 0, 0}}, Point{{1, 0, 0}}, Point{{0, 1, 0}}};
  soup.face_sizes = {0xffffffffu, 4};
  soup.corners = {0, 1, 2};
  EXPECT_THAT(error_of([&] { build(soup); }), AllOf(HasSubstr("4294967299"), HasSubstr("3")));
  EXPECT_THAT(error_of([&] { soup.check(); }), HasSubstr("4294967299"));
}

TEST(Limits, MeshGrowthBeyondTheIndicesIsRefusedBeforeAllocating) {
  Mesh mesh;
  EXPECT_THAT(error_of([&] { mesh.resize(5000000000u, 0, 0); }),
              AllOf(HasSubstr("5,000,000,000 vertices"), HasSubstr("at most 4,294,967,294 vertices")));
  EXPECT_THAT(error_of([&] { mesh.resize(0, std::size_t(1) << 31, 0); }),
              AllOf(HasSubstr("4,294,967,296 half-edges"), HasSubstr("at most 4,294,967,294 half-edges")));
  EXPECT_THAT(error_of([&] { mesh.resize(0, 0, std::size_t(1) << 32); }), HasSubstr("4,294,967,296 faces"));
  EXPECT_EQ(mesh.vertices_size(), 0u);
  EXPECT_EQ(mesh.halfedges_size(), 0u);
}

Mesh tetrahedron() {
  Soup soup;
  soup.positions = {Point{{0, 0, 0}}, Point{{1, 0, 0}}, Point{{0, 1, 0}}, Point{{0, 0, 1}}};
  soup.add_face({0, 2, 1});
  soup.add_face({0, 1, 3});
  soup.add_face({1, 2, 3});
  soup.add_face({0, 3, 2});
  return build(soup).mesh;
}

Mesh cube() {
  std::vector<Point> corners;
  for (int i = 0; i < 8; ++i) corners.push_back(Point{{float(i & 1), float((i >> 1) & 1), float(i >> 2)}});
  return test::make_mesh(corners, {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}});
}

TEST(Limits, SubdivisionBeyondTheIndicesIsRefusedBeforeStarting) {
  Mesh mesh = tetrahedron();
  SubdivideOptions options;
  options.max_faces = std::numeric_limits<std::size_t>::max();  // only the 32-bit limit is left
  options.iterations = 16;
  // Loop on a tetrahedron: 2E after step k is 48 * 4^(k-1); step 15 needs 12,884,901,888.
  EXPECT_THAT(error_of([&] { subdivide(mesh, options); }),
              AllOf(HasSubstr("16 iterations of loop"), HasSubstr("12,884,901,888 half-edges at step 15"),
                    HasSubstr("at most 4,294,967,294 half-edges"), HasSubstr("use at most 14 iterations")));
  EXPECT_EQ(mesh.n_faces(), 4u);  // untouched

  options.scheme = SubdivisionScheme::catmull_clark;
  options.iterations = 30;
  Mesh box = cube();
  const std::string message = error_of([&] { subdivide(box, options); });
  EXPECT_THAT(message, AllOf(HasSubstr("30 iterations of catmull_clark"), HasSubstr("half-edges at step"),
                             HasSubstr("4,294,967,294")));
  EXPECT_EQ(box.n_faces(), 6u);
}

TEST(Limits, TheSubdivisionForecastMatchesRealSteps) {
  // The recurrences behind the refusal (vertices, edges, faces per step), against real steps.
  for (SubdivisionScheme scheme : {SubdivisionScheme::loop, SubdivisionScheme::sqrt3, SubdivisionScheme::midpoint,
                                   SubdivisionScheme::catmull_clark}) {
    Mesh mesh = scheme == SubdivisionScheme::catmull_clark ? cube() : tetrahedron();
    SubdivideOptions options;
    options.scheme = scheme;
    options.iterations = 3;
    subdivide(mesh, options);
    const char* name = subdivision_scheme_name(scheme);
    // Per step: loop, midpoint and catmull_clark V' = V + E (+ F for polygons), E' = 2E + corners;
    // sqrt3 V' = V + F, E' = E + 3F (tetrahedron: V=4, E=6, F=4; cube: V=8, E=12, F=6).
    std::size_t v = 0, e = 0, f = 0;
    switch (scheme) {
      case SubdivisionScheme::loop:
      case SubdivisionScheme::midpoint:
        v = 130, e = 384, f = 256;
        break;
      case SubdivisionScheme::sqrt3:
        v = 4 + 4 + 12 + 36, e = 6 + 12 + 36 + 108, f = 108;
        break;
      case SubdivisionScheme::catmull_clark:
        v = 386, e = 768, f = 384;
        break;
    }
    EXPECT_EQ(mesh.n_vertices(), v) << name;
    EXPECT_EQ(mesh.n_edges(), e) << name;
    EXPECT_EQ(mesh.n_faces(), f) << name;
  }
}

}  // namespace
}  // namespace hedge
