// Tests of mesh reading and writing (libmorph/src/io_*.cpp).
//
// The truth here is independent of the writers: hand-written files whose values the
// compiler parses too (literals), binary files assembled byte by byte, and bit patterns
// of the doubles that went in.
#include <doctest/doctest.h>
#include <morph/error.h>
#include <morph/io.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cfloat>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;
using morph::Mesh;
using morph::MeshFormat;
using morph::Point;

namespace {

std::uint64_t bits(double value) { return std::bit_cast<std::uint64_t>(value); }

// The unit cube, six outward quads.
Mesh make_cube() {
  Mesh mesh;
  const double corners[8][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0},
                                {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
  std::vector<Mesh::VertexHandle> v;
  for (const auto& c : corners) v.push_back(mesh.add_vertex(Point(c[0], c[1], c[2])));
  const int faces[6][4] = {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4},
                           {2, 3, 7, 6}, {0, 4, 7, 3}, {1, 2, 6, 5}};
  for (const auto& f : faces) mesh.add_face({v[f[0]], v[f[1]], v[f[2]], v[f[3]]});
  return mesh;
}

// The cube's connectivity with coordinates that stress exact printing and parsing.
Mesh make_awkward_cube(const std::vector<double>& values) {
  Mesh mesh = make_cube();
  const std::size_t n = values.size();
  for (Mesh::VertexHandle v : mesh.vertices()) {
    const std::size_t i = static_cast<std::size_t>(v.idx());
    mesh.point(v) = Point(values[i % n], values[(i + 3) % n], values[(i + 5) % n]);
  }
  return mesh;
}

const std::vector<double> kAwkwardDoubles = {0.12345678901234567,
                                             1e-300,
                                             -0.0,
                                             1.7976931348623157e308,
                                             4.9406564584124654e-324,
                                             2.2250738585072009e-308,
                                             -1.0 / 3.0,
                                             123456789.98765432,
                                             -2.5e-310,
                                             1e22,
                                             0.1,
                                             -7.0};

// Float-representable values (what binary STL can hold).
const std::vector<double> kAwkwardFloats = {
    static_cast<double>(0.1f),
    -0.0,
    static_cast<double>(FLT_MAX),
    static_cast<double>(std::numeric_limits<float>::denorm_min()),
    static_cast<double>(1e-30f),
    static_cast<double>(-1.0f / 3.0f),
    16777215.0,
    static_cast<double>(FLT_MIN),
    -7.0};

std::vector<int> face_vertices(const Mesh& mesh, Mesh::FaceHandle f) {
  std::vector<int> out;
  for (Mesh::VertexHandle v : mesh.fv_range(f)) out.push_back(v.idx());
  return out;
}

// Same vertices (bit for bit, in order) and same faces (same vertex cycles).
void check_identical(const Mesh& read, const Mesh& written) {
  REQUIRE(read.n_vertices() == written.n_vertices());
  REQUIRE(read.n_faces() == written.n_faces());
  for (Mesh::VertexHandle v : written.vertices()) {
    for (int k = 0; k < 3; ++k) {
      INFO("vertex " << v.idx() << " axis " << k);
      CHECK(bits(read.point(v)[k]) == bits(written.point(v)[k]));
    }
  }
  for (Mesh::FaceHandle f : written.faces()) {
    CHECK(face_vertices(read, f) == face_vertices(written, f));
  }
}

// The triangles of a fan triangulation, as coordinate bit patterns.
using Triangle = std::vector<std::uint64_t>;
std::vector<Triangle> fan_triangles(const Mesh& mesh, bool as_float) {
  std::vector<Triangle> out;
  for (Mesh::FaceHandle f : mesh.faces()) {
    std::vector<Point> p;
    for (Mesh::VertexHandle v : mesh.fv_range(f)) p.push_back(mesh.point(v));
    for (std::size_t i = 1; i + 1 < p.size(); ++i) {
      Triangle t;
      for (const Point* q : {&p[0], &p[i], &p[i + 1]}) {
        for (int k = 0; k < 3; ++k) {
          t.push_back(bits(as_float ? static_cast<double>(static_cast<float>((*q)[k])) : (*q)[k]));
        }
      }
      out.push_back(t);
    }
  }
  return out;
}

Mesh round_trip(const Mesh& mesh, MeshFormat format, bool binary) {
  std::stringstream stream;
  morph::WriteOptions options;
  options.binary = binary;
  morph::write_mesh(mesh, stream, format, options);
  return morph::read_mesh(stream, format, "round-trip");
}

Mesh read_text(const std::string& content, MeshFormat format,
               const morph::ReadOptions& options = {}) {
  std::istringstream in(content);
  return morph::read_mesh(in, format, "mem", options);
}

// Reading `content` as `format` (named "bad") throws Expected whose message holds `needle`.
template <class Expected>
void check_rejects(const std::string& content, MeshFormat format, const std::string& needle,
                   const morph::ReadOptions& options = {}) {
  INFO("input: " << content.substr(0, 300));
  std::istringstream in(content);
  try {
    morph::read_mesh(in, format, "bad", options);
    FAIL("accepted a malformed input; expected an error containing: " << needle);
  } catch (const Expected& e) {
    const std::string message = e.what();
    INFO("message: " << message);
    CHECK(message.find(needle) != std::string::npos);
  } catch (const std::exception& e) {
    FAIL("wrong exception type, message: " << e.what());
  }
}

// Binary buffers assembled by hand.
template <class T>
void put(std::string& out, T value, bool big_endian = false) {
  char bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));
  if (big_endian == (std::endian::native == std::endian::little))
    std::reverse(bytes, bytes + sizeof(T));
  out.append(bytes, sizeof(T));
}

// A binary STL of the given triangles (float corners), with a zero normal.
std::string binary_stl(const std::vector<std::array<std::array<float, 3>, 3>>& triangles,
                       std::string header = std::string(80, '\0')) {
  std::string out = header;
  put<std::uint32_t>(out, static_cast<std::uint32_t>(triangles.size()));
  for (const auto& t : triangles) {
    for (int k = 0; k < 3; ++k) put<float>(out, 0.0f);
    for (const auto& corner : t) {
      for (float c : corner) put<float>(out, c);
    }
    put<std::uint16_t>(out, 0);
  }
  return out;
}

