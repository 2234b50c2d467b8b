// Private: the operand check of prepare_convex_polyhedron() without its copy of the mesh,
// for make_operand(), which reverses the facets of an inverted mesh itself.
#pragma once

#include <morph/validate.h>

#include <optional>
#include <string_view>

namespace morph::detail {

/// Checks `mesh` exactly as prepare_convex_polyhedron() does (same exceptions, same
/// messages). Returns nothing when `mesh` is an operand as it is, and the flipped copy
/// with its note when it was inverted and options.fix_inverted allowed the fix.
/// Complexity: linear in the mesh (plus a copy only when it is inverted).
std::optional<PreparedMesh> check_operand(const Mesh& mesh, std::string_view name,
                                          const ValidationOptions& options = {});

}  // namespace morph::detail
