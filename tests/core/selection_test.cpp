// selection_only (core/src/selection.h): every operation that has it leaves the faces outside
// the host's selection as they were, so the border between selected and unselected stays put
// and watertight; inside the selection it does its work.

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "hedge/catalogue.h"
#include "hedge/io.h"
#include "hedge/soup.h"

namespace {

using namespace hedge;

using Corners = std::vector<std::array<float, 3>>;

bool load_bunny(Soup& soup) {
  const std::string path = std::string(HEDGE_MESH_DIR) + "/bunny.off";
  if (!std::filesystem::exists(path)) return false;
  soup = read_mesh(path);
  return true;
}

//! Selects the faces whose first corner lies left of the median x (about half the mesh).
void select_left_half(Soup& soup) {
  const std::vector<std::size_t> offsets = soup.face_offsets();
  std::vector<float> xs;
  for (std::size_t f = 0; f < soup.n_faces(); ++f) xs.push_back(soup.positions[soup.corners[offsets[f]]][0]);
  std::vector<float> sorted = xs;
  std::nth_element(sorted.begin(), sorted.begin() + std::ptrdiff_t(sorted.size() / 2), sorted.end());
  const float median = sorted[sorted.size() / 2];
  auto* selected = soup.add_channel("selected", Domain::face, ScalarType::u8, 1).as<std::uint8_t>();
  for (std::size_t f = 0; f < soup.n_faces(); ++f) selected[f] = xs[f] < median;
}

const std::uint8_t* face_selection(const Soup& soup) {
  const Channel* c = soup.find("selected", Domain::face);
  return c ? c->as<std::uint8_t>() : nullptr;
}

//! The faces with selection flag `want`, each as its corner positions from the smallest one
//! on (the pipeline may renumber vertices, not move unselected corners), sorted.
std::vector<Corners> faces_where(const Soup& soup, bool want) {
  const std::uint8_t* selected = face_selection(soup);
  const std::vector<std::size_t> offsets = soup.face_offsets();
  std::vector<Corners> out;
  for (std::size_t f = 0; f < soup.n_faces(); ++f) {
    if (bool(selected[f]) != want) continue;
    Corners c;
    for (std::size_t k = offsets[f]; k < offsets[f + 1]; ++k) {
      const Point& p = soup.positions[soup.corners[k]];
      c.push_back({p[0], p[1], p[2]});
    }
    std::rotate(c.begin(), std::min_element(c.begin(), c.end()), c.end());
    out.push_back(c);
  }
  std::sort(out.begin(), out.end());
  return out;
}

//! Edges of unselected faces that have no other face (by corner positions, so renumbering
//! does not matter): a crack along the border of the selection would add some.
std::size_t open_unselected_edges(const Soup& soup) {
  std::map<std::pair<std::array<float, 3>, std::array<float, 3>>, int> uses;
  std::vector<std::pair<std::array<float, 3>, std::array<float, 3>>> unselected;
  const std::uint8_t* selected = face_selection(soup);
  const std::vector<std::size_t> offsets = soup.face_offsets();
  for (std::size_t f = 0; f < soup.n_faces(); ++f)
    for (std::size_t k = offsets[f]; k < offsets[f + 1]; ++k) {
      const std::size_t next = k + 1 == offsets[f + 1] ? offsets[f] : k + 1;
      const Point &a = soup.positions[soup.corners[k]], &b = soup.positions[soup.corners[next]];
      std::array<float, 3> pa{a[0], a[1], a[2]}, pb{b[0], b[1], b[2]};
      if (pb < pa) std::swap(pa, pb);
      ++uses[{pa, pb}];
      if (!selected[f]) unselected.push_back({pa, pb});
    }
  return std::size_t(std::count_if(unselected.begin(), unselected.end(), [&](const auto& e) { return uses[e] == 1; }));
}

RunResult run(const std::string& id, const Soup& input, std::map<std::string, std::string> params) {
  const Operation& op = find_operation(id);
  params["selection_only"] = "true";
  return run_operation(op, input, resolve_params(op, params), Progress::none());
}

//! The bunny as quads (one Catmull-Clark step), for the operations that treat polygons.
Soup quad_bunny(const Soup& bunny) {
  return run_operation(find_operation("subdivide"), bunny,
                       resolve_params(find_operation("subdivide"),
                                      std::map<std::string, std::string>{{"scheme", "catmull_clark"}}),
                       Progress::none())
      .soup;
}

std::vector<const Operation*> with_selection() {
  std::vector<const Operation*> out;
  for (const Operation& op : catalogue())
    if (op.find_param("selection_only")) out.push_back(&op);
  return out;
}

TEST(Selection, EveryOperationWithItKeepsTheUnselectedFaces) {
  Soup bunny;
  if (!load_bunny(bunny)) GTEST_SKIP() << "bunny.off not present";
  Soup quads = quad_bunny(bunny);
  select_left_half(bunny);
  select_left_half(quads);
  const std::vector<const Operation*> ops = with_selection();
  ASSERT_GE(ops.size(), 4u);
  for (const Operation* op : ops) {
    for (const Soup* input : {&bunny, &quads}) {
      const bool triangles = input == &bunny;
      if (!triangles && op->id == "make_delaunay") continue;  // triangle meshes only
      if (triangles && op->id == "triangulate") continue;     // nothing to do
      SCOPED_TRACE(op->id + (triangles ? " on the bunny" : " on the quad bunny"));
      std::map<std::string, std::string> params;
      if (!triangles && op->id == "subdivide") params["scheme"] = "catmull_clark";  // loop: triangles only
      const RunResult r = run(op->id, *input, params);
      ASSERT_NE(face_selection(r.soup), nullptr);
      EXPECT_EQ(faces_where(r.soup, false), faces_where(*input, false));
      EXPECT_EQ(open_unselected_edges(r.soup), open_unselected_edges(*input));
      // (fill_holes: no hole of the bunny lies inside the left half; see the test below)
      if (op->id != "fill_holes") {
        EXPECT_NE(faces_where(r.soup, true), faces_where(*input, true)) << "nothing changed inside the selection";
      }
      EXPECT_TRUE(r.report.messages.empty() ||
                  std::find(r.report.messages.begin(), r.report.messages.end(),
                            "selection_only: nothing is selected, so the mesh is unchanged") ==
                      r.report.messages.end());
    }
  }
}

// Selects the faces around one hole of the bunny (every face touching its border); returns
// how many faces that is.
std::size_t select_around_one_hole(Soup& soup) {
  const std::vector<std::size_t> offsets = soup.face_offsets();
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> uses;
  for (std::size_t f = 0; f < soup.n_faces(); ++f)
    for (std::size_t k = offsets[f]; k < offsets[f + 1]; ++k) {
      const std::uint32_t a = soup.corners[k], b = soup.corners[k + 1 == offsets[f + 1] ? offsets[f] : k + 1];
      ++uses[{std::min(a, b), std::max(a, b)}];
    }
  std::map<std::uint32_t, std::vector<std::uint32_t>> next;  // boundary graph
  for (const auto& [edge, n] : uses)
    if (n == 1) next[edge.first].push_back(edge.second), next[edge.second].push_back(edge.first);
  if (next.empty()) return 0;  // a closed surface
  std::vector<char> on_hole(soup.n_vertices(), 0);
  std::vector<std::uint32_t> stack{next.begin()->first};
  while (!stack.empty()) {
    const std::uint32_t v = stack.back();
    stack.pop_back();
    if (on_hole[v]) continue;
    on_hole[v] = 1;
    for (std::uint32_t w : next[v]) stack.push_back(w);
  }
  auto* selected = soup.add_channel("selected", Domain::face, ScalarType::u8, 1).as<std::uint8_t>();
  std::size_t count = 0;
  for (std::size_t f = 0; f < soup.n_faces(); ++f) {
    for (std::size_t k = offsets[f]; k < offsets[f + 1]; ++k) selected[f] |= on_hole[soup.corners[k]];
    count += selected[f];
  }
  return count;
}

//! Opens two holes in the (closed) bunny: the faces with a corner near its leftmost and its
//! rightmost vertex go.
void cut_two_holes(Soup& soup) {
  std::size_t left = 0, right = 0;
  for (std::size_t v = 0; v < soup.n_vertices(); ++v) {
    if (soup.positions[v][0] < soup.positions[left][0]) left = v;
    if (soup.positions[v][0] > soup.positions[right][0]) right = v;
  }
  const std::vector<std::size_t> offsets = soup.face_offsets();
  Soup out;
  out.positions = soup.positions;
  for (std::size_t f = 0; f < soup.n_faces(); ++f) {
    bool near = false;
    std::vector<std::uint32_t> corners;
    for (std::size_t k = offsets[f]; k < offsets[f + 1]; ++k) {
      const Point& p = soup.positions[soup.corners[k]];
      for (std::size_t c : {left, right}) {
        const Point& q = soup.positions[c];
        const float dx = p[0] - q[0], dy = p[1] - q[1], dz = p[2] - q[2];
        near = near || dx * dx + dy * dy + dz * dz < 0.25f;
      }
      corners.push_back(soup.corners[k]);
    }
    if (!near) out.add_face(corners);
  }
  soup = std::move(out);
}

TEST(Selection, FillHolesFillsOnlyHolesWithASelectedBorder) {
  Soup bunny;
  if (!load_bunny(bunny)) GTEST_SKIP() << "bunny.off not present";
  cut_two_holes(bunny);
  ASSERT_GT(select_around_one_hole(bunny), 0u);
  const RunResult r = run("fill_holes", bunny, {});
  const std::int64_t found = std::get<std::int64_t>(*r.report.find("holes_found"));
  ASSERT_GT(found, 1);
  EXPECT_EQ(std::get<std::int64_t>(*r.report.find("holes_filled")), 1);
  EXPECT_EQ(std::get<std::int64_t>(*r.report.find("holes_not_selected")), found - 1);
  EXPECT_EQ(faces_where(r.soup, false), faces_where(bunny, false));
  EXPECT_GT(r.soup.n_faces(), bunny.n_faces());  // the patch, selected like the faces around it
  EXPECT_GT(faces_where(r.soup, true).size(), faces_where(bunny, true).size());
}

TEST(Selection, DecimateTargetRatioAppliesToTheSelectedFaces) {
  Soup bunny;
  if (!load_bunny(bunny)) GTEST_SKIP() << "bunny.off not present";
  select_left_half(bunny);
  const std::size_t selected = faces_where(bunny, true).size(), unselected = bunny.n_faces() - selected;
  const RunResult r = run("decimate", bunny, {{"target_ratio", "0.25"}});
  const std::size_t target = unselected + std::size_t(std::llround(0.25 * double(selected)));
  EXPECT_EQ(std::get<std::int64_t>(*r.report.find("target_faces")), std::int64_t(target));
  // A collapse removes two triangles (one at a boundary): the target is met or passed by one.
  EXPECT_LE(r.soup.n_faces(), target + 1);
  EXPECT_GE(r.soup.n_faces(), target);
}

TEST(Selection, SmoothMovesOnlyTheSelectedVertices) {
  Soup bunny;
  if (!load_bunny(bunny)) GTEST_SKIP() << "bunny.off not present";
  auto* selected = bunny.add_channel("selected", Domain::vertex, ScalarType::u8, 1).as<std::uint8_t>();
  for (std::size_t v = 0; v < bunny.n_vertices(); ++v) selected[v] = v % 3 == 0;
  const RunResult r = run("smooth", bunny, {{"iterations", "5"}});
  ASSERT_EQ(r.soup.n_vertices(), bunny.n_vertices());
  std::size_t moved = 0;
  for (std::size_t v = 0; v < bunny.n_vertices(); ++v) {
    const bool same = r.soup.positions[v] == bunny.positions[v];
    if (!selected[v]) {
      EXPECT_TRUE(same) << "unselected vertex " << v << " moved";
    }
    moved += !same;
  }
  EXPECT_GT(moved, bunny.n_vertices() / 4);
}

TEST(Selection, NothingSelectedChangesNothingAndSaysSo) {
  Soup bunny;
  if (!load_bunny(bunny)) GTEST_SKIP() << "bunny.off not present";
  Soup quads = quad_bunny(bunny);
  bunny.add_channel("selected", Domain::face, ScalarType::u8, 1);  // all zero
  quads.add_channel("selected", Domain::face, ScalarType::u8, 1);
  for (const Operation* op : with_selection()) {
    const Soup& input = op->id == "make_delaunay" ? bunny : quads;
    SCOPED_TRACE(op->id);
    const RunResult r = run(op->id, input, {});
    EXPECT_EQ(faces_where(r.soup, false), faces_where(input, false));
    EXPECT_EQ(r.soup.n_faces(), input.n_faces());
    EXPECT_NE(std::find(r.report.messages.begin(), r.report.messages.end(),
                        "selection_only: nothing is selected, so the mesh is unchanged"),
              r.report.messages.end());
  }
  // No selection channel at all (a host that selected nothing sends none) is the same.
  Soup plain;
  ASSERT_TRUE(load_bunny(plain));
  const RunResult r = run("decimate", plain, {});
  EXPECT_EQ(r.soup.n_faces(), plain.n_faces());
}

}  // namespace