// The 12 triangles of the unit cube's faces (each quad split along a diagonal).
std::vector<std::array<std::array<float, 3>, 3>> cube_triangles() {
  std::vector<std::array<std::array<float, 3>, 3>> out;
  Mesh cube = make_cube();
  for (Mesh::FaceHandle f : cube.faces()) {
    std::vector<std::array<float, 3>> p;
    for (Mesh::VertexHandle v : cube.fv_range(f)) {
      const Point& q = cube.point(v);
      p.push_back({float(q[0]), float(q[1]), float(q[2])});
    }
    out.push_back({p[0], p[1], p[2]});
    out.push_back({p[0], p[2], p[3]});
  }
  return out;
}

// A fresh directory under the system temporary directory, removed afterwards.
struct TempDir {
  fs::path path;
  TempDir() {
    static int counter = 0;
    path = fs::temp_directory_path() /
           ("morph_io_test_" + std::to_string(::getpid()) + "_" + std::to_string(counter++));
    fs::remove_all(path);
    fs::create_directories(path);
  }
  ~TempDir() {
    std::error_code ignored;
    fs::remove_all(path, ignored);
  }
  // Names of leftover temporaries of the atomic writer.
  std::vector<std::string> temporaries() const {
    std::vector<std::string> out;
    for (const auto& entry : fs::recursive_directory_iterator(path)) {
      const std::string name = entry.path().filename().string();
      if (name.find(".tmp-") != std::string::npos) out.push_back(name);
    }
    return out;
  }
};

std::string slurp(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void spit(const fs::path& path, const std::string& content) {
  std::ofstream out(path, std::ios::binary);
  out << content;
}

const std::string kOffTetra =
    "OFF\n4 4 6\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n";

}  // namespace

// ---------------------------------------------------------------- formats by name

TEST_CASE("io: format from path and name") {
  CHECK(morph::format_from_path("a/b.off") == MeshFormat::off);
  CHECK(morph::format_from_path("B.OBJ") == MeshFormat::obj);
  CHECK(morph::format_from_path("x.Ply") == MeshFormat::ply);
  CHECK(morph::format_from_path("x.stl") == MeshFormat::stl);
  CHECK(morph::format_from_name("STL") == MeshFormat::stl);
  CHECK_THROWS_AS(morph::format_from_path("mesh.xyz"), morph::input_error);
  CHECK_THROWS_AS(morph::format_from_path("mesh"), morph::input_error);
  CHECK_THROWS_AS(morph::format_from_name("3ds"), morph::input_error);
  CHECK_THROWS_AS(morph::read_mesh(fs::path("nowhere/mesh.xyz")), morph::input_error);
}

// ---------------------------------------------------------------- exact values

TEST_CASE("io: hand-written files read to the nearest double") {
  const std::string off =
      "OFF\n# a comment\n4 1 0\n0.1 -2.5e-310 1e-400\n+3 0.3333333333333333 -0\n"
      "1.7976931348623157e308 4.9406564584124654e-324 7\n 0 0 0 \n4 0 1 2 3\n";
  Mesh mesh = read_text(off, MeshFormat::off);
  REQUIRE(mesh.n_vertices() == 4);
  CHECK(bits(mesh.point(Mesh::VertexHandle(0))[0]) == bits(0.1));
  CHECK(bits(mesh.point(Mesh::VertexHandle(0))[1]) == bits(-2.5e-310));
  CHECK(bits(mesh.point(Mesh::VertexHandle(0))[2]) == bits(0.0));  // underflow rounds to zero
  CHECK(bits(mesh.point(Mesh::VertexHandle(1))[0]) == bits(3.0));
  CHECK(bits(mesh.point(Mesh::VertexHandle(1))[1]) == bits(0.3333333333333333));
  CHECK(bits(mesh.point(Mesh::VertexHandle(1))[2]) == bits(-0.0));
  CHECK(bits(mesh.point(Mesh::VertexHandle(2))[0]) == bits(1.7976931348623157e308));
  CHECK(bits(mesh.point(Mesh::VertexHandle(2))[1]) == bits(4.9406564584124654e-324));
  REQUIRE(mesh.n_faces() == 1);
  CHECK(mesh.valence(Mesh::FaceHandle(0)) == 4);
}

TEST_CASE("io: OFF variants: counts on the header line, COFF, face colours") {
  Mesh a = read_text("OFF 4 4 6\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n",
                     MeshFormat::off);
  CHECK(a.n_vertices() == 4);
  CHECK(a.n_faces() == 4);
  Mesh b = read_text(
      "COFF\n4 4 6\n0 0 0 255 0 0 255\n1 0 0 0 255 0 255\n0 1 0 1 1 1 1\n0 0 1 0 0 0 1\n"
      "3 0 2 1 255 0 0\n3 0 1 3 0.5 0.5 0.5 1\n3 0 3 2\n3 1 2 3 7\n",
      MeshFormat::off);
  CHECK(b.n_faces() == 4);
  CHECK(bits(b.point(Mesh::VertexHandle(1))[0]) == bits(1.0));
  CHECK(face_vertices(b, Mesh::FaceHandle(3)) == std::vector<int>{1, 2, 3});
  CHECK(read_text("OFF\n0 0 0\n", MeshFormat::off).n_vertices() == 0);
}

