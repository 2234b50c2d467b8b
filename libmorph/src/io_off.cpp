// OFF (Object File Format): "OFF", then "#vertices #faces #edges", then one vertex per
// line ("x y z", extra values such as colours ignored), then one face per line
// ("n i0 ... i(n-1)", optional colour ignored). '#' starts a comment. The header may be
// prefixed by ST, C and N (texture, colour, normal per vertex: extra values on the
// vertex lines), and the counts may follow the keyword on the same line.
#include "io_detail.h"

namespace morph::io_detail {
namespace {

// The smallest text a vertex ("0 0 0\n") and a face ("3 0 1 2\n") can take.
constexpr std::uint64_t kMinVertexBytes = 6;
constexpr std::uint64_t kMinFaceBytes = 8;

// Checks the header keyword ([ST][C][N]OFF); throws for anything else.
void check_keyword(std::string_view keyword, std::string_view name, std::size_t line) {
  std::string_view rest = keyword;
  if (rest.starts_with("ST")) rest.remove_prefix(2);
  if (rest.starts_with("C")) rest.remove_prefix(1);
  if (rest.starts_with("N")) rest.remove_prefix(1);
  if (rest == "OFF") return;
  if (rest == "4OFF" || rest == "nOFF" || rest == "4nOFF") {
    fail_at_line(name, line, std::string(keyword) + ": only 3-dimensional OFF is supported");
  }
  fail_at_line(
      name, line,
      "missing OFF header: expected 'OFF', found '" + std::string(keyword.substr(0, 40)) + "'");
}

}  // namespace

Mesh read_off(std::string_view data, std::string_view name, const ReadLimits& limits) {
  LineReader lines(data);
  std::string_view line;
  auto next_content_line = [&](Tokens& tokens) {
    while (lines.next(line)) {
      tokens = Tokens(strip_comment(line));
      if (!tokens.empty()) return true;
    }
    return false;
  };

  Tokens tokens{{}};
  std::string_view token;
  if (!next_content_line(tokens)) fail_in_file(name, "empty file");
  tokens.next(token);
  check_keyword(token, name, lines.line());
  if (tokens.empty() && !next_content_line(tokens)) {
    fail_at_line(name, lines.line(), "truncated: the counts line is missing");
  }
  // The counts: vertices, faces, and (ignored) edges.
  std::int64_t counts[3] = {0, 0, 0};
  int n_counts = 0;
  while (n_counts < 3 && tokens.next(token)) {
    if (n_counts == 0 && token == "BINARY") {
      fail_at_line(name, lines.line(), "binary OFF is not supported");
    }
    counts[n_counts] = parse_integer(token, name, lines.line(), "count");
    if (counts[n_counts] < 0) fail_at_line(name, lines.line(), "negative count");
    ++n_counts;
  }
  if (n_counts < 2) {
    fail_at_line(name, lines.line(), "expected the counts '#vertices #faces #edges'");
  }
  if (!tokens.empty()) fail_at_line(name, lines.line(), "unexpected text after the counts");
  const auto n_vertices = static_cast<std::uint64_t>(counts[0]);
  const auto n_faces = static_cast<std::uint64_t>(counts[1]);
  // The last line may lack its newline, hence the one spare byte.
  const std::uint64_t available = lines.remaining() + 1;
  check_count(name, "vertices", n_vertices, limits.max_vertices, kMinVertexBytes, available);
  check_count(name, "faces", n_faces, limits.max_faces, kMinFaceBytes, available);
  if (n_vertices * kMinVertexBytes + n_faces * kMinFaceBytes > available) {
    fail_limit(name, "the header declares " + std::to_string(n_vertices) + " vertices and " +
                         std::to_string(n_faces) + " faces, which cannot fit in the " +
                         std::to_string(available - 1) +
                         " bytes that follow (truncated file or wrong counts)");
  }

  MeshData mesh;
  mesh.points.reserve(n_vertices);
  mesh.face_end.reserve(n_faces);
  mesh.face_line.reserve(n_faces);
  mesh.corners.reserve(3 * n_faces);
  for (std::uint64_t v = 0; v < n_vertices; ++v) {
    if (!next_content_line(tokens)) {
      fail_at_line(name, lines.line(),
                   "truncated: the header declares " + std::to_string(n_vertices) +
                       " vertices, found " + std::to_string(v));
    }
    double xyz[3];
    for (double& c : xyz) {
      if (!tokens.next(token)) {
        fail_at_line(name, lines.line(),
                     "vertex " + std::to_string(v) + ": expected 3 coordinates");
      }
      c = parse_coordinate(token, name, lines.line());
    }
    mesh.points.emplace_back(xyz[0], xyz[1], xyz[2]);
  }
  for (std::uint64_t f = 0; f < n_faces; ++f) {
    if (!next_content_line(tokens)) {
      fail_at_line(name, lines.line(),
                   "truncated: the header declares " + std::to_string(n_faces) + " faces, found " +
                       std::to_string(f));
    }
    tokens.next(token);
    const std::int64_t valence = parse_integer(token, name, lines.line(), "vertex count");
    if (valence < 3) {
      fail_at_line(name, lines.line(),
                   "face " + std::to_string(f) + ": has " + std::string(token) +
                       " vertices; a face needs at least 3");
    }
    if (static_cast<std::uint64_t>(valence) > limits.max_face_valence) {
      throw limit_error(std::string(name) + ":" + std::to_string(lines.line()) + ": face " +
                        std::to_string(f) + ": has " + std::to_string(valence) +
                        " vertices, more than the limit of " +
                        std::to_string(limits.max_face_valence));
    }
    for (std::int64_t i = 0; i < valence; ++i) {
      if (!tokens.next(token)) {
        fail_at_line(name, lines.line(),
                     "face " + std::to_string(f) + ": expected " + std::to_string(valence) +
                         " vertex indices, found " + std::to_string(i));
      }
      const std::int64_t index = parse_integer(token, name, lines.line(), "vertex index");
      if (index < 0 || static_cast<std::uint64_t>(index) >= n_vertices) {
        fail_at_line(name, lines.line(),
                     "face " + std::to_string(f) + ": vertex index " + std::to_string(index) +
                         " is out of range (the file has " + std::to_string(n_vertices) +
                         " vertices)");
      }
      mesh.corners.push_back(static_cast<int>(index));
    }
    // Whatever follows the indices is a colour: ignored.
    mesh.add_face_line(lines.line());
    mesh.end_face();
  }
  if (next_content_line(tokens)) {
    fail_at_line(
        name, lines.line(),
        "unexpected content after the " + std::to_string(n_faces) + " faces the header declares");
  }
  return build_mesh(mesh, name, limits);
}

void write_off(const WriteView& view, const Mesh& mesh, std::ostream& out) {
  BlockWriter writer(out);
  std::string& text = writer.buffer();
  text += "OFF\n";
  append_integer(text, view.vertices.size());
  text += ' ';
  append_integer(text, view.faces.size());
  text += " 0\n";
  for (Mesh::VertexHandle v : view.vertices) {
    append_point(text, mesh.point(v));
    text += '\n';
    writer.maybe_flush();
  }
  for (std::size_t f = 0; f < view.faces.size(); ++f) {
    append_integer(text, mesh.valence(view.faces[f]));
    for (Mesh::VertexHandle v : mesh.fv_range(view.faces[f])) {
      text += ' ';
      append_integer(text, view.index_of[v.idx()]);
    }
    if (!view.colors.empty()) {
      for (std::uint8_t channel : view.colors[f]) {
        text += ' ';
        append_integer(text, channel);
      }
    }
    text += '\n';
    writer.maybe_flush();
  }
  writer.finish();
}

}  // namespace morph::io_detail
