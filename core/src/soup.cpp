// Soup helpers and the validity check every front end relies on.
#include "hedge/soup.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>

#include "hedge/error.h"

namespace hedge {

const char* domain_name(Domain domain) {
  switch (domain) {
    case Domain::vertex: return "vertex";
    case Domain::face: return "face";
    case Domain::corner: return "corner";
  }
  return "unknown";
}

Channel Channel::make(std::string name, Domain domain, ScalarType scalar, int components, std::size_t n) {
  Channel c;
  c.name = std::move(name);
  c.domain = domain;
  c.scalar = scalar;
  c.components = components;
  c.data.assign(n * c.stride(), std::byte{0});
  return c;
}

std::size_t Soup::domain_size(Domain domain) const {
  switch (domain) {
    case Domain::vertex: return n_vertices();
    case Domain::face: return n_faces();
    case Domain::corner: return n_corners();
  }
  return 0;
}

void Soup::add_face(std::initializer_list<std::uint32_t> vertices) {
  face_sizes.push_back(static_cast<std::uint32_t>(vertices.size()));
  corners.insert(corners.end(), vertices.begin(), vertices.end());
}

void Soup::add_face(const std::vector<std::uint32_t>& vertices) {
  face_sizes.push_back(static_cast<std::uint32_t>(vertices.size()));
  corners.insert(corners.end(), vertices.begin(), vertices.end());
}

std::vector<std::size_t> Soup::face_offsets() const {
  std::vector<std::size_t> offsets(face_sizes.size() + 1, 0);
  for (std::size_t f = 0; f < face_sizes.size(); ++f) offsets[f + 1] = offsets[f] + face_sizes[f];
  return offsets;
}

Channel* Soup::find(const std::string& name, Domain domain) {
  for (auto& c : channels)
    if (c.name == name && c.domain == domain) return &c;
  return nullptr;
}

const Channel* Soup::find(const std::string& name, Domain domain) const {
  for (const auto& c : channels)
    if (c.name == name && c.domain == domain) return &c;
  return nullptr;
}

Channel& Soup::add_channel(std::string name, Domain domain, ScalarType scalar, int components) {
  if (find(name, domain)) throw Error("soup: " + std::string(domain_name(domain)) + " channel '" + name + "' exists already");
  channels.push_back(Channel::make(std::move(name), domain, scalar, components, domain_size(domain)));
  return channels.back();
}

void Soup::check() const {
  std::size_t total = 0;
  for (std::size_t f = 0; f < face_sizes.size(); ++f) total += face_sizes[f];
  if (total != corners.size())
    throw Error("soup: face sizes add up to " + std::to_string(total) + " corners but there are " +
                std::to_string(corners.size()));
  // Branch-free scans first (build() runs this on every soup); the loops that name the
  // culprit run only when something is wrong.
  bool finite = true;
  for (const Point& p : positions)
    for (int k = 0; k < 3; ++k) {
      std::uint32_t bits;
      std::memcpy(&bits, &p[k], sizeof bits);
      finite &= (bits & 0x7f800000u) != 0x7f800000u;  // exponent all ones: NaN or infinity
    }
  if (!finite)
    for (std::size_t v = 0; v < positions.size(); ++v)
      for (int k = 0; k < 3; ++k)
        if (!std::isfinite(positions[v][k]))
          throw Error("soup: vertex " + std::to_string(v) + " has " +
                      (std::isnan(positions[v][k]) ? "a NaN" : "an infinite") + " coordinate (" + "xyz"[k] + " = " +
                      (std::isnan(positions[v][k]) ? "nan"
                       : positions[v][k] > 0       ? "inf"
                                                   : "-inf") +
                      "); every coordinate must be a finite number");
  std::uint32_t largest = 0;
  for (std::uint32_t c : corners) largest = std::max(largest, c);
  if (!corners.empty() && largest >= positions.size()) {
    std::size_t corner = 0;
    for (std::size_t f = 0; f < face_sizes.size(); ++f)
      for (std::uint32_t k = 0; k < face_sizes[f]; ++k, ++corner)
        if (corners[corner] >= positions.size())
          throw Error("soup: face " + std::to_string(f) + " uses vertex " + std::to_string(corners[corner]) +
                      " but there are only " + std::to_string(positions.size()) + " vertices");
  }
  for (const auto& c : channels) {
    if (c.components < 1 || c.stride() == 0)
      throw Error("soup: channel '" + c.name + "' has " + std::to_string(c.components) + " components");
    if (c.data.size() != domain_size(c.domain) * c.stride())
      throw Error("soup: " + std::string(domain_name(c.domain)) + " channel '" + c.name + "' holds " +
                  std::to_string(c.data.size() / c.stride()) + " elements, expected " + std::to_string(domain_size(c.domain)));
  }
}

}  // namespace hedge