TEST_CASE("io: OBJ statements and index forms") {
  const std::string obj =
      "# cube corner\nmtllib x.mtl\no thing\nv 0 0 0\nv 1 0 0 1.0\nv 0 1 0\nv 0 0 1 0.5 0.5 0.5\n"
      "vt 0 0\nvn 0 0 1\ng group\nusemtl red\ns off\n"
      "f 1 3 2\nf 1/1 2/1 4/1\nf 1//1 4//1 3//1\nf -3/1/1 -2/1/1 -1/1/1\n";
  Mesh mesh = read_text(obj, MeshFormat::obj);
  REQUIRE(mesh.n_vertices() == 4);
  REQUIRE(mesh.n_faces() == 4);
  CHECK(face_vertices(mesh, Mesh::FaceHandle(0)) == std::vector<int>{0, 2, 1});
  CHECK(face_vertices(mesh, Mesh::FaceHandle(1)) == std::vector<int>{0, 1, 3});
  CHECK(face_vertices(mesh, Mesh::FaceHandle(2)) == std::vector<int>{0, 3, 2});
  CHECK(face_vertices(mesh, Mesh::FaceHandle(3)) == std::vector<int>{1, 2, 3});
  CHECK(mesh.is_boundary(Mesh::VertexHandle(0)) == false);  // closed tetrahedron
}

TEST_CASE("io: PLY float properties are read as floats, double as doubles, extras skipped") {
  const std::string ascii =
      "ply\nformat ascii 1.0\ncomment hi\nelement vertex 3\nproperty float x\nproperty double y\n"
      "property int z\nproperty uchar red\nelement face 1\nproperty uchar flags\n"
      "property list uchar uint vertex_index\nproperty list int float texcoord\n"
      "element edge 1\nproperty int a\nproperty int b\nend_header\n"
      "0.1 0.1 5 255\n1 0 0 0\n0 1 -3 9\n7 3 0 1 2 2 0.5 0.25\n0 1\n";
  Mesh mesh = read_text(ascii, MeshFormat::ply);
  REQUIRE(mesh.n_vertices() == 3);
  CHECK(bits(mesh.point(Mesh::VertexHandle(0))[0]) == bits(static_cast<double>(0.1f)));
  CHECK(bits(mesh.point(Mesh::VertexHandle(0))[1]) == bits(0.1));
  CHECK(mesh.point(Mesh::VertexHandle(0))[2] == 5.0);
  CHECK(mesh.point(Mesh::VertexHandle(2))[2] == -3.0);
  REQUIRE(mesh.n_faces() == 1);
  CHECK(face_vertices(mesh, Mesh::FaceHandle(0)) == std::vector<int>{0, 1, 2});

  // The same in binary, both byte orders, assembled by hand.
  for (bool big : {false, true}) {
    CAPTURE(big);
    std::string ply = std::string("ply\nformat ") +
                      (big ? "binary_big_endian" : "binary_little_endian") +
                      " 1.0\nelement vertex 3\nproperty float x\nproperty double y\n"
                      "property short z\nproperty uchar red\nelement face 1\nproperty uchar flags\n"
                      "property list uchar uint vertex_index\nproperty list int float texcoord\n"
                      "end_header\n";
    const float xs[3] = {0.1f, 1, 0};
    const double ys[3] = {0.1, 0, 1};
    const std::int16_t zs[3] = {5, 0, -3};
    for (int i = 0; i < 3; ++i) {
      put<float>(ply, xs[i], big);
      put<double>(ply, ys[i], big);
      put<std::int16_t>(ply, zs[i], big);
      put<std::uint8_t>(ply, 200, big);
    }
    put<std::uint8_t>(ply, 7, big);
    put<std::uint8_t>(ply, 3, big);
    for (std::uint32_t i : {2u, 0u, 1u}) put<std::uint32_t>(ply, i, big);
    put<std::int32_t>(ply, 2, big);
    put<float>(ply, 0.5f, big);
    put<float>(ply, 0.25f, big);
    Mesh b = read_text(ply, MeshFormat::ply);
    REQUIRE(b.n_vertices() == 3);
    CHECK(bits(b.point(Mesh::VertexHandle(0))[0]) == bits(static_cast<double>(0.1f)));
    CHECK(bits(b.point(Mesh::VertexHandle(0))[1]) == bits(0.1));
    CHECK(b.point(Mesh::VertexHandle(2))[2] == -3.0);
    REQUIRE(b.n_faces() == 1);
    CHECK(face_vertices(b, Mesh::FaceHandle(0)) == std::vector<int>{2, 0, 1});
  }
}

// ---------------------------------------------------------------- round trips

TEST_CASE("io: write-then-read is bit-exact and keeps polygons (OFF, OBJ, PLY, ascii STL)") {
  const Mesh mesh = make_awkward_cube(kAwkwardDoubles);
  SUBCASE("OFF") { check_identical(round_trip(mesh, MeshFormat::off, false), mesh); }
  SUBCASE("OBJ") { check_identical(round_trip(mesh, MeshFormat::obj, false), mesh); }
  SUBCASE("PLY ascii") { check_identical(round_trip(mesh, MeshFormat::ply, false), mesh); }
  SUBCASE("PLY binary") { check_identical(round_trip(mesh, MeshFormat::ply, true), mesh); }
  SUBCASE("STL ascii: fan triangles, exact corners") {
    Mesh read = round_trip(mesh, MeshFormat::stl, false);
    CHECK(read.n_vertices() == 8);
    std::vector<Triangle> got;
    for (Mesh::FaceHandle f : read.faces()) {
      REQUIRE(read.valence(f) == 3);
      Triangle t;
      for (Mesh::VertexHandle v : read.fv_range(f)) {
        for (int k = 0; k < 3; ++k) t.push_back(bits(read.point(v)[k]));
      }
      got.push_back(t);
    }
    CHECK(got == fan_triangles(mesh, false));
  }
}

