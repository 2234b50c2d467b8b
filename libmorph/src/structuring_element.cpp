// Structuring elements: the parametric convex solids of structuring_element.h and the
// spec parser that picks one (or reads a mesh file).
//
// Solids whose faces follow from a formula (box, cylinder, UV sphere, icosphere
// subdivision) are built face by face. Solids given by their vertices (the platonic
// solids, the snub dodecahedron) take their faces from the convex hull of the vertices,
// with the hull's coplanar triangles merged back into polygons.
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/convex_hull_3.h>
#include <morph/error.h>
#include <morph/io.h>
#include <morph/structuring_element.h>
#include <morph/validate.h>

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <map>
#include <numbers>
#include <numeric>
#include <optional>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

namespace morph {
namespace {

// Limits on the parameters: beyond them a spec is a mistake, not a structuring element.
constexpr int kMaxIcosphereLevel = 7;   // 327,680 triangles
constexpr int kMinSides = 3;            // fewest sides of a polygon
constexpr int kMaxSides = 4096;         // n of a cylinder (n + 2 faces)
constexpr int kMaxUvSphereSides = 512;  // n of a uvsphere: n^2 faces, 262,144 at most (as level 7)
// Radii, edges: cubes of these stay finite in double, and squared facet areas (~extent^4,
// as validation computes them) stay above underflow: at 1e-100 every facet had zero area.
constexpr double kMinExtent = 1e-50;
constexpr double kMaxExtent = 1e50;  // element sizes stay well inside kMaxSize (morph/validate.h)

// Two hull triangles are one face when each lies within this fraction of the
// circumdiameter of the other's plane: vertices given by irrational formulas (a
// dodecahedron's pentagons) are coplanar only up to rounding, ~1e-16; distinct faces of
// the solids built here are far more than this apart.
constexpr double kCoplanarMergeTolerance = 1e-12;

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using HullMesh = CGAL::Surface_mesh<Kernel::Point_3>;

void require_extent(double value, const char* what) {
  if (!(std::isfinite(value) && value >= kMinExtent && value <= kMaxExtent))
    throw input_error(std::string(what) +
                      " must be a positive finite number between 1e-50 and 1e50, got " +
                      std::to_string(value));
}

void require_count(int value, int lo, int hi, const char* what) {
  if (value < lo || value > hi)
    throw input_error(std::string(what) + " must be an integer in " + std::to_string(lo) + ".." +
                      std::to_string(hi) + ", got " + std::to_string(value));
}

// The mesh of polygons given as index loops into `points`, each oriented outwards from
// the origin (reversed if its Newell normal points towards the origin).
Mesh mesh_from_polygons(const std::vector<Point>& points,
                        const std::vector<std::vector<int>>& polygons) {
  Mesh mesh;
  std::vector<Mesh::VertexHandle> handles;
  handles.reserve(points.size());
  for (const auto& p : points) handles.push_back(mesh.add_vertex(p));
  std::vector<Mesh::VertexHandle> face;
  for (const auto& polygon : polygons) {
    Point centroid(0, 0, 0), normal(0, 0, 0);
    for (int i : polygon) centroid += points[i];
    centroid /= static_cast<double>(polygon.size());
    for (std::size_t i = 0; i < polygon.size(); ++i)
      normal += OpenMesh::cross(points[polygon[i]] - centroid,
                                points[polygon[(i + 1) % polygon.size()]] - centroid);
    face.clear();
    for (int i : polygon) face.push_back(handles[i]);
    if (OpenMesh::dot(normal, centroid) < 0) std::reverse(face.begin(), face.end());
    mesh.add_face(face);
  }
  return mesh;
}

// The faces of the convex hull of `points` (in general position up to coplanar faces),
// as outward index loops, coplanar hull triangles merged into one polygon.
std::vector<std::vector<int>> hull_polygons(const std::vector<Point>& points) {
  std::vector<Kernel::Point_3> input;
  for (const auto& p : points) input.emplace_back(p[0], p[1], p[2]);
  HullMesh hull;
  CGAL::convex_hull_3(input.begin(), input.end(), hull);

  // Hull vertices back to input indices (the hull copies the points exactly).
  std::map<std::array<double, 3>, int> index;
  for (std::size_t i = 0; i < points.size(); ++i)
    index.emplace(std::array<double, 3>{points[i][0], points[i][1], points[i][2]},
                  static_cast<int>(i));
  const auto id = [&](HullMesh::Vertex_index v) {
    const auto& p = hull.point(v);
    return index.at({p.x(), p.y(), p.z()});
  };
  const auto point = [&](HullMesh::Vertex_index v) { return points[id(v)]; };

  double diameter = 0;
  for (const auto& p : points) diameter = std::max(diameter, 2 * p.norm());
  const double tolerance = kCoplanarMergeTolerance * diameter;

  // Merge the two triangles of an edge when the far corner of each is on the other's plane.
  std::vector<int> group(hull.number_of_faces());
  std::iota(group.begin(), group.end(), 0);
  const auto find = [&](int x) {
    while (group[x] != x) x = group[x] = group[group[x]];
    return x;
  };
  const auto far_corner_height = [&](HullMesh::Halfedge_index h) {
    // height of the corner of face(opposite(h)) not on the edge, above the plane of face(h)
    const Point a = point(hull.source(h)), b = point(hull.target(h));
    const Point c = point(hull.target(hull.next(h)));
    Point normal = OpenMesh::cross(b - a, c - a);
    normal.normalize();
    const Point d = point(hull.target(hull.next(hull.opposite(h))));
    return std::abs(OpenMesh::dot(d - a, normal));
  };
  for (auto e : hull.edges()) {
    const auto h = hull.halfedge(e);
    if (far_corner_height(h) <= tolerance && far_corner_height(hull.opposite(h)) <= tolerance)
      group[find(static_cast<int>(hull.face(h)))] =
          find(static_cast<int>(hull.face(hull.opposite(h))));
  }

  // Each group's boundary, walked along its halfedges (outward, as the hull's).
  std::map<int, std::map<int, HullMesh::Halfedge_index>> boundary;  // group -> source -> halfedge
  for (auto h : hull.halfedges()) {
    const int g = find(static_cast<int>(hull.face(h)));
    if (g != find(static_cast<int>(hull.face(hull.opposite(h)))))
      boundary[g].emplace(static_cast<int>(hull.source(h)), h);
  }
  std::vector<std::vector<int>> polygons;
  for (auto& [g, out] : boundary) {
    std::vector<int> polygon;
    auto h = out.begin()->second;
    for (std::size_t steps = 0; steps <= out.size(); ++steps) {
      polygon.push_back(id(hull.source(h)));
      h = out.at(static_cast<int>(hull.target(h)));
      if (h == out.begin()->second) break;
    }
    // CGAL may shuffle its input: put each loop's smallest index first and sort the
    // loops, so that the faces (and the icosphere built on them) are reproducible.
    std::rotate(polygon.begin(), std::min_element(polygon.begin(), polygon.end()), polygon.end());
    polygons.push_back(std::move(polygon));
  }
  std::sort(polygons.begin(), polygons.end());
  return polygons;
}

Mesh hull_mesh(const std::vector<Point>& points) {
  return mesh_from_polygons(points, hull_polygons(points));
}

std::vector<Point> scaled_to_radius(std::vector<Point> points, double radius) {
  for (auto& p : points) p *= radius / p.norm();
  return points;
}

constexpr double kPhi = std::numbers::phi;

std::vector<Point> icosahedron_points() {
  std::vector<Point> points;
  for (double s : {-1.0, 1.0})
    for (double t : {-1.0, 1.0}) {
      points.emplace_back(0, s, t * kPhi);
      points.emplace_back(s, t * kPhi, 0);
      points.emplace_back(t * kPhi, 0, s);
    }
  return points;
}

// ---------------------------------------------------------------- spec parsing

std::string trim(std::string_view text) {
  const auto first = text.find_first_not_of(" \t");
  if (first == std::string_view::npos) return {};
  const auto last = text.find_last_not_of(" \t");
  return std::string(text.substr(first, last - first + 1));
}

std::string lower(std::string text) {
  for (auto& c : text) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return text;
}

[[noreturn]] void bad_spec(std::string_view spec, const std::string& why) {
  throw input_error("bad structuring element \"" + std::string(spec) + "\": " + why +
                    "\nvalid forms:\n" + structuring_element_grammar());
}

struct Parameter {
  const char* name;
  std::optional<double> fallback;  // none: required
  bool integer = false;
};

// The values of `parameters` given in `arguments` ("0.5,level=3"): positional values
// first, in order, then named ones, each at most once.
std::vector<double> parse_arguments(std::string_view spec, std::string_view arguments,
                                    const std::vector<Parameter>& parameters) {
  std::vector<std::optional<double>> values(parameters.size());
  bool named_seen = false;
  std::size_t position = 0;
  std::size_t start = 0;
  while (start <= arguments.size() && !trim(arguments).empty()) {
    const auto comma = std::min(arguments.find(',', start), arguments.size());
    const std::string item = trim(arguments.substr(start, comma - start));
    start = comma + 1;
    if (item.empty()) bad_spec(spec, "empty value");
    std::size_t slot = 0;
    std::string text;
    if (const auto equals = item.find('='); equals != std::string::npos) {
      const std::string name = lower(trim(item.substr(0, equals)));
      text = trim(item.substr(equals + 1));
      const auto found = std::find_if(parameters.begin(), parameters.end(),
                                      [&](const Parameter& p) { return name == p.name; });
      if (found == parameters.end()) bad_spec(spec, "unknown parameter \"" + name + "\"");
      slot = static_cast<std::size_t>(found - parameters.begin());
      named_seen = true;
    } else {
      if (named_seen) bad_spec(spec, "a positional value after a named one");
      if (position >= parameters.size()) bad_spec(spec, "too many values");
      slot = position++;
      text = item;
    }
    if (values[slot]) bad_spec(spec, std::string("\"") + parameters[slot].name + "\" given twice");
    double value = 0;
    const char* end = text.data() + text.size();
    std::from_chars_result result;
    if (parameters[slot].integer) {
      int integer = 0;
      result = std::from_chars(text.data(), end, integer);
      value = integer;
    } else {
      result = std::from_chars(text.data(), end, value);
    }
    if (text.empty() || result.ec != std::errc() || result.ptr != end)
      bad_spec(spec, std::string("\"") + parameters[slot].name + "\" is not " +
                         (parameters[slot].integer ? "an integer" : "a number") + ": \"" + text +
                         "\"");
    values[slot] = value;
  }
  std::vector<double> out;
  for (std::size_t i = 0; i < parameters.size(); ++i) {
    if (!values[i] && !parameters[i].fallback)
      bad_spec(spec, std::string("missing \"") + parameters[i].name + "\"");
    out.push_back(values[i] ? *values[i] : *parameters[i].fallback);
  }
  return out;
}

bool names_a_file(std::string_view spec) {
  if (spec.find('/') != std::string_view::npos || spec.find('\\') != std::string_view::npos)
    return true;
  std::error_code error;
  const std::filesystem::path path{std::string(spec)};
  if (std::filesystem::is_regular_file(path, error)) return true;
  const std::string extension = lower(path.extension().string());
  return extension == ".off" || extension == ".obj" || extension == ".ply" || extension == ".stl";
}

}  // namespace

std::string structuring_element_grammar() {
  return "  sphere:r=R[,level=L]     icosphere (geodesic, 20*4^L triangles), L in 0..7, default 2\n"
         "  uvsphere:r=R[,n=N]       UV sphere, N longitudes x N latitudes, N in 3..512, default "
         "40\n"
         "  cube:S                   axis-aligned cube of edge S\n"
         "  box:X,Y,Z                axis-aligned box of edges X, Y, Z\n"
         "  tetrahedron:R  octahedron:R  icosahedron:R  dodecahedron:R\n"
         "                           platonic solids of circumradius R\n"
         "  snub_dodecahedron:R      snub dodecahedron of circumradius R\n"
         "  cylinder:r=R,h=H[,n=N]   prism with an N-gon cross-section (N in 3..4096, default 16), "
         "axis z\n"
         "  a path to a mesh file    any convex mesh (.off .obj .ply .stl), used as it is\n"
         "Positional values may also be named (cube:s=0.2, box:x=1,y=2,z=3); lengths are\n"
         "positive finite numbers.\n";
}

Mesh make_structuring_element(std::string_view spec) {
  const std::string text = trim(spec);
  if (text.empty()) bad_spec(spec, "the spec is empty");
  if (names_a_file(text)) {
    const Mesh mesh = read_mesh(std::filesystem::path(text));
    return prepare_convex_polyhedron(mesh, text).mesh;
  }
  const auto colon = text.find(':');
  const std::string kind = lower(trim(text.substr(0, colon)));
  const std::string_view arguments =
      colon == std::string::npos ? std::string_view{} : std::string_view(text).substr(colon + 1);
  const auto values = [&](std::vector<Parameter> parameters) {
    return parse_arguments(spec, arguments, parameters);
  };
  // Parameter errors (a negative radius) are reported with the spec and the grammar.
  const auto build = [&](auto&& make) -> Mesh {
    Mesh mesh = [&] {
      try {
        return make();
      } catch (const input_error& error) {
        bad_spec(spec, error.what());
      }
    }();
    // Each extent is bounded on its own; their ratio can still be beyond what doubles
    // resolve (cylinder:r=1,h=1e30: its caps have no area at the element's scale). Such an
    // element is refused here, as a bad spec, not later as a bad operand.
    if (const CheckResult check = check_convex_polyhedron(mesh); !check.ok())
      bad_spec(spec, "its proportions are too extreme for a valid solid in double precision (" +
                         check.problem + ")");
    return mesh;
  };
  if (kind == "sphere") {
    const auto v = values({{"r", {}}, {"level", 2.0, true}});
    return build([&] { return make_icosphere(v[0], static_cast<int>(v[1])); });
  }
  if (kind == "uvsphere") {
    const auto v = values({{"r", {}}, {"n", 40.0, true}});
    return build([&] { return make_uv_sphere(v[0], static_cast<int>(v[1])); });
  }
  if (kind == "cube") {
    const auto v = values({{"s", {}}});
    return build([&] { return make_box(v[0], v[0], v[0]); });
  }
  if (kind == "box") {
    const auto v = values({{"x", {}}, {"y", {}}, {"z", {}}});
    return build([&] { return make_box(v[0], v[1], v[2]); });
  }
  if (kind == "cylinder") {
    const auto v = values({{"r", {}}, {"h", {}}, {"n", 16.0, true}});
    return build([&] { return make_cylinder(v[0], v[1], static_cast<int>(v[2])); });
  }
  using Maker = Mesh (*)(double);
  static const std::vector<std::pair<std::string, Maker>> by_radius = {
      {"tetrahedron", make_tetrahedron},
      {"octahedron", make_octahedron},
      {"icosahedron", make_icosahedron},
      {"dodecahedron", make_dodecahedron},
      {"snub_dodecahedron", make_snub_dodecahedron}};
  for (const auto& entry : by_radius) {  // not a structured binding: clang 14 cannot capture one
    if (kind != entry.first) continue;
    const Maker make = entry.second;
    const auto v = values({{"r", {}}});
    return build([&] { return make(v[0]); });
  }
  if (colon == std::string::npos) bad_spec(spec, "not a known solid, and no such file");
  bad_spec(spec, "unknown solid \"" + kind + "\"");
}

Mesh make_icosphere(double radius, int level) {
  require_extent(radius, "sphere radius r");
  require_count(level, 0, kMaxIcosphereLevel, "sphere level");
  std::vector<Point> points = icosahedron_points();
  std::vector<std::vector<int>> triangles = hull_polygons(points);
  for (auto& p : points) p /= p.norm();
  // Orient the base triangles outwards once, so that subdivision keeps them outwards.
  for (auto& t : triangles) {
    const Point normal = OpenMesh::cross(points[t[1]] - points[t[0]], points[t[2]] - points[t[0]]);
    if (OpenMesh::dot(normal, points[t[0]]) < 0) std::swap(t[1], t[2]);
  }
  for (int step = 0; step < level; ++step) {
    std::map<std::pair<int, int>, int> midpoints;
    const auto midpoint = [&](int a, int b) {
      const auto key = std::minmax(a, b);
      const auto [it, added] = midpoints.emplace(key, static_cast<int>(points.size()));
      if (added) {
        const Point m = points[a] + points[b];
        points.push_back(m / m.norm());
      }
      return it->second;
    };
    std::vector<std::vector<int>> finer;
    finer.reserve(triangles.size() * 4);
    for (const auto& t : triangles) {
      const int ab = midpoint(t[0], t[1]), bc = midpoint(t[1], t[2]), ca = midpoint(t[2], t[0]);
      finer.push_back({t[0], ab, ca});
      finer.push_back({t[1], bc, ab});
      finer.push_back({t[2], ca, bc});
      finer.push_back({ab, bc, ca});
    }
    triangles = std::move(finer);
  }
  for (auto& p : points) p *= radius;
  return mesh_from_polygons(points, triangles);
}

Mesh make_uv_sphere(double radius, int n) {
  require_extent(radius, "uvsphere radius r");
  require_count(n, kMinSides, kMaxUvSphereSides, "uvsphere n");
  // Latitude i (1..n-1) at polar angle pi*i/n, longitude j at 2*pi*j/n. The sines and
  // cosines are computed once per circle, so each quad is an isosceles trapezoid up to
  // one rounding per coordinate.
  std::vector<double> ring_cos(n), ring_sin(n);
  for (int j = 0; j < n; ++j) {
    const double angle = 2 * std::numbers::pi * j / n;
    ring_cos[j] = std::cos(angle);
    ring_sin[j] = std::sin(angle);
  }
  std::vector<Point> points;
  points.reserve(2 + static_cast<std::size_t>(n - 1) * n);
  points.emplace_back(0, 0, radius);
  for (int i = 1; i < n; ++i) {
    const double polar = std::numbers::pi * i / n;
    const double ring = radius * std::sin(polar), z = radius * std::cos(polar);
    for (int j = 0; j < n; ++j) points.emplace_back(ring * ring_cos[j], ring * ring_sin[j], z);
  }
  points.emplace_back(0, 0, -radius);
  const int south = static_cast<int>(points.size()) - 1;
  const auto at = [n](int i, int j) { return 1 + (i - 1) * n + (j % n); };
  std::vector<std::vector<int>> faces;
  for (int j = 0; j < n; ++j) {
    faces.push_back({0, at(1, j), at(1, j + 1)});
    for (int i = 1; i + 1 < n; ++i)
      faces.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)});
    faces.push_back({south, at(n - 1, j + 1), at(n - 1, j)});
  }
  return mesh_from_polygons(points, faces);
}

