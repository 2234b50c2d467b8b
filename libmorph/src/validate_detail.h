// Private: the operand check of prepare_convex_polyhedron() without its copy of the mesh,
// for make_operand(), which reverses the facets of an inverted mesh itself.
#pragma once

#include <morph/error.h>
#include <morph/validate.h>

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>

namespace morph::detail {

/// A mesh's connectivity read as plain int arrays, for the passes that walk every
/// halfedge: OpenMesh keeps each halfedge as four handles (face, target vertex, next,
/// previous; the two of edge e at 2e and 2e + 1), each vertex and face as one halfedge
/// handle, and indexing them here saves the handle arithmetic of each accessor call.
/// Read only while the mesh is not changed.
struct HalfedgeArrays {
  explicit HalfedgeArrays(const Mesh& mesh) {
    static_assert(sizeof(Mesh::Halfedge) == 4 * sizeof(int) &&
                      sizeof(Mesh::Edge) == 2 * sizeof(Mesh::Halfedge) &&
                      sizeof(Mesh::Vertex) == sizeof(int) && sizeof(Mesh::Face) == sizeof(int),
                  "OpenMesh's array items are not plain handles");
    if (mesh.n_halfedges() > 0) {
      halfedge = reinterpret_cast<const int*>(&mesh.halfedge(Mesh::HalfedgeHandle(0)));
      // The field order is fixed by OpenMesh's ArrayItems; checked on the first and the
      // last halfedge (one could hold equal values in two fields by chance).
      for (const int i : {0, static_cast<int>(mesh.n_halfedges()) - 1}) {
        const Mesh::HalfedgeHandle h(i);
        if (face(i) != mesh.face_handle(h).idx() || to(i) != mesh.to_vertex_handle(h).idx() ||
            next(i) != mesh.next_halfedge_handle(h).idx() ||
            prev(i) != mesh.prev_halfedge_handle(h).idx())
          throw error("internal error: unexpected layout of OpenMesh's halfedges");
      }
    }
    if (mesh.n_vertices() > 0)
      vertex_halfedge = reinterpret_cast<const int*>(&mesh.vertex(Mesh::VertexHandle(0)));
    if (mesh.n_faces() > 0)
      face_halfedge = reinterpret_cast<const int*>(&mesh.face(Mesh::FaceHandle(0)));
  }
  // The record's offset in 64 bits (one sign extension of h, not one of each 4 h + k).
  const int* record(int h) const { return halfedge + 4 * static_cast<std::ptrdiff_t>(h); }
  int face(int h) const { return record(h)[0]; }
  int to(int h) const { return record(h)[1]; }
  int next(int h) const { return record(h)[2]; }
  int prev(int h) const { return record(h)[3]; }
  int from(int h) const { return to(h ^ 1); }
  int halfedge_of_vertex(int v) const { return vertex_halfedge[v]; }
  int halfedge_of_face(int f) const { return face_halfedge[f]; }

  const int* halfedge = nullptr;
  const int* vertex_halfedge = nullptr;
  const int* face_halfedge = nullptr;
};

/// Checks `mesh` exactly as prepare_convex_polyhedron() does (same exceptions, same
/// messages). Returns nothing when `mesh` is an operand as it is, and the flipped copy
/// with its note when it was inverted and options.fix_inverted allowed the fix.
/// Complexity: linear in the mesh (plus a copy only when it is inverted).
std::optional<PreparedMesh> check_operand(const Mesh& mesh, std::string_view name,
                                          const ValidationOptions& options = {});

/// A mesh's face cycles as check_operand reads them: corner k of face f is vertex
/// vertex[begin[f] + k], counted from the target of the face's halfedge along its next
/// links, and across[begin[f] + k] is the face across the edge that ends at that corner
/// (begin has F + 1 entries).
struct FaceCycleView {
  const int* begin;
  const int* vertex;
  const int* across;
};

/// Whether check_operand(mesh) (with this tolerance) returns nothing: the mesh is an operand
/// as it is. Only for a mesh without deleted elements, with every coordinate finite, that the
/// caller has found to pass check_operand's topological checks (closed, every vertex one fan
/// reaching each neighbour once, connected, Euler characteristic 2), with its face cycles: runs the
/// geometric checks alone, on the same values with the same verdicts. False when check_operand
/// would throw or flip the mesh (its caller then calls it, for the message). Linear in the mesh.
bool geometry_passes(const Mesh& mesh, const FaceCycleView& cycles,
                     double planarity_tolerance = kPlanarityTolerance);

struct UnitNormal;  // polytope.h

/// geometry_passes(mesh, cycles) (the default tolerance) that also, when it returns true, fills
/// unit_normals[f] (F entries) with face f's unit normal and a bound on its distance to the
/// direction of the face's exact Newell normal (centroid_unit_normal() of the plane the checks
/// computed anyway): the values Polytope::compute_normals() gives a facet with this cycle.
/// `complete` is false when some face's Newell sum is out of that function's range (then the
/// caller computes them all itself). `edges_convex` is true when, moreover, every face is a
/// triangle and every edge is proven strictly convex (the far corner of each triangle across
/// lies strictly below the exact plane of the face, told from the heights the reflex test
/// computes): then so is every edge of the polytope with these facets.
/// `box`, when given: the mesh's bounding box, lo and hi minimised and maximised (Point's
/// minimize, maximize) over the vertices in index order from +-infinity, as the checks would
/// compute it (then they do not read the points again for it). The mesh has a vertex.
struct PointBox {
  Point lo, hi;
};
bool geometry_passes(const Mesh& mesh, const FaceCycleView& cycles, UnitNormal* unit_normals,
                     bool& complete, bool& edges_convex, const PointBox* box = nullptr);

/// geometry_passes(mesh, cycles) on the face cycles read here from the mesh (check_operand's),
/// for a caller that checks beside the halfedge walks that would give them: the same verdict
/// whenever the mesh passes check_operand's topological checks. Only for a mesh without deleted
/// elements, with every coordinate finite; any other may be passed (a face that is not a
/// closed cycle or an open edge gives false), the verdict then being meaningless.
bool geometry_passes(const Mesh& mesh, double planarity_tolerance = kPlanarityTolerance);

/// check_convex_polyhedron(mesh).problem with this tolerance, with or without the unrolled
/// paths of triangles and quadrilaterals (`shortcuts`): for tests, which check that both give
/// the same verdicts and messages.
std::string convex_polyhedron_problem(const Mesh& mesh, double planarity_tolerance, bool shortcuts);

}  // namespace morph::detail