TEST_CASE("io: binary STL round trip is exact for float values and rounds doubles to float") {
  for (const auto* values : {&kAwkwardFloats, &kAwkwardDoubles}) {
    std::vector<double> usable = *values;
    // Binary STL cannot hold values beyond float's range.
    std::erase_if(usable, [](double x) { return std::fabs(x) > FLT_MAX; });
    const Mesh mesh = make_awkward_cube(usable);
    Mesh read = round_trip(mesh, MeshFormat::stl, true);
    REQUIRE(read.n_faces() == 12);
    std::vector<Triangle> got;
    for (Mesh::FaceHandle f : read.faces()) {
      Triangle t;
      for (Mesh::VertexHandle v : read.fv_range(f)) {
        for (int k = 0; k < 3; ++k) t.push_back(bits(read.point(v)[k]));
      }
      got.push_back(t);
    }
    CHECK(got == fan_triangles(mesh, true));
  }
  Mesh huge = make_cube();
  huge.point(Mesh::VertexHandle(3))[1] = 1e300;
  std::stringstream out;
  morph::WriteOptions options;
  options.binary = true;
  CHECK_THROWS_AS(morph::write_mesh(huge, out, MeshFormat::stl, options), morph::input_error);
  CHECK(out.str().empty());  // checked before anything is written
}

TEST_CASE("io: round trip through files for every format and variant") {
  TempDir dir;
  const Mesh mesh = make_awkward_cube(kAwkwardDoubles);
  for (const char* name : {"m.off", "m.obj", "m.ply", "m.PLY"}) {
    CAPTURE(name);
    morph::WriteOptions options;
    options.binary = std::string(name) == "m.PLY";
    morph::write_mesh(mesh, dir.path / name, options);
    check_identical(morph::read_mesh(dir.path / name), mesh);
  }
  const Mesh cube = make_cube();
  for (bool binary : {false, true}) {
    morph::WriteOptions options;
    options.binary = binary;
    morph::write_mesh(cube, dir.path / "c.stl", options);
    const std::string bytes = slurp(dir.path / "c.stl");
    CHECK((bytes.rfind("solid", 0) == 0) == !binary);
    if (binary) CHECK(bytes.size() == 84 + 12 * 50);
    Mesh read = morph::read_mesh(dir.path / "c.stl");
    CHECK(read.n_vertices() == 8);
    CHECK(read.n_faces() == 12);
  }
  CHECK(dir.temporaries().empty());
}

TEST_CASE("io: polygons stay polygons, large valences too") {
  const Mesh cube = make_cube();
  for (MeshFormat format : {MeshFormat::off, MeshFormat::obj, MeshFormat::ply}) {
    for (bool binary : {false, true}) {
      Mesh read = round_trip(cube, format, binary);
      REQUIRE(read.n_faces() == 6);
      for (Mesh::FaceHandle f : read.faces()) CHECK(read.valence(f) == 4);
    }
  }
  // One 300-gon: PLY needs a wider list count than uchar.
  Mesh disk;
  std::vector<Mesh::VertexHandle> ring;
  for (int i = 0; i < 300; ++i) {
    ring.push_back(disk.add_vertex(Point(std::cos(i * 0.02), std::sin(i * 0.02), 0)));
  }
  disk.add_face(ring);
  for (MeshFormat format : {MeshFormat::off, MeshFormat::obj, MeshFormat::ply}) {
    for (bool binary : {false, true}) {
      check_identical(round_trip(disk, format, binary), disk);
    }
  }
  Mesh fan = round_trip(disk, MeshFormat::stl, true);
  CHECK(fan.n_faces() == 298);
  CHECK(fan.n_vertices() == 300);
}

TEST_CASE("io: STL facets carry the polygon's unit normal") {
  std::stringstream ascii;
  morph::write_mesh(make_cube(), ascii, MeshFormat::stl);
  const std::string text = ascii.str();
  std::vector<std::string> normals;
  std::istringstream lines(text);
  for (std::string line; std::getline(lines, line);) {
    if (line.find("facet normal") != std::string::npos) normals.push_back(line);
  }
  // Two fan triangles per quad, in face order: -z, +z, -y, +y, -x, +x.
  const std::vector<std::string> expected = {"0 0 -1", "0 0 1",  "0 -1 0",
                                             "0 1 0",  "-1 0 0", "1 0 0"};
  REQUIRE(normals.size() == 12);
  for (std::size_t i = 0; i < 12; ++i) {
    CHECK(normals[i] == "  facet normal " + expected[i / 2]);
  }
  morph::WriteOptions options;
  options.binary = true;
  std::stringstream binary;
  morph::write_mesh(make_cube(), binary, MeshFormat::stl, options);
  const std::string bytes = binary.str();
  REQUIRE(bytes.size() == 84 + 12 * 50);
  float n[3];
  std::memcpy(n, bytes.data() + 84 + 50 * 11, sizeof n);  // last triangle: +x face
  CHECK(n[0] == 1.0f);
  CHECK(n[1] == 0.0f);
  CHECK(n[2] == 0.0f);
}

TEST_CASE("io: STL corners are merged into shared vertices") {
  Mesh binary = read_text(binary_stl(cube_triangles()), MeshFormat::stl);
  CHECK(binary.n_vertices() == 8);
  CHECK(binary.n_faces() == 12);
  for (Mesh::VertexHandle v : binary.vertices()) CHECK_FALSE(binary.is_boundary(v));

  // A binary file whose header starts with "solid" is still binary (size decides).
  Mesh solid_header = read_text(
      binary_stl(cube_triangles(), "solid but binary" + std::string(64, ' ')), MeshFormat::stl);
  CHECK(solid_header.n_vertices() == 8);

  // -0 and +0 are the same corner.
  auto triangles = cube_triangles();
  for (auto& t : triangles) {
    for (auto& c : t) {
      if (c[0] == 0.0f) c[0] = -0.0f;
      break;
    }
  }
  CHECK(read_text(binary_stl(triangles), MeshFormat::stl).n_vertices() == 8);

  std::string ascii = "solid cube thing\n";
  for (const auto& t : cube_triangles()) {
    ascii += " facet normal 0 0 0\n  outer loop\n";
    for (const auto& c : t) {
      ascii += "   vertex " + std::to_string(c[0]) + " " + std::to_string(c[1]) + " " +
               std::to_string(c[2]) + "\n";
    }
    ascii += "  endloop\n endfacet\n";
  }
  ascii += "endsolid cube thing\n";
  Mesh from_ascii = read_text(ascii, MeshFormat::stl);
  CHECK(from_ascii.n_vertices() == 8);
  CHECK(from_ascii.n_faces() == 12);
}

