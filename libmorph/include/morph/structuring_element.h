// Structuring elements: parametric convex solids centred on the origin, or any convex
// mesh file, from one compact spec shared by every app and pipeline.
//
// Spec grammar (one place, see docs/cli.md):
//   sphere:r=R[,level=L]        icosphere (geodesic, 20*4^L triangles), default level 2
//   uvsphere:r=R[,n=N]          UV sphere, N longitudes x N latitudes (2N triangles + N(N-2) quads)
//   cube:S                      axis-aligned cube of edge S
//   box:X,Y,Z                   axis-aligned box of edges X, Y, Z
//   tetrahedron:R  octahedron:R  icosahedron:R  dodecahedron:R   platonic solids, circumradius R
//   cylinder:r=R,h=H[,n=N]      prism with an N-gon cross-section (default 16), axis z
//   a path to a mesh file       any convex mesh (.off .obj .ply .stl), used as it is
// Positional values may also be named (cube:s=0.2, box:x=1,y=2,z=3). A bad spec throws
// input_error listing the valid forms.
#pragma once

#include <morph/mesh.h>

#include <string>
#include <string_view>

namespace morph {

/// Text listing the valid spec forms (used in error messages and --help).
std::string structuring_element_grammar();

/// Builds a structuring element from a spec; a spec that names an existing file
/// (or contains a path separator or a mesh extension) is read with read_mesh.
/// Throws input_error for a bad spec, io_error/input_error for a bad file.
Mesh make_structuring_element(std::string_view spec);

/// Generators, all centred on the origin with outward-oriented faces; linear in their
/// output size. Non-positive or non-finite sizes throw input_error.
Mesh make_icosphere(double radius, int level);  // 20*4^level triangles
Mesh make_uv_sphere(double radius, int n);      // n >= 3
Mesh make_box(double x, double y, double z);    // 6 quads
Mesh make_tetrahedron(double radius);
Mesh make_octahedron(double radius);
Mesh make_icosahedron(double radius);
Mesh make_dodecahedron(double radius);                    // 12 pentagons
Mesh make_cylinder(double radius, double height, int n);  // n-gon prism
Mesh make_snub_dodecahedron(double radius);               // 80 triangles + 12 pentagons

}  // namespace morph