Mesh make_box(double x, double y, double z) {
  require_extent(x, "box edge x");
  require_extent(y, "box edge y");
  require_extent(z, "box edge z");
  std::vector<Point> points;
  for (int i = 0; i < 8; ++i)
    points.emplace_back((i & 1 ? 0.5 : -0.5) * x, (i & 2 ? 0.5 : -0.5) * y,
                        (i & 4 ? 0.5 : -0.5) * z);
  // Each face: the corners with one coordinate bit fixed, in cyclic order.
  const std::vector<std::vector<int>> faces = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                                               {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  return mesh_from_polygons(points, faces);
}

Mesh make_tetrahedron(double radius) {
  require_extent(radius, "tetrahedron circumradius");
  return hull_mesh(scaled_to_radius({{1, 1, 1}, {1, -1, -1}, {-1, 1, -1}, {-1, -1, 1}}, radius));
}

Mesh make_octahedron(double radius) {
  require_extent(radius, "octahedron circumradius");
  return hull_mesh({{radius, 0, 0},
                    {-radius, 0, 0},
                    {0, radius, 0},
                    {0, -radius, 0},
                    {0, 0, radius},
                    {0, 0, -radius}});
}

Mesh make_icosahedron(double radius) {
  require_extent(radius, "icosahedron circumradius");
  return hull_mesh(scaled_to_radius(icosahedron_points(), radius));
}

Mesh make_dodecahedron(double radius) {
  require_extent(radius, "dodecahedron circumradius");
  std::vector<Point> points;
  for (double s : {-1.0, 1.0})
    for (double t : {-1.0, 1.0}) {
      for (double u : {-1.0, 1.0}) points.emplace_back(s, t, u);
      points.emplace_back(0, s / kPhi, t * kPhi);
      points.emplace_back(s / kPhi, t * kPhi, 0);
      points.emplace_back(t * kPhi, 0, s / kPhi);
    }
  return hull_mesh(scaled_to_radius(std::move(points), radius));
}

Mesh make_cylinder(double radius, double height, int n) {
  require_extent(radius, "cylinder radius r");
  require_extent(height, "cylinder height h");
  require_count(n, kMinSides, kMaxSides, "cylinder n");
  // Top and bottom rings share their x, y, so the side quads are exactly planar.
  std::vector<Point> points;
  for (double z : {-0.5 * height, 0.5 * height})
    for (int j = 0; j < n; ++j) {
      const double angle = 2 * std::numbers::pi * j / n;
      points.emplace_back(radius * std::cos(angle), radius * std::sin(angle), z);
    }
  std::vector<std::vector<int>> faces(2);
  for (int j = 0; j < n; ++j) {
    faces[0].push_back(j);
    faces[1].push_back(n + j);
    faces.push_back({j, (j + 1) % n, n + (j + 1) % n, n + j});
  }
  return mesh_from_polygons(points, faces);
}

Mesh make_snub_dodecahedron(double radius) {
  require_extent(radius, "snub dodecahedron circumradius");
  // xi: the real root of xi^3 - 2 xi = phi (Newton from above converges monotonically).
  double xi = 2;
  for (int i = 0; i < 100; ++i) {
    const double next = xi - (xi * xi * xi - 2 * xi - kPhi) / (3 * xi * xi - 2);
    if (next == xi) break;
    xi = next;
  }
  const double a = xi - 1 / xi;
  const double b = xi * kPhi + kPhi * kPhi + kPhi / xi;
  const double f = kPhi;
  const std::array<std::array<double, 3>, 5> base = {{
      {2 * a, 2, 2 * b},
      {a + b / f + f, -a * f + b + 1 / f, a / f + b * f - 1},
      {-a / f + b * f + 1, -a + b / f - f, a * f + b - 1 / f},
      {-a / f + b * f - 1, a - b / f - f, a * f + b + 1 / f},
      {a + b / f - f, a * f - b + 1 / f, a / f + b * f + 1},
  }};
  // One chirality: the even (cyclic) permutations with an even number of plus signs.
  std::vector<Point> points;
  for (const auto& t : base)
    for (int shift = 0; shift < 3; ++shift)
      for (const auto& signs :
           {std::array<double, 3>{-1, -1, -1}, {1, 1, -1}, {1, -1, 1}, {-1, 1, 1}})
        points.emplace_back(signs[0] * t[shift % 3], signs[1] * t[(shift + 1) % 3],
                            signs[2] * t[(shift + 2) % 3]);
  return hull_mesh(scaled_to_radius(std::move(points), radius));
}

}  // namespace morph
