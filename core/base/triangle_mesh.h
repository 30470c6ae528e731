// A triangle mesh as the Blender bridge writes it (the `mesh` pass, docs/file_formats.md) and
// the ray tracer reads it: shared vertices and indexed triangles, no normals (AO needs none:
// both sides of a triangle occlude).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace aolab {

struct TriangleMesh {
  std::vector<float> vertices;           ///< 3 floats per vertex: x, y, z
  std::vector<std::uint32_t> triangles;  ///< 3 vertex indices per triangle
  std::size_t vertex_count() const { return vertices.size() / 3; }
  std::size_t triangle_count() const { return triangles.size() / 3; }
};

}  // namespace aolab
