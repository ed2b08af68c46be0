// Shared checks of the fuzz targets: build a soup, validate, and compare extract() with
// what the soup should come back as (skipped faces removed, channels grouped by domain);
// count the defects extract()'s weld may not add (docs/architecture.md, "No mesh comes back
// worse") with the test suite's counter, which shares no code with the mesh.
#pragma once
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <string_view>
#include <vector>

#include "../core/defect_counts.h"
#include "hedge/build.h"
#include "hedge/error.h"
#include "hedge/soup.h"
#include "hedge/threads.h"
#include "hedge/validate.h"
#include "parallel.h"

namespace hedge_fuzz {

[[noreturn]] inline void fail(const std::string& what) {
  std::fprintf(stderr, "FUZZ INVARIANT BROKEN: %s\n", what.c_str());
  std::fflush(stderr);
  std::abort();
}

//! The soup extract(build(soup)) must give back: faces build() skipped removed (with their
//! face and corner channel entries), channels stably grouped vertex, face, corner.
inline hedge::Soup expected_round_trip(const hedge::Soup& soup, const std::vector<std::uint32_t>& skipped) {
  hedge::Soup out;
  out.positions = soup.positions;
  std::vector<bool> skip(soup.n_faces(), false);
  for (auto f : skipped) skip.at(f) = true;
  auto offsets = soup.face_offsets();
  std::vector<bool> keep_corner(soup.n_corners(), true);
  for (std::size_t f = 0; f < soup.n_faces(); ++f) {
    if (skip[f]) {
      for (std::size_t c = offsets[f]; c < offsets[f + 1]; ++c) keep_corner[c] = false;
      continue;
    }
    out.face_sizes.push_back(soup.face_sizes[f]);
    for (std::size_t c = offsets[f]; c < offsets[f + 1]; ++c) out.corners.push_back(soup.corners[c]);
  }
  for (hedge::Domain d : {hedge::Domain::vertex, hedge::Domain::face, hedge::Domain::corner}) {
    for (const auto& ch : soup.channels) {
      if (ch.domain != d) continue;
      hedge::Channel c = ch;
      if (d != hedge::Domain::vertex) {
        c.data.clear();
        std::size_t stride = ch.stride();
        std::size_t n = ch.count();
        for (std::size_t i = 0; i < n; ++i) {
          bool keep = d == hedge::Domain::face ? !skip[i] : keep_corner[i];
          if (keep) c.data.insert(c.data.end(), ch.data.begin() + i * stride, ch.data.begin() + (i + 1) * stride);
        }
      }
      out.channels.push_back(std::move(c));
    }
  }
  return out;
}

inline std::string describe_difference(const hedge::Soup& a, const hedge::Soup& b) {
  if (a.positions.size() != b.positions.size())
    return "vertex count " + std::to_string(a.positions.size()) + " vs " + std::to_string(b.positions.size());
  for (std::size_t i = 0; i < a.positions.size(); ++i)
    if (std::memcmp(&a.positions[i], &b.positions[i], sizeof(a.positions[i])) != 0)
      return "position of vertex " + std::to_string(i);
  if (a.face_sizes != b.face_sizes)
    return "face sizes (" + std::to_string(a.face_sizes.size()) + " vs " + std::to_string(b.face_sizes.size()) +
           " faces)";
  if (a.corners != b.corners) return "corner indices";
  if (a.channels.size() != b.channels.size())
    return "channel count " + std::to_string(a.channels.size()) + " vs " + std::to_string(b.channels.size());
  for (std::size_t i = 0; i < a.channels.size(); ++i)
    if (!(a.channels[i] == b.channels[i])) return "channel " + std::to_string(i) + " '" + a.channels[i].name + "'";
  return "";
}

//! Bitwise soup equality (operator== on float positions treats NaN as unequal and -0 == 0).
inline bool same_bits(const hedge::Soup& a, const hedge::Soup& b) { return describe_difference(a, b).empty(); }

//! Given the soup build() was given and no change since, extract() has nothing to keep apart:
//! the same soup comes back as without it (`expected`: expected_round_trip()).
inline void check_extract_with_input(const hedge::BuildResult& built, const hedge::Soup& soup,
                                     const hedge::Soup& expected) {
  hedge::ExtractOptions options;
  options.input = &soup;
  hedge::ExtractReport report;
  hedge::Soup back;
  try {
    back = hedge::extract(built.mesh, options, &report);
  } catch (const hedge::Error& e) {
    fail(std::string("extract(input) threw: ") + e.what());
  }
  std::string diff = describe_difference(back, expected);
  if (!diff.empty())
    fail("extract(build(soup), input = soup) differs from the soup: " + diff + " (" +
         std::to_string(report.copies_kept_apart) + " copies kept apart)");
}

//! build() -> validate() -> extract() round trip. hedge::Error from build() is an answer,
//! not a bug; everything else aborts with a message. `with_input`: extract() given the soup
//! must give it back too.
inline void check_build_round_trip(const hedge::Soup& soup, bool with_input = false) {
  hedge::BuildResult built;
  try {
    built = hedge::build(soup);
  } catch (const hedge::Error&) {
    return;
  }
  hedge::Validation v = hedge::validate(built.mesh);
  if (!v) fail("validate after build: " + v.message);
  if (built.report.skipped_faces != built.maps.skipped_faces.size()) fail("skipped_faces count and map disagree");
  if (built.mesh.n_faces() != soup.n_faces() - built.maps.skipped_faces.size())
    fail("face count " + std::to_string(built.mesh.n_faces()) + " != soup faces " + std::to_string(soup.n_faces()) +
         " - skipped " + std::to_string(built.maps.skipped_faces.size()));
  hedge::Soup back;
  try {
    back = hedge::extract(built.mesh);
  } catch (const hedge::Error& e) {
    fail(std::string("extract threw: ") + e.what());
  }
  hedge::Soup expected = expected_round_trip(soup, built.maps.skipped_faces);
  std::string diff = describe_difference(back, expected);
  if (!diff.empty()) fail("extract(build(soup)) differs from the soup: " + diff);
  if (with_input) check_extract_with_input(built, soup, expected);
}

//! Reads `bytes` with `read` whole, then in runs of a few bytes on two threads (the text readers
//! cut big files into runs read side by side): the same soup, or the same error, must come back;
//! then what was read must build and round-trip.
template <class Read>
void check_reader(std::string_view bytes, Read read) {
  struct Result {
    hedge::Soup soup;
    std::string error;
    bool failed = false;
  };
  auto attempt = [&] {
    Result r;
    try {
      r.soup = read(bytes);
    } catch (const hedge::Error& e) {
      r.failed = true;
      r.error = e.what();
    }
    return r;
  };
  const Result whole = attempt();
  const std::size_t run_bytes = 1 + bytes.size() % 7;
  hedge::set_thread_count(2);
  hedge::testing::set_parallel_grain(run_bytes);
  const Result in_runs = attempt();
  hedge::set_thread_count(0);
  hedge::testing::set_parallel_grain(0);
  if (whole.failed != in_runs.failed || whole.error != in_runs.error || !(whole.soup == in_runs.soup))
    fail("read in runs of " + std::to_string(run_bytes) + " bytes differs from the whole file: '" +
         (whole.failed ? whole.error : "a soup") + "' against '" + (in_runs.failed ? in_runs.error : "a soup") + "'");
  if (!whole.failed) check_build_round_trip(whole.soup);
}

inline std::string describe(const hedge::test::DefectCounts& d) {
  return std::to_string(d.non_manifold_edges) + " non-manifold edges, " + std::to_string(d.non_manifold_vertices) +
         " non-manifold vertices, " + std::to_string(d.duplicate_faces) + " duplicate faces, " +
         std::to_string(d.repeating_faces) + " faces repeating a vertex";
}

}  // namespace hedge_fuzz
