// STL (stereolithography), ascii ("solid ... facet normal ... outer loop / vertex x y z
// / endloop endfacet ... endsolid") and binary (80-byte header, uint32 triangle count,
// 50 bytes a triangle: normal and corners as little-endian float32, uint16 attribute).
//
// STL repeats each corner in every triangle; exactly equal corners are merged into one
// vertex so that the mesh is connected (+0 and -0 count as equal; the first one read is
// kept). Facet normals are ignored on reading. Writing triangulates each polygon as a
// fan from its first vertex (STL holds only triangles) with the polygon's normal.
// Binary STL stores float32, so only float-representable coordinates survive it exactly.
#include <array>
#include <cmath>
#include <limits>
#include <unordered_map>

#include "io_detail.h"

namespace morph::io_detail {
namespace {

constexpr std::size_t kBinaryHeaderBytes = 84;    // 80-byte comment + uint32 count
constexpr std::size_t kBinaryTriangleBytes = 50;  // normal, 3 corners, attribute

// Merges exactly equal corners, hashing their bit patterns.
class CornerMerger {
 public:
  explicit CornerMerger(MeshData& mesh) : mesh_(mesh) {}
  int index_of(const Point& p) {
    Key key;
    for (int i = 0; i < 3; ++i) {
      const double c = p[i] == 0.0 ? 0.0 : p[i];  // -0 and +0 are the same point
      key[i] = std::bit_cast<std::uint64_t>(c);
    }
    auto [it, added] = index_.try_emplace(key, static_cast<int>(mesh_.points.size()));
    if (added) mesh_.points.push_back(p);
    return it->second;
  }
  void reserve(std::size_t n) { index_.reserve(n); }

 private:
  using Key = std::array<std::uint64_t, 3>;
  struct KeyHash {
    std::size_t operator()(const Key& k) const {
      std::uint64_t h = 0x9e3779b97f4a7c15ull;
      for (std::uint64_t word : k) {
        h ^= word + 0x9e3779b97f4a7c15ull + (h << 6) + (h >> 2);
      }
      return static_cast<std::size_t>(h);
    }
  };
  MeshData& mesh_;
  std::unordered_map<Key, int, KeyHash> index_;
};

// Tokens of a whole text, with the line each comes from.
class TokenStream {
 public:
  explicit TokenStream(std::string_view data) : lines_(data) {}
  bool next(std::string_view& token) {
    while (!tokens_.next(token)) {
      std::string_view line;
      if (!lines_.next(line)) return false;
      tokens_ = Tokens(line);
    }
    return true;
  }
  void skip_rest_of_line() { tokens_ = Tokens({}); }
  std::size_t line() const { return lines_.line(); }