TEST_CASE("io: face colours in OFF and PLY") {
  const Mesh cube = make_cube();
  morph::WriteOptions options;
  for (int i = 0; i < 6; ++i) {
    options.face_colors.push_back({static_cast<std::uint8_t>(40 * i), 7, 255});
  }
  std::stringstream off;
  morph::write_mesh(cube, off, MeshFormat::off, options);
  CHECK(off.str().find("\n4 0 3 2 1 0 7 255\n") != std::string::npos);
  CHECK(off.str().find("\n4 1 2 6 5 200 7 255\n") != std::string::npos);
  check_identical(morph::read_mesh(off, MeshFormat::off, "colours"), cube);
  for (bool binary : {false, true}) {
    options.binary = binary;
    std::stringstream ply;
    morph::write_mesh(cube, ply, MeshFormat::ply, options);
    CHECK(ply.str().find("property uchar red\nproperty uchar green\nproperty uchar blue\n") !=
          std::string::npos);
    if (!binary) CHECK(ply.str().find("\n4 1 2 6 5 200 7 255\n") != std::string::npos);
    check_identical(morph::read_mesh(ply, MeshFormat::ply, "colours"), cube);
  }
  options.face_colors.pop_back();
  std::stringstream bad;
  CHECK_THROWS_AS(morph::write_mesh(cube, bad, MeshFormat::off, options), morph::input_error);
}

TEST_CASE("io: deleted elements are skipped and indices compacted") {
  Mesh mesh = make_cube();
  mesh.delete_vertex(Mesh::VertexHandle(0));  // and its three faces
  for (MeshFormat format : {MeshFormat::off, MeshFormat::obj, MeshFormat::ply}) {
    Mesh read = round_trip(mesh, format, false);
    CHECK(read.n_vertices() == 7);
    REQUIRE(read.n_faces() == 3);
    // Every written face is one of the cube's, by coordinates.
    for (Mesh::FaceHandle f : read.faces()) {
      for (Mesh::VertexHandle v : read.fv_range(f)) CHECK(read.point(v) != Point(0, 0, 0));
    }
  }
}

// ---------------------------------------------------------------- malformed input

TEST_CASE("io: malformed OFF") {
  using morph::input_error;
  using morph::limit_error;
  const MeshFormat off = MeshFormat::off;
  check_rejects<input_error>("", off, "bad: empty file");
  check_rejects<input_error>(" \n\n\t\n", off, "bad: empty file");
  check_rejects<input_error>("OFX\n3 1 0\n", off, "bad:1: missing OFF header");
  check_rejects<input_error>("# comment\n3 1 0\n0 0 0\n", off, "bad:2: missing OFF header");
  check_rejects<input_error>("4OFF\n", off, "bad:1:");
  check_rejects<input_error>("OFF\n", off, "bad:1: truncated");
  check_rejects<input_error>("OFF\nthree 1 0\n", off, "bad:2: count 'three' is not an integer");
  check_rejects<input_error>("OFF\n-3 1 0\n", off, "bad:2: negative count");
  // Lines long enough that the counts fit the size, yet lines are missing.
  const std::string pad = "0.000000000000000000000000000 ";
  check_rejects<input_error>("OFF\n4 1 0\n" + pad + "0 0\n" + pad + "0 0\n" + pad + "0 0\n", off,
                             "bad:5: truncated: the header declares 4 vertices, found 3");
  check_rejects<input_error>(
      "OFF\n3 2 0\n" + pad + "0 0\n" + pad + "1 0\n" + pad + "0 1\n3 0 1 2\n", off,
      "bad:6: truncated: the header declares 2 faces, found 1");
  const std::string tri = "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n";
  check_rejects<input_error>("OFF\n3 1 0\n0 0 0\n1 x 0\n0 1 0\n3 0 1 2\n", off,
                             "bad:4: 'x' is not a number");
  check_rejects<input_error>("OFF\n3 1 0\n0 0 0\n1 0x1 0\n0 1 0\n3 0 1 2\n", off, "bad:4:");
  check_rejects<input_error>("OFF\n3 1 0\n0.0 0.0 0.0\n1.0 0.0\n0.0 1.0 0.0\n3 0 1 2\n", off,
                             "bad:4: vertex 1: expected 3 coordinates");
  check_rejects<input_error>("OFF\n3 1 0\n0 0 0\n1 nan 0\n0 1 0\n3 0 1 2\n", off,
                             "bad:4: coordinate 'nan' is not finite");
  check_rejects<input_error>("OFF\n3 1 0\n0 0 0\n1 0 -inf\n0 1 0\n3 0 1 2\n", off,
                             "bad:4: coordinate '-inf' is not finite");
  check_rejects<input_error>("OFF\n3 1 0\n0 0 0\n1e400 0 0\n0 1 0\n3 0 1 2\n", off,
                             "bad:4: coordinate '1e400' is beyond the range of double");
  check_rejects<input_error>(tri + "3 0 1 3\n", off,
                             "bad:6: face 0: vertex index 3 is out of range");
  check_rejects<input_error>(tri + "3 0 -1 2\n", off,
                             "bad:6: face 0: vertex index -1 is out of range");
  check_rejects<input_error>(tri + "3 0 1.5 2\n", off,
                             "bad:6: vertex index '1.5' is not an integer");
  check_rejects<input_error>("OFF\n3 1 0\n0.0 0 0\n1.0 0 0\n0.0 1 0\n2 0 1\n", off,
                             "bad:6: face 0: has 2 vertices");
  check_rejects<input_error>(tri + "3 0 1 1\n", off, "bad:6: face 0: vertex 1 appears twice");
  check_rejects<input_error>(tri + "4 0 1 2\n", off,
                             "bad:6: face 0: expected 4 vertex indices, found 3");
  check_rejects<input_error>(tri + "3 0 1 2\n3 0 2 1\n", off, "bad:7: unexpected content");
}

