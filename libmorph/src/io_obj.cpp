// Wavefront OBJ: "v x y z" vertices and "f a b c ..." faces, whose corners are
// "v", "v/vt", "v/vt/vn" or "v//vn"; indices count from 1, negative ones count back
// from the last vertex read so far. Texture coordinates, normals, groups, materials
// and every other statement are ignored.
#include "io_detail.h"

namespace morph::io_detail {
namespace {

// The vertex index of one face corner ("7", "7/2", "7/2/5", "7//5"), as written. The
// texture and normal parts, if present, must be integers too.
std::int64_t corner_vertex(std::string_view corner, std::string_view name, std::size_t line) {
  std::size_t slash = corner.find('/');
  std::int64_t vertex = parse_integer(corner.substr(0, slash), name, line, "vertex index");
  while (slash != std::string_view::npos) {
    corner.remove_prefix(slash + 1);
    slash = corner.find('/');
    std::string_view part = corner.substr(0, slash);
    if (!part.empty()) parse_integer(part, name, line, "texture or normal index");
  }
  return vertex;
}

}  // namespace

Mesh read_obj(std::string_view data, std::string_view name, const ReadLimits& limits) {
  MeshData mesh;
  mesh.index_base = 1;
  LineReader lines(data);
  std::string_view line;
  std::string_view token;
  while (lines.next(line)) {
    Tokens tokens(strip_comment(line));
    if (!tokens.next(token)) continue;
    if (token == "v") {
      if (mesh.points.size() >= limits.max_vertices) {
        fail_limit(name, "more than the limit of " + std::to_string(limits.max_vertices) +
                             " vertices (line " + std::to_string(lines.line()) + ")");
      }
      double xyz[3];
      for (double& c : xyz) {
        if (!tokens.next(token)) fail_at_line(name, lines.line(), "vertex: expected 3 coordinates");
        c = parse_coordinate(token, name, lines.line());
      }
      // An optional w or a colour may follow: ignored.
      mesh.points.emplace_back(xyz[0], xyz[1], xyz[2]);
    } else if (token == "f") {
      const std::size_t face = mesh.face_end.size();
      if (face >= limits.max_faces) {
        fail_limit(name, "more than the limit of " + std::to_string(limits.max_faces) +
                             " faces (line " + std::to_string(lines.line()) + ")");
      }
      const auto n_read = static_cast<std::int64_t>(mesh.points.size());
      std::size_t valence = 0;
      while (tokens.next(token)) {
        if (++valence > limits.max_face_valence) {
          throw limit_error(std::string(name) + ":" + std::to_string(lines.line()) + ": face " +
                            std::to_string(face) + ": more than the limit of " +
                            std::to_string(limits.max_face_valence) + " vertices");
        }
        const std::int64_t index = corner_vertex(token, name, lines.line());
        const std::int64_t resolved = index < 0 ? n_read + index : index - 1;
        if (index == 0 || resolved < 0 || resolved >= n_read) {
          fail_at_line(name, lines.line(),
                       "face " + std::to_string(face) + ": vertex index " + std::to_string(index) +
                           (index == 0 ? " is invalid (OBJ indices count from 1)"
                                       : " does not refer to one of the " + std::to_string(n_read) +
                                             " vertices read so far"));
        }
        mesh.corners.push_back(static_cast<int>(resolved));
      }
      mesh.add_face_line(lines.line());
      mesh.end_face();
    }
    // vt, vn, vp, g, o, s, usemtl, mtllib, l, p, ...: not part of the polyhedron.
  }
  // OBJ has no header: a file without a single vertex is most likely not OBJ at all.
  if (mesh.points.empty()) fail_in_file(name, "no vertices ('v' lines) found");
  return build_mesh(mesh, name, limits);
}

void write_obj(const WriteView& view, const Mesh& mesh, std::ostream& out) {
  BlockWriter writer(out);
  std::string& text = writer.buffer();
  text += "# written by libmorph\n";
  for (Mesh::VertexHandle v : view.vertices) {
    text += "v ";
    append_point(text, mesh.point(v));
    text += '\n';
    writer.maybe_flush();
  }
  for (Mesh::FaceHandle f : view.faces) {
    text += 'f';
    for (Mesh::VertexHandle v : mesh.fv_range(f)) {
      text += ' ';
      append_integer(text, static_cast<std::uint64_t>(view.index_of[v.idx()]) + 1);
    }
    text += '\n';
    writer.maybe_flush();
  }
  writer.finish();
}

}  // namespace morph::io_detail
