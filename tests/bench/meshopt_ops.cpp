// meshoptimizer's side of hedge_bench --ops (Debian's 0.18): meshopt_simplify and, as the lower
// bound of time, meshopt_simplifySloppy, on the soup's positions and a 32-bit triangle index buffer.
#include <meshoptimizer.h>

#include <cmath>
#include <cstdint>
#include <memory>
#include <vector>

#include "bench.h"

namespace bench {

namespace {

static_assert(sizeof(hedge::Point) == 3 * sizeof(float), "meshoptimizer reads positions as packed float3");

//! meshoptimizer's input and output: it reads the soup's positions in place and writes a new
//! index buffer that still refers to them.
struct IndexedMesh {
  const hedge::Point* positions = nullptr;
  std::size_t vertex_count = 0;
  std::vector<unsigned int> indices;
  std::vector<unsigned int> result;
};

//! The soup as triangles (polygons fanned; faces that repeat a vertex left out, as for the peers).
std::unique_ptr<IndexedMesh> build_mesh() {
  const hedge::Soup& soup = input().soup;
  auto mesh = std::make_unique<IndexedMesh>();
  mesh->positions = soup.positions.data();
  mesh->vertex_count = soup.n_vertices();
  mesh->indices.reserve(soup.corners.size());
  std::size_t offset = 0;
  const std::uint32_t* c = soup.corners.data();
  for (std::uint32_t n : soup.face_sizes) {
    if (!repeats_vertex(c + offset, n))
      for (std::uint32_t i = 2; i < n; ++i)
        mesh->indices.insert(mesh->indices.end(), {c[offset], c[offset + i - 1], c[offset + i]});
    offset += n;
  }
  // The worst case of the output is the input's index count (not the target); allocated here,
  // outside the time, as the peers' meshes are.
  mesh->result.resize(mesh->indices.size());
  return mesh;
}

//! The result as a soup of only the vertices its triangles use: meshoptimizer leaves the others
//! in the buffer, and they must not count as part of the surface in the distance measurement.
hedge::Soup to_soup(const IndexedMesh& mesh) {
  constexpr std::uint32_t kUnused = ~std::uint32_t{0};
  std::vector<std::uint32_t> compact(mesh.vertex_count, kUnused);
  hedge::Soup soup;
  soup.corners.reserve(mesh.result.size());
  for (unsigned int v : mesh.result) {
    if (compact[v] == kUnused) {
      compact[v] = static_cast<std::uint32_t>(soup.positions.size());
      soup.positions.push_back(mesh.positions[v]);
    }
    soup.corners.push_back(compact[v]);
  }
  soup.face_sizes.assign(mesh.result.size() / 3, 3);
  return soup;
}

// Relative to the mesh's extent: 1 would allow moving the surface by its whole size, so the
// index count, not the error, is what stops both simplifiers on any real mesh.
constexpr float kTargetError = 1.0f;

std::size_t target_index_count(const IndexedMesh& mesh) {
  const double triangles = static_cast<double>(mesh.indices.size() / 3);
  return 3 * static_cast<std::size_t>(std::llround(kDecimateRatio * triangles));
}

template <bool sloppy>
OpRun decimate_run(double) {
  return time_operation(
      build_mesh,
      [](IndexedMesh& mesh) {
        const float* positions = mesh.positions->data.data();
        const std::size_t count =
            sloppy ? meshopt_simplifySloppy(mesh.result.data(), mesh.indices.data(), mesh.indices.size(), positions,
                                            mesh.vertex_count, sizeof(hedge::Point), target_index_count(mesh),
                                            kTargetError)
                   : meshopt_simplify(mesh.result.data(), mesh.indices.data(), mesh.indices.size(), positions,
                                      mesh.vertex_count, sizeof(hedge::Point), target_index_count(mesh), kTargetError);
        mesh.result.resize(count);
      },
      to_soup);
}

}  // namespace

std::vector<OpEntry> meshopt_simplify_operations() {
  return {{kOpDecimate, "meshopt_simplify alone (target_error 1, options 0); index and output buffers made beforehand",
           decimate_run<false>}};
}

std::vector<OpEntry> meshopt_sloppy_operations() {
  return {{kOpDecimate, "meshopt_simplifySloppy alone (target_error 1); index and output buffers made beforehand",
           decimate_run<true>}};
}

}  // namespace bench