TEST_CASE("io: malformed OBJ") {
  using morph::input_error;
  const MeshFormat obj = MeshFormat::obj;
  const std::string tri = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
  check_rejects<input_error>("", obj, "bad: empty file");
  check_rejects<input_error>("# only a comment\no name\n", obj, "bad: no vertices");
  check_rejects<input_error>("v 0 0 x\n", obj, "bad:1: 'x' is not a number");
  check_rejects<input_error>("v 0 0\n", obj, "bad:1: vertex: expected 3 coordinates");
  check_rejects<input_error>("v 0 NaN 0\n", obj, "bad:1: coordinate 'NaN' is not finite");
  check_rejects<input_error>(
      tri + "f 1 2 4\n", obj,
      "bad:4: face 0: vertex index 4 does not refer to one of the 3 vertices");
  check_rejects<input_error>(tri + "f 1 2 0\n", obj, "bad:4: face 0: vertex index 0 is invalid");
  check_rejects<input_error>(tri + "f -1 -2 -4\n", obj,
                             "bad:4: face 0: vertex index -4 does not refer");
  check_rejects<input_error>(tri + "f 1 2\n", obj, "bad:4: face 0: has 2 vertices");
  check_rejects<input_error>(tri + "f 1 2 -2\n", obj, "bad:4: face 0: vertex 2 appears twice");
  check_rejects<input_error>(tri + "f 1/x 2 3\n", obj, "bad:4: texture or normal index 'x'");
  check_rejects<input_error>(tri + "f 1 two 3\n", obj,
                             "bad:4: vertex index 'two' is not an integer");
}

