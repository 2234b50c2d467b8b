// The mesh type of libmorph: OpenMesh's polygon mesh with double coordinates.
//
// Facets are kept as polygons (never triangulated behind the caller's back). Every
// libmorph function takes meshes by const reference and returns new ones.
#pragma once

#include <OpenMesh/Core/Mesh/PolyMesh_ArrayKernelT.hh>

namespace morph {

/// OpenMesh traits with double-precision points and normals, and the status
/// attributes needed to delete elements.
struct MeshTraits : public OpenMesh::DefaultTraits {
  using Point = OpenMesh::Vec3d;
  using Normal = OpenMesh::Vec3d;
  VertexAttributes(OpenMesh::Attributes::Status);
  FaceAttributes(OpenMesh::Attributes::Status);
  EdgeAttributes(OpenMesh::Attributes::Status);
};

/// A polygon mesh with double coordinates.
using Mesh = OpenMesh::PolyMesh_ArrayKernelT<MeshTraits>;
using Point = Mesh::Point;

}  // namespace morph