 private:
  LineReader lines_;
  Tokens tokens_{{}};
};

bool starts_with_solid(std::string_view data) {
  Tokens tokens(data.substr(0, 256));
  std::string_view first;
  return tokens.next(first) && first == "solid";
}

void read_ascii(std::string_view data, std::string_view name, const ReadLimits& limits,
                MeshData& mesh) {
  TokenStream in(data);
  CornerMerger merger(mesh);
  std::string_view token;
  auto expect = [&](std::string_view word) {
    if (!in.next(token))
      fail_at_line(name, in.line(), "truncated: expected '" + std::string(word) + "'");
    if (token != word) {
      fail_at_line(
          name, in.line(),
          "expected '" + std::string(word) + "', found '" + std::string(token.substr(0, 40)) + "'");
    }
  };
  expect("solid");
  in.skip_rest_of_line();  // the solid's name
  for (;;) {
    if (!in.next(token)) fail_at_line(name, in.line(), "truncated: missing 'endsolid'");
    if (token == "endsolid") {
      in.skip_rest_of_line();
      if (!in.next(token)) break;
      if (token != "solid") {
        fail_at_line(name, in.line(),
                     "unexpected '" + std::string(token.substr(0, 40)) + "' after 'endsolid'");
      }
      in.skip_rest_of_line();  // another solid follows
      continue;
    }
    if (token != "facet") {
      fail_at_line(
          name, in.line(),
          "expected 'facet' or 'endsolid', found '" + std::string(token.substr(0, 40)) + "'");
    }
    const std::size_t face = mesh.face_end.size();
    const std::size_t facet_line = in.line();
    if (face >= limits.max_faces) {
      fail_limit(name, "more than the limit of " + std::to_string(limits.max_faces) +
                           " facets (line " + std::to_string(facet_line) + ")");
    }
    expect("normal");
    for (int i = 0; i < 3; ++i) {  // the normal: ignored, but must be there
      if (!in.next(token)) fail_at_line(name, in.line(), "truncated facet normal");
    }
    expect("outer");
    expect("loop");
    std::size_t valence = 0;
    for (;;) {
      if (!in.next(token))
        fail_at_line(name, in.line(), "truncated: expected 'vertex' or 'endloop'");
      if (token == "endloop") break;
      if (token != "vertex") {
        fail_at_line(
            name, in.line(),
            "expected 'vertex' or 'endloop', found '" + std::string(token.substr(0, 40)) + "'");
      }
      if (++valence > limits.max_face_valence) {
        throw limit_error(std::string(name) + ":" + std::to_string(in.line()) + ": face " +
                          std::to_string(face) + ": more than the limit of " +
                          std::to_string(limits.max_face_valence) + " vertices");
      }
      double xyz[3];
      for (double& c : xyz) {
        if (!in.next(token)) fail_at_line(name, in.line(), "truncated vertex");
        c = parse_coordinate(token, name, in.line());
      }
      mesh.corners.push_back(merger.index_of(Point(xyz[0], xyz[1], xyz[2])));
    }
    expect("endfacet");
    mesh.add_face_line(facet_line);
    mesh.end_face();
  }
}

void read_binary(std::string_view data, std::string_view name, const ReadLimits& limits,
                 MeshData& mesh) {
  if (data.size() < kBinaryHeaderBytes) {
    fail_in_file(name, "not an STL file: it does not start with 'solid' (ascii) and its " +
                           std::to_string(data.size()) +
                           " bytes cannot hold the 84-byte binary header");
  }
  const auto n = from_bytes<std::uint32_t>(data.data() + 80, std::endian::little);
  const std::size_t available = data.size() - kBinaryHeaderBytes;
  check_count(name, "triangles", n, limits.max_faces, kBinaryTriangleBytes, available);
  if (available != std::uint64_t{n} * kBinaryTriangleBytes) {
    fail_in_file(name,
                 "binary STL size does not match its header: " + std::to_string(n) +
                     " triangles need " +
                     std::to_string(kBinaryHeaderBytes + std::uint64_t{n} * kBinaryTriangleBytes) +
                     " bytes, the file has " + std::to_string(data.size()));
  }
  CornerMerger merger(mesh);
  merger.reserve(n / 2 + 3);
  mesh.points.reserve(n / 2 + 3);
  mesh.corners.reserve(std::size_t{3} * n);
  mesh.face_end.reserve(n);
  const char* p = data.data() + kBinaryHeaderBytes;
  for (std::uint32_t t = 0; t < n; ++t, p += kBinaryTriangleBytes) {
    for (int corner = 0; corner < 3; ++corner) {
      double xyz[3];
      for (int i = 0; i < 3; ++i) {
        xyz[i] = from_bytes<float>(p + 12 * (corner + 1) + 4 * i, std::endian::little);
        if (!std::isfinite(xyz[i])) {
          fail_in_file(name, "triangle " + std::to_string(t) + ": coordinate is not finite");
        }
      }
      mesh.corners.push_back(merger.index_of(Point(xyz[0], xyz[1], xyz[2])));
    }
    mesh.end_face();
  }
}

// The unit normal of a polygon (Newell's method), or zero if it has no area.
Point polygon_normal(const Mesh& mesh, Mesh::FaceHandle f) {
  Point normal(0, 0, 0);
  std::vector<Point> points;
  for (Mesh::VertexHandle v : mesh.fv_range(f)) points.push_back(mesh.point(v));
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Point& p = points[i];
    const Point& q = points[(i + 1) % points.size()];
    normal[0] += (p[1] - q[1]) * (p[2] + q[2]);
    normal[1] += (p[2] - q[2]) * (p[0] + q[0]);
    normal[2] += (p[0] - q[0]) * (p[1] + q[1]);
  }
  const double length = normal.norm();
  if (!(length > 0) || !std::isfinite(length)) return Point(0, 0, 0);
  return normal / length;
}

// Throws unless every written coordinate fits in binary STL's float32 (checked before
// anything is written, so a stream gets no partial file).
void check_float_range(const WriteView& view, const Mesh& mesh) {
  for (std::size_t i = 0; i < view.vertices.size(); ++i) {
    const Point& p = mesh.point(view.vertices[i]);
    for (int k = 0; k < 3; ++k) {
      if (std::fabs(p[k]) > static_cast<double>(std::numeric_limits<float>::max())) {
        throw input_error("write_mesh: vertex " + std::to_string(i) +
                          ": a coordinate is beyond the range of binary STL's 32-bit floats");
      }
    }
  }
}

}  // namespace