TEST_CASE("io: malformed PLY") {
  using morph::input_error;
  using morph::limit_error;
  const MeshFormat ply = MeshFormat::ply;
  const std::string head =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty double x\nproperty double y\n"
      "property double z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";
  const std::string verts = "0 0 0\n1 0 0\n0 1 0\n";  // lines 10-12
  check_rejects<input_error>("", ply, "bad: empty file");
  check_rejects<input_error>("plyx\n", ply, "bad:1: missing PLY header");
  check_rejects<input_error>("ply\nformat ascii 1.0\nelement vertex 0\n", ply,
                             "bad:3: the header has no 'end_header'");
  check_rejects<input_error>("ply\nelement vertex 0\nend_header\n", ply,
                             "bad: the header has no 'format'");
  check_rejects<input_error>("ply\nformat binary_middle_endian 1.0\nend_header\n", ply,
                             "bad:2: unknown PLY format");
  check_rejects<input_error>(
      "ply\nformat ascii 1.0\nelement vertex 1\nproperty real x\nend_header\n", ply,
      "bad:4: unknown property type 'real'");
  check_rejects<input_error>(
      "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nend_header\n0 "
      "0\n",
      ply, "bad:3: element vertex has no property z");
  check_rejects<input_error>("ply\nformat ascii 1.0\nproperty float x\nend_header\n", ply,
                             "bad:3: property before any element");
  check_rejects<input_error>(head + "0 0 0\n1 0 0\n", ply, "bad:");
  check_rejects<input_error>(
      head + "0.000000000000000000000000 0 0\n1.00000000000000000000000000000 0 0\n", ply,
      "bad:11: vertex 2: truncated");
  check_rejects<input_error>(head + "0 0 0\n1 zero 0\n0 1 0\n3 0 1 2\n", ply,
                             "bad:11: 'zero' is not a number");
  check_rejects<input_error>(head + "0 0 0\n1 inf 0\n0 1 0\n3 0 1 2\n", ply,
                             "bad:11: coordinate 'inf' is not finite");
  check_rejects<input_error>(head + "0 0 0\n1 0\n0 1 0\n3 0 1 2\n", ply,
                             "bad:11: vertex 1: too few values");
  check_rejects<input_error>(head + "0 0 0\n1 0 0 0\n0 1 0\n3 0 1 2\n", ply,
                             "bad:11: vertex 1: more values than its properties");
  check_rejects<input_error>(head + verts + "3 0 1 3\n", ply,
                             "bad:13: face 0: vertex index 3 is out of range");
  check_rejects<input_error>(head + verts + "3 0 -1 2\n", ply,
                             "bad:13: face 0: vertex index -1 is out of range");
  check_rejects<input_error>(head + verts + "2 0 1\n", ply, "bad:13: face 0: has 2 vertices");
  check_rejects<input_error>(head + verts + "3 0 1 1\n", ply,
                             "bad:13: face 0: vertex 1 appears twice");
  check_rejects<input_error>(head + verts + "3 0 1\n", ply, "bad:13: face 0: too few values");
  check_rejects<input_error>(head + verts + "3 0 1 2\n3 0 1 2\n", ply,
                             "bad:14: unexpected content");

  // Binary: sizes must match the header exactly.
  std::string bin =
      "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty double x\nproperty double "
      "y\n"
      "property double z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";
  const double coords[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  for (double c : coords) put<double>(bin, c);
  std::string good = bin;
  put<std::uint8_t>(good, 3);
  for (int i : {0, 1, 2}) put<std::int32_t>(good, i);
  CHECK(read_text(good, ply).n_faces() == 1);
  check_rejects<input_error>(good + "x", ply, "bad: 1 bytes follow the last element");
  check_rejects<input_error>(good.substr(0, good.size() - 2), ply,
                             "bad: face 0: the file ends inside this element");
  std::string far = bin;
  put<std::uint8_t>(far, 3);
  for (int i : {0, 1, 7}) put<std::int32_t>(far, i);
  check_rejects<input_error>(far, ply, "bad: face 0: vertex index 7 is out of range");
  std::string nan = good;
  const double not_a_number = std::numeric_limits<double>::quiet_NaN();
  std::memcpy(nan.data() + bin.size() - 8 * 5, &not_a_number, 8);  // vertex 1, y
  check_rejects<input_error>(nan, ply, "bad: vertex 1: coordinate is not finite");
}

TEST_CASE("io: malformed STL") {
  using morph::input_error;
  using morph::limit_error;
  const MeshFormat stl = MeshFormat::stl;
  auto facet = [](const std::string& corners) {
    return " facet normal 0 0 1\n  outer loop\n" + corners + "  endloop\n endfacet\n";
  };
  const std::string corners = "   vertex 0 0 0\n   vertex 1 0 0\n   vertex 0 1 0\n";
  check_rejects<input_error>("", stl, "bad: empty file");
  check_rejects<input_error>("abc", stl, "bad: not an STL file");
  check_rejects<input_error>("solid x\n" + facet(corners), stl,
                             "bad:8: truncated: missing 'endsolid'");
  check_rejects<input_error>("solid x\n facet normal 0 0 1\n  outer lop\n", stl,
                             "bad:3: expected 'loop', found 'lop'");
  check_rejects<input_error>("solid x\n faucet\n", stl, "bad:2: expected 'facet' or 'endsolid'");
  check_rejects<input_error>(
      "solid x\n" + facet("   vertex 0 0 0\n   vertex 1 y 0\n   vertex 0 1 0\n") + "endsolid x\n",
      stl, "bad:5: 'y' is not a number");
  check_rejects<input_error>(
      "solid x\n" + facet("   vertex 0 0 0\n   vertex 1 nan 0\n   vertex 0 1 0\n") + "endsolid x\n",
      stl, "bad:5: coordinate 'nan' is not finite");
  check_rejects<input_error>(
      "solid x\n" + facet("   vertex 0 0 0\n   vertex 1 0 0\n") + "endsolid x\n", stl,
      "bad:2: face 0: has 2 vertices");
  check_rejects<input_error>(
      "solid x\n" + facet("   vertex 0 0 0\n   vertex 1 0 0\n   vertex 1 0 0\n") + "endsolid x\n",
      stl, "bad:2: face 0: vertex 1 appears twice");
  check_rejects<input_error>("solid x\n" + facet(corners) + "endsolid x\nfoo\n", stl,
                             "bad:10: unexpected 'foo' after 'endsolid'");

  auto cube = binary_stl(cube_triangles());
  check_rejects<input_error>(cube + "z", stl, "bad: binary STL size does not match its header");
  check_rejects<limit_error>(cube.substr(0, cube.size() - 10), stl,
                             "bad: the header declares 12 triangles");
  auto degenerate = cube_triangles();
  degenerate[5][2] = degenerate[5][1];
  check_rejects<input_error>(binary_stl(degenerate), stl, "bad: face 5: vertex");
  auto infinite = cube_triangles();
  infinite[3][1][2] = std::numeric_limits<float>::infinity();
  check_rejects<input_error>(binary_stl(infinite), stl,
                             "bad: triangle 3: coordinate is not finite");
}

TEST_CASE("io: non-manifold faces are errors naming the face, and nothing is printed") {
  std::ostringstream captured;
  std::streambuf* old = std::cerr.rdbuf(captured.rdbuf());
  // Face 1 repeats the directed edge 0->1 of face 0 (inconsistent orientation).
  check_rejects<morph::invalid_mesh>("OFF\n4 2 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 1 2\n3 0 1 3\n",
                                     MeshFormat::off, "bad:8: face 1: edge 0-1 is already used");
  // A closed tetrahedron, then a face at one of its (already closed) vertices.
  check_rejects<morph::invalid_mesh>(
      "OFF\n6 5 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n-1 0 0\n-1 -1 0\n3 0 2 1\n3 0 1 3\n3 0 3 2\n"
      "3 1 2 3\n3 0 4 5\n",
      MeshFormat::off, "bad:13: face 4: vertex 0 is already enclosed");
  // Three faces on one edge, in OBJ numbering.
  check_rejects<morph::invalid_mesh>(
      "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\nf 1 2 3\nf 2 1 4\nf 1 2 5\n", MeshFormat::obj,
      "bad:8: face 2: edge 1-2 is already used in the same direction by face 0");
  // Two fans at vertex 0, then a face closing one fan against the other.
  const std::string fans =
      "OFF\n5 3 0\n0 0 0\n1 0 0\n0 1 0\n-1 0 0\n0 -1 0\n3 0 1 2\n3 0 3 4\n3 1 0 2\n";
  check_rejects<morph::invalid_mesh>(fans, MeshFormat::off,
                                     "bad:10: face 2: vertex 0 would join two separate fans");
  std::cerr.rdbuf(old);
  CHECK(captured.str().empty());
}

TEST_CASE("io: absurd counts give limit_error without allocating") {
  using morph::limit_error;
  // 40 million vertices is within the default limits but cannot fit in 20 bytes.
  check_rejects<limit_error>("OFF\n40000000 1 0\n0 0 0\n", MeshFormat::off,
                             "bad: the header declares 40000000 vertices");
  check_rejects<limit_error>("OFF\n1000000000 1000000000 0\n", MeshFormat::off,
                             "more than the limit of 50000000");
  check_rejects<limit_error>("OFF\n9223372036854775807 0 0\n", MeshFormat::off,
                             "bad: the header declares");
  check_rejects<limit_error>(
      "ply\nformat binary_little_endian 1.0\nelement vertex 40000000\nproperty double x\n"
      "property double y\nproperty double z\nend_header\n0123456789",
      MeshFormat::ply, "bad: the header declares 40000000 vertices");
  check_rejects<limit_error>(
      "ply\nformat ascii 1.0\nelement vertex 1\nproperty double x\nproperty double y\n"
      "property double z\nelement face 90000000\nproperty list uchar int "
      "vertex_indices\nend_header\n"
      "0 0 0\n",
      MeshFormat::ply, "bad: the header declares 90000000 faces");
  check_rejects<limit_error>(
      "ply\nformat ascii 1.0\nelement junk 4000000000\nproperty double x\nend_header\n0\n",
      MeshFormat::ply, "'junk' elements");
  // A face list claiming 4 billion indices in a tiny binary file.
  std::string ply =
      "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty double x\nproperty double "
      "y\n"
      "property double z\nelement face 1\nproperty list uint int vertex_indices\nend_header\n";
  for (int i = 0; i < 9; ++i) put<double>(ply, 0.5 * i);
  put<std::uint32_t>(ply, 4000000000u);
  check_rejects<limit_error>(ply, MeshFormat::ply, "bad: face 0: has 4000000000 vertices");
  std::string stl = std::string(80, 'x');
  put<std::uint32_t>(stl, 40000000u);
  stl += std::string(50, '\0');
  check_rejects<limit_error>(stl, MeshFormat::stl, "bad: the header declares 40000000 triangles");

  // Explicit ReadLimits.
  morph::ReadOptions small;
  small.limits.max_vertices = 3;
  check_rejects<limit_error>(kOffTetra, MeshFormat::off, "more than the limit of 3", small);
  morph::ReadOptions few_faces;
  few_faces.limits.max_faces = 3;
  check_rejects<limit_error>(kOffTetra, MeshFormat::off, "more than the limit of 3", few_faces);
  morph::ReadOptions triangles_only;
  triangles_only.limits.max_face_valence = 3;
  std::stringstream cube;
  morph::write_mesh(make_cube(), cube, MeshFormat::obj);
  check_rejects<limit_error>(cube.str(), MeshFormat::obj, "face 0: more than the limit of 3",
                             triangles_only);
  std::stringstream cube_off;
  morph::write_mesh(make_cube(), cube_off, MeshFormat::off);
  check_rejects<limit_error>(cube_off.str(), MeshFormat::off, "face 0: has 4 vertices, more than",
                             triangles_only);
  std::stringstream cube_ply;
  morph::write_mesh(make_cube(), cube_ply, MeshFormat::ply);
  check_rejects<limit_error>(cube_ply.str(), MeshFormat::ply, "face 0: has 4 vertices, more than",
                             triangles_only);
}

// ---------------------------------------------------------------- files and atomic writes

TEST_CASE("io: reading files: missing file is io_error naming it") {
  TempDir dir;
  try {
    morph::read_mesh(dir.path / "missing.off");
    FAIL("no error");
  } catch (const morph::io_error& e) {
    CHECK(std::string(e.what()).find("missing.off") != std::string::npos);
    CHECK(std::string(e.what()).find("No such file") != std::string::npos);
  }
  fs::create_directory(dir.path / "dir.off");
  CHECK_THROWS_AS(morph::read_mesh(dir.path / "dir.off"), morph::io_error);
  spit(dir.path / "bad.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 9\n");
  try {
    morph::read_mesh(dir.path / "bad.off");
    FAIL("no error");
  } catch (const morph::input_error& e) {
    CHECK(std::string(e.what()).find((dir.path / "bad.off").string() + ":6: face 0") !=
          std::string::npos);
  }
}

TEST_CASE("io: atomic write never clobbers the target and leaves no temporaries") {
  TempDir dir;
  const Mesh cube = make_cube();
  const fs::path target = dir.path / "keep.off";
  spit(target, "original");

  SUBCASE("missing directory") {
    CHECK_THROWS_AS(morph::write_mesh(cube, dir.path / "no" / "such" / "x.off"), morph::io_error);
  }
  SUBCASE("parent is a regular file") {
    try {
      morph::write_mesh(cube, target / "x.off");
      FAIL("no error");
    } catch (const morph::io_error& e) {
      CHECK(std::string(e.what()).find("x.off") != std::string::npos);
    }
    CHECK(slurp(target) == "original");
  }
  SUBCASE("input error before anything is written") {
    morph::WriteOptions options;
    options.face_colors = {{1, 2, 3}};
    CHECK_THROWS_AS(morph::write_mesh(cube, target, options), morph::input_error);
    CHECK(slurp(target) == "original");
  }
  SUBCASE("the target is a directory: rename fails after the temporary is written") {
    fs::create_directory(dir.path / "d.off");
    spit(dir.path / "d.off" / "inside", "x");
    CHECK_THROWS_AS(morph::write_mesh(cube, dir.path / "d.off"), morph::io_error);
    CHECK(fs::is_directory(dir.path / "d.off"));
    CHECK(slurp(dir.path / "d.off" / "inside") == "x");
  }
  SUBCASE("unknown extension") {
    CHECK_THROWS_AS(morph::write_mesh(cube, dir.path / "x.dat"), morph::input_error);
  }
  SUBCASE("success replaces the target, keeping its permissions") {
    fs::permissions(target, fs::perms::owner_read | fs::perms::owner_write | fs::perms::group_read);
    morph::write_mesh(cube, target);
    check_identical(morph::read_mesh(target), cube);
    CHECK(fs::status(target).permissions() ==
          (fs::perms::owner_read | fs::perms::owner_write | fs::perms::group_read));
  }
  SUBCASE("explicit format overrides the extension") {
    morph::WriteOptions options;
    options.format = MeshFormat::obj;
    morph::write_mesh(cube, dir.path / "cube.txt", options);
    CHECK(slurp(dir.path / "cube.txt").find("\nf 1 4 3 2\n") != std::string::npos);
  }
  CHECK(dir.temporaries().empty());
}

TEST_CASE("io: writing to a failing stream is io_error") {
  std::ofstream full("/dev/full");
  if (!full) return;  // no /dev/full on this system
  Mesh big;
  std::vector<Mesh::VertexHandle> ring;
  for (int i = 0; i < 20000; ++i) ring.push_back(big.add_vertex(Point(i, 0.5 * i, 0)));
  big.add_face(ring);
  CHECK_THROWS_AS(morph::write_mesh(big, full, MeshFormat::off), morph::io_error);
  std::ostringstream closed;
  closed.setstate(std::ios::badbit);
  CHECK_THROWS_AS(morph::write_mesh(make_cube(), closed, MeshFormat::ply), morph::io_error);
}
