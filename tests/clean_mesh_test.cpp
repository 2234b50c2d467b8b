// White-box test of the assembly's last step: facets over rounded points to a clean mesh.
#include <doctest/doctest.h>

#include <algorithm>
#include <set>
#include <vector>

#include "fims.h"

namespace {

using morph::detail::clean_mesh;
using morph::detail::V3;

// The unit cube (vertex x + 2y + 4z) with its top split in two along x = 1/2: the
// midpoints 8 = (1/2,0,1) and 9 = (1/2,1,1) are corners of the front and back facets too.
TEST_CASE("clean_mesh merges a split facet and drops the vertices in the middle of edges") {
  std::vector<V3<double>> points;
  for (int v = 0; v < 8; ++v)
    points.push_back({double(v & 1), double((v >> 1) & 1), double(v >> 2)});
  points.push_back({0.5, 0, 1});
  points.push_back({0.5, 1, 1});
  const std::vector<std::vector<int>> facets = {
      {4, 8, 9, 6},     // top, left half
      {0, 1, 5, 8, 4},  // front
      {8, 5, 7, 9},     // top, right half
      {2, 6, 9, 7, 3},  // back
      {0, 2, 3, 1},     // bottom
      {0, 4, 6, 2},     // left
      {1, 3, 7, 5},     // right
  };
  std::vector<int> begin{0}, corners;
  for (const auto& f : facets) {
    corners.insert(corners.end(), f.begin(), f.end());
    begin.push_back(static_cast<int>(corners.size()));
  }
  std::vector<int> source;
  const morph::Mesh mesh = clean_mesh(points, begin, corners, &source);
  CHECK(mesh.n_vertices() == 8);
  REQUIRE(mesh.n_faces() == 6);
  CHECK(mesh.n_edges() == 12);
  CHECK(source.size() == 6);
  // Each face a quad on one face plane of the cube, every one once; no boundary.
  std::set<int> planes;
  for (auto f : mesh.faces()) {
    CHECK(mesh.valence(f) == 4);
    for (int axis = 0; axis < 3; ++axis)
      for (int side = 0; side < 2; ++side) {
        bool on = true;
        for (auto v : mesh.fv_range(f)) on = on && mesh.point(v)[axis] == side;
        if (on) planes.insert(2 * axis + side);
      }
  }
  CHECK(planes.size() == 6);
  for (auto h : mesh.halfedges()) CHECK_FALSE(mesh.is_boundary(h));
  // The top comes from its larger half; equal areas: the first.
  CHECK(std::count(source.begin(), source.end(), 0) == 1);
  CHECK(std::count(source.begin(), source.end(), 2) == 0);
}

}  // namespace