Mesh read_stl(std::string_view data, std::string_view name, const ReadLimits& limits) {
  MeshData mesh;
  bool binary = !starts_with_solid(data);
  if (data.size() >= kBinaryHeaderBytes) {
    // Some binary files start with "solid" too: an exact size match decides.
    const auto n = from_bytes<std::uint32_t>(data.data() + 80, std::endian::little);
    if (kBinaryHeaderBytes + std::uint64_t{n} * kBinaryTriangleBytes == data.size()) binary = true;
  }
  if (binary) {
    read_binary(data, name, limits, mesh);
  } else {
    read_ascii(data, name, limits, mesh);
  }
  return build_mesh(mesh, name, limits);
}

void write_stl(const WriteView& view, const Mesh& mesh, std::ostream& out, bool binary) {
  BlockWriter writer(out);
  std::string& text = writer.buffer();
  if (binary) {
    check_float_range(view, mesh);
    std::uint64_t triangles = 0;
    for (Mesh::FaceHandle f : view.faces) triangles += mesh.valence(f) - 2;
    if (triangles > std::numeric_limits<std::uint32_t>::max()) {
      throw input_error("write_mesh: " + std::to_string(triangles) +
                        " triangles do not fit in a binary STL");
    }
    std::string header = "binary STL written by libmorph";
    header.resize(80, ' ');
    text += header;
    append_le<std::uint32_t>(text, static_cast<std::uint32_t>(triangles));
  } else {
    text += "solid libmorph\n";
  }
  std::vector<Mesh::VertexHandle> corners;
  for (Mesh::FaceHandle f : view.faces) {
    const Point normal = polygon_normal(mesh, f);
    corners.clear();
    for (Mesh::VertexHandle v : mesh.fv_range(f)) corners.push_back(v);
    for (std::size_t i = 1; i + 1 < corners.size(); ++i) {
      const Mesh::VertexHandle triangle[3] = {corners[0], corners[i], corners[i + 1]};
      if (binary) {
        for (int k = 0; k < 3; ++k) append_le<float>(text, static_cast<float>(normal[k]));
        for (Mesh::VertexHandle v : triangle) {
          const Point& p = mesh.point(v);
          for (int k = 0; k < 3; ++k) append_le<float>(text, static_cast<float>(p[k]));
        }
        append_le<std::uint16_t>(text, 0);
      } else {
        text += "  facet normal ";
        append_point(text, normal);
        text += "\n    outer loop\n";
        for (Mesh::VertexHandle v : triangle) {
          text += "      vertex ";
          append_point(text, mesh.point(v));
          text += '\n';
        }
        text += "    endloop\n  endfacet\n";
      }
    }
    writer.maybe_flush();
  }
  if (!binary) text += "endsolid libmorph\n";
  writer.finish();
}

}  // namespace morph::io_detail
