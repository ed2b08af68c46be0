// selection_only: what a host's selection lets an operation change. build() carries the
// selection as the "selected" channels of faces and vertices (soup.h: u8, non-zero means
// selected); operations read it here, once, as flags per element index. Also here: the
// per-vertex values a user names by attribute (weights, locks), read the same way.
//
// The contract every operation with selection_only keeps: a face that is not selected comes
// back as it was (same corners, same positions), so the border between selected and
// unselected faces stays where it is and stays watertight.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "hedge/mesh.h"

namespace hedge::detail {

//! Per face index: 1 when the face is selected. All zero when the mesh has no face selection.
std::vector<std::uint8_t> selected_faces(const Mesh& mesh);

//! Per vertex index: 1 when the vertex is selected, from the vertex selection when the host
//! gave one; else (hosts that only select faces) when it is inside the face selection, so
//! that the border stays.
std::vector<std::uint8_t> selected_vertices(const Mesh& mesh);

//! Per vertex index: 1 when every face around the vertex is selected (isolated vertices and
//! copies of one host vertex: 0). Only such vertices may move or go when faces change around
//! them; the others hold the border.
std::vector<std::uint8_t> inside_selection(const Mesh& mesh, const std::vector<std::uint8_t>& faces);

//! Whether the host selected any face or vertex.
bool has_selection(const Mesh& mesh);

//! Per vertex index: the value of the one-component vertex channel `name` (any scalar type),
//! for parameters of type vertex_channel. Throws Error naming `what` (e.g. "decimate:
//! weight_attribute") and the mesh's vertex attributes when there is no such channel, or
//! when it holds more than one number per vertex.
std::vector<double> vertex_values(const Mesh& mesh, const std::string& name, const std::string& what);

//! The message a run with selection_only gives when nothing is selected.
inline constexpr const char* kNothingSelected = "selection_only: nothing is selected, so the mesh is unchanged";

}  // namespace hedge::detail
