// Mesh I/O entry points (format choice, whole-file reading, atomic writing) and the
// helpers every format shares: exact number parsing and printing, mesh building.
#include <fcntl.h>
#include <locale.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <istream>
#include <iterator>
#include <limits>
#include <sstream>

#include "io_detail.h"

namespace morph {
namespace io_detail {

// ---------------------------------------------------------------- errors

void fail_at_line(std::string_view name, std::size_t line, std::string_view what) {
  throw input_error(std::string(name) + ":" + std::to_string(line) + ": " + std::string(what));
}

void fail_in_file(std::string_view name, std::string_view what) {
  throw input_error(std::string(name) + ": " + std::string(what));
}

void fail_limit(std::string_view name, std::string_view what) {
  throw limit_error(std::string(name) + ": " + std::string(what));
}

void check_count(std::string_view name, std::string_view element, std::uint64_t count,
                 std::uint64_t max_count, std::uint64_t min_bytes, std::uint64_t available) {
  if (count > max_count) {
    fail_limit(name, "the header declares " + std::to_string(count) + " " + std::string(element) +
                         ", more than the limit of " + std::to_string(max_count));
  }
  if (min_bytes > 0 && count > available / min_bytes) {
    fail_limit(name, "the header declares " + std::to_string(count) + " " + std::string(element) +
                         ", which cannot fit in the " + std::to_string(available) +
                         " bytes that follow (truncated file or wrong count)");
  }
}

// ---------------------------------------------------------------- text scanning

bool LineReader::next(std::string_view& line) {
  if (pos_ >= data_.size()) return false;
  std::size_t end = data_.find('\n', pos_);
  std::size_t stop = end == std::string_view::npos ? data_.size() : end;
  line = data_.substr(pos_, stop - pos_);
  if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
  pos_ = end == std::string_view::npos ? data_.size() : end + 1;
  line_ = next_line_++;
  return true;
}

namespace {
bool is_space(char c) {
  return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\f' || c == '\v';
}
}  // namespace

bool Tokens::next(std::string_view& token) {
  std::size_t i = 0;
  while (i < rest_.size() && is_space(rest_[i])) ++i;
  if (i == rest_.size()) {
    rest_ = {};
    return false;
  }
  std::size_t j = i;
  while (j < rest_.size() && !is_space(rest_[j])) ++j;
  token = rest_.substr(i, j - i);
  rest_.remove_prefix(j);
  return true;
}

bool Tokens::empty() {
  std::size_t i = 0;
  while (i < rest_.size() && is_space(rest_[i])) ++i;
  rest_.remove_prefix(i);
  return rest_.empty();
}

std::string_view strip_comment(std::string_view line, char comment) {
  std::size_t at = line.find(comment);
  return at == std::string_view::npos ? line : line.substr(0, at);
}

bool is_blank(std::string_view data) {
  return std::all_of(data.begin(), data.end(), [](char c) { return is_space(c); });
}

namespace {

// A token shown in a message: quoted, cut short, control bytes replaced.
std::string quoted(std::string_view token) {
  std::string out = "'";
  for (char c : token.substr(0, 40)) {
    out += std::isprint(static_cast<unsigned char>(c)) ? c : '?';
  }
  if (token.size() > 40) out += "...";
  return out + "'";
}

// from_chars does not take a leading '+', which C's strtod and most writers allow.
std::string_view without_plus(std::string_view token) {
  if (token.size() > 1 && token[0] == '+' && token[1] != '-' && token[1] != '+') {
    token.remove_prefix(1);
  }
  return token;
}

// from_chars reports both overflow and underflow as out of range; strtod in the C
// locale tells them apart (underflow gives a value of magnitude at most the smallest
// normal, overflow gives HUGE_VAL).
template <class T>
bool overflows(std::string_view token) {
  static const locale_t c_locale = newlocale(LC_ALL_MASK, "C", locale_t{});
  std::string copy(token);
  double value = strtod_l(copy.c_str(), nullptr, c_locale);
  return std::fabs(value) > static_cast<double>(std::numeric_limits<T>::max());
}

template <class T>
double parse_real(std::string_view token, std::string_view name, std::size_t line) {
  std::string_view text = without_plus(token);
  T value{};
  auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (end != text.data() + text.size() ||
      (ec != std::errc() && ec != std::errc::result_out_of_range)) {
    fail_at_line(name, line, quoted(token) + " is not a number");
  }
  if (ec == std::errc::result_out_of_range) {
    if (overflows<T>(text)) {
      fail_at_line(name, line,
                   "coordinate " + quoted(token) + " is beyond the range of " +
                       (sizeof(T) == 4 ? "float" : "double"));
    }
    value = text[0] == '-' ? -T(0) : T(0);  // below the smallest subnormal: rounds to zero
  }
  if (!std::isfinite(value)) {
    fail_at_line(name, line, "coordinate " + quoted(token) + " is not finite");
  }
  return static_cast<double>(value);
}

}  // namespace

double parse_coordinate(std::string_view token, std::string_view name, std::size_t line) {
  return parse_real<double>(token, name, line);
}

double parse_float_coordinate(std::string_view token, std::string_view name, std::size_t line) {
  return parse_real<float>(token, name, line);
}

std::int64_t parse_integer(std::string_view token, std::string_view name, std::size_t line,
                           std::string_view what) {
  std::string_view text = without_plus(token);
  std::int64_t value = 0;
  auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (ec != std::errc() || end != text.data() + text.size()) {
    fail_at_line(name, line, std::string(what) + " " + quoted(token) + " is not an integer");
  }
  return value;
}

// ---------------------------------------------------------------- building meshes

namespace {

// Why OpenMesh's add_face would refuse `face`, or "" if it will succeed. Mirrors the
// checks of PolyConnectivity::add_face (complex vertex, complex edge, patch re-linking)
// so that OpenMesh is never asked to add a face it would reject (it prints on omerr).
std::string why_face_cannot_join(const Mesh& mesh, const std::vector<Mesh::VertexHandle>& face,
                                 std::vector<Mesh::HalfedgeHandle>& halfedges, int index_base) {
  const std::size_t n = face.size();
  auto vertex = [&](std::size_t i) { return std::to_string(face[i].idx() + index_base); };
  halfedges.assign(n, Mesh::HalfedgeHandle());
  for (std::size_t i = 0; i < n; ++i) {
    if (!mesh.is_boundary(face[i])) {
      return "vertex " + vertex(i) +
             " is already enclosed by a closed fan of faces (non-manifold vertex)";
    }
    halfedges[i] = mesh.find_halfedge(face[i], face[(i + 1) % n]);
    if (halfedges[i].is_valid() && !mesh.is_boundary(halfedges[i])) {
      return "edge " + vertex(i) + "-" + vertex((i + 1) % n) +
             " is already used in the same direction by face " +
             std::to_string(mesh.face_handle(halfedges[i]).idx()) +
             " (non-manifold edge or inconsistent orientation)";
    }
  }
  for (std::size_t i = 0; i < n; ++i) {
    std::size_t next = (i + 1) % n;
    if (!halfedges[i].is_valid() || !halfedges[next].is_valid()) continue;
    if (mesh.next_halfedge_handle(halfedges[i]) == halfedges[next]) continue;
    // Both edges exist but are not consecutive around vertex `next`: OpenMesh moves the
    // faces between them to another boundary gap of that vertex, which must exist.
    Mesh::HalfedgeHandle boundary_prev = mesh.opposite_halfedge_handle(halfedges[next]);
    do {
      boundary_prev = mesh.opposite_halfedge_handle(mesh.next_halfedge_handle(boundary_prev));
    } while (!mesh.is_boundary(boundary_prev));
    if (boundary_prev == halfedges[i]) {
      return "vertex " + vertex(next) +
             " would join two separate fans of faces (non-manifold vertex)";
    }
  }
  return {};
}

}  // namespace

Mesh build_mesh(const MeshData& data, std::string_view name, const ReadLimits& limits) {
  const std::size_t n_vertices = data.points.size();
  const std::size_t n_faces = data.face_end.size();
  if (n_vertices > limits.max_vertices) {
    fail_limit(name, std::to_string(n_vertices) + " vertices, more than the limit of " +
                         std::to_string(limits.max_vertices));
  }
  if (n_faces > limits.max_faces) {
    fail_limit(name, std::to_string(n_faces) + " faces, more than the limit of " +
                         std::to_string(limits.max_faces));
  }
  Mesh mesh;
  mesh.reserve(n_vertices, n_vertices + n_faces, n_faces);
  for (const Point& p : data.points) mesh.add_vertex(p);

  std::vector<std::size_t> seen_in_face(n_vertices, std::numeric_limits<std::size_t>::max());
  std::vector<Mesh::VertexHandle> face;
  std::vector<Mesh::HalfedgeHandle> halfedges;
  std::size_t begin = 0;
  for (std::size_t f = 0; f < n_faces; ++f) {
    auto fail = [&](const std::string& what, bool limit = false) {
      std::string where = std::string(name) + ":";
      if (!data.face_line.empty()) where += std::to_string(data.face_line[f]) + ":";
      std::string message = where + " face " + std::to_string(f) + ": " + what;
      if (limit) throw limit_error(message);
      throw input_error(message);
    };
    const std::size_t end = data.face_end[f];
    const std::size_t valence = end - begin;
    if (valence < 3) fail("has " + std::to_string(valence) + " vertices; a face needs at least 3");
    if (valence > limits.max_face_valence) {
      fail("has " + std::to_string(valence) + " vertices, more than the limit of " +
               std::to_string(limits.max_face_valence),
           true);
    }
    face.clear();
    for (std::size_t c = begin; c < end; ++c) {
      const int v = data.corners[c];
      if (v < 0 || static_cast<std::size_t>(v) >= n_vertices) {
        fail("vertex index " + std::to_string(static_cast<long long>(v) + data.index_base) +
             " is out of range (the file has " + std::to_string(n_vertices) + " vertices)");
      }
      if (seen_in_face[v] == f) {
        fail("vertex " + std::to_string(v + data.index_base) + " appears twice");
      }
      seen_in_face[v] = f;
      face.push_back(Mesh::VertexHandle(v));
    }
    std::string problem = why_face_cannot_join(mesh, face, halfedges, data.index_base);
    Mesh::FaceHandle added;
    if (problem.empty()) added = mesh.add_face(face);
    if (!added.is_valid()) {
      if (problem.empty()) problem = "cannot be joined to the faces before it (non-manifold)";
      std::string where = std::string(name) + ":";
      if (!data.face_line.empty()) where += std::to_string(data.face_line[f]) + ":";
      throw invalid_mesh(where + " face " + std::to_string(f) + ": " + problem);
    }
    begin = end;
  }
  return mesh;
}

// ---------------------------------------------------------------- writing

WriteView make_write_view(const Mesh& mesh, const WriteOptions& options) {
  WriteView view;
  view.index_of.assign(mesh.n_vertices(), -1);
  for (Mesh::VertexHandle v : mesh.all_vertices()) {
    if (mesh.has_vertex_status() && mesh.status(v).deleted()) continue;
    view.index_of[v.idx()] = static_cast<int>(view.vertices.size());
    view.vertices.push_back(v);
  }
  for (Mesh::FaceHandle f : mesh.all_faces()) {
    if (mesh.has_face_status() && mesh.status(f).deleted()) continue;
    view.faces.push_back(f);
    view.max_valence = std::max<std::size_t>(view.max_valence, mesh.valence(f));
  }
  const auto& colors = options.face_colors;
  if (!colors.empty()) {
    if (colors.size() == view.faces.size()) {
      view.colors = colors;
    } else if (colors.size() == mesh.n_faces()) {  // indexed by face idx, deleted ones too
      for (Mesh::FaceHandle f : view.faces) view.colors.push_back(colors[f.idx()]);
    } else {
      throw input_error("write_mesh: " + std::to_string(colors.size()) +
                        " face colours given for a mesh of " + std::to_string(view.faces.size()) +
                        " faces");
    }
  }
  return view;
}

void append_double(std::string& out, double value) {
  char buffer[64];
  auto result = std::to_chars(buffer, buffer + sizeof buffer, value, std::chars_format::general,
                              std::numeric_limits<double>::max_digits10);
  out.append(buffer, result.ptr);
}

void append_point(std::string& out, const Point& point) {
  append_double(out, point[0]);
  out += ' ';
  append_double(out, point[1]);
  out += ' ';
  append_double(out, point[2]);
}

void append_integer(std::string& out, std::uint64_t value) {
  char buffer[32];
  auto result = std::to_chars(buffer, buffer + sizeof buffer, value);
  out.append(buffer, result.ptr);
}

void BlockWriter::flush() {
  out_.write(buffer_.data(), static_cast<std::streamsize>(buffer_.size()));
  buffer_.clear();
  if (!out_) throw io_error("write_mesh: writing to the output stream failed");
}

void BlockWriter::finish() {
  flush();
  out_.flush();
  if (!out_) throw io_error("write_mesh: writing to the output stream failed");
}

}  // namespace io_detail

// ---------------------------------------------------------------- public entry points

namespace {

std::string errno_text(int error) { return std::string(std::strerror(error)); }

std::string lower(std::string_view text) {
  std::string out(text);
  for (char& c : out) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

std::optional<MeshFormat> format_named(std::string_view word) {
  const std::string name = lower(word);
  if (name == "off") return MeshFormat::off;
  if (name == "obj") return MeshFormat::obj;
  if (name == "ply") return MeshFormat::ply;
  if (name == "stl") return MeshFormat::stl;
  return std::nullopt;
}

// The whole file, read with POSIX calls so that errors carry errno.
std::string read_whole_file(const std::filesystem::path& path) {
  const std::string name = path.string();
  int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) throw io_error(name + ": cannot open: " + errno_text(errno));
  std::string data;
  struct stat info {};
  if (::fstat(fd, &info) == 0 && S_ISREG(info.st_mode) && info.st_size > 0) {
    data.reserve(static_cast<std::size_t>(info.st_size));
  }
  char block[1 << 16];
  for (;;) {
    ssize_t got = ::read(fd, block, sizeof block);
    if (got < 0) {
      if (errno == EINTR) continue;
      int error = errno;
      ::close(fd);
      throw io_error(name + ": cannot read: " + errno_text(error));
    }
    if (got == 0) break;
    data.append(block, static_cast<std::size_t>(got));
  }
  ::close(fd);
  return data;
}

Mesh read_buffer(std::string_view data, MeshFormat format, std::string_view name,
                 const ReadOptions& options) {
  if (io_detail::is_blank(data)) io_detail::fail_in_file(name, "empty file");
  switch (format) {
    case MeshFormat::off:
      return io_detail::read_off(data, name, options.limits);
    case MeshFormat::obj:
      return io_detail::read_obj(data, name, options.limits);
    case MeshFormat::ply:
      return io_detail::read_ply(data, name, options.limits);
    case MeshFormat::stl:
      return io_detail::read_stl(data, name, options.limits);
  }
  throw input_error(std::string(name) + ": unknown mesh format");
}

// Permissions for a new file: what open(..., 0666) would give under the process umask.
// The umask is read from /proc (umask() would change it, racing other threads).
mode_t new_file_mode() {
  mode_t mask = 022;
  std::ifstream status("/proc/self/status");
  std::string key;
  while (status >> key) {
    if (key == "Umask:") {
      std::string value;
      status >> value;
      mask = static_cast<mode_t>(std::strtoul(value.c_str(), nullptr, 8));
      break;
    }
    status.ignore(std::numeric_limits<std::streamsize>::max(), '\n');
  }
  return 0666 & ~mask;
}

// Writes `bytes` to a temporary file beside `target`, syncs it and renames it over the
// target. On any failure the temporary is removed and the target is untouched.
void write_in_place(const std::filesystem::path& target, const std::string& name,
                    std::string_view bytes) {
  const int fd = ::open(target.c_str(), O_WRONLY | O_CLOEXEC);
  if (fd < 0) throw io_error(name + ": cannot open for writing: " + errno_text(errno));
  for (std::size_t done = 0; done < bytes.size();) {
    const ssize_t wrote = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (wrote < 0 && errno == EINTR) continue;
    if (wrote <= 0) {
      const int error = wrote < 0 ? errno : EIO;
      ::close(fd);
      throw io_error(name + ": cannot write: " + errno_text(error));
    }
    done += static_cast<std::size_t>(wrote);
  }
  if (::close(fd) != 0) throw io_error(name + ": cannot write (close): " + errno_text(errno));
}

void write_atomically(const std::filesystem::path& requested, std::string_view bytes) {
  std::error_code ignored;
  std::filesystem::path target = requested;
  if (std::filesystem::is_symlink(target, ignored)) {  // replace the file, keep the link
    target = std::filesystem::weakly_canonical(target, ignored);
    if (ignored) target = requested;
  }
  const std::string name = requested.string();
  // A device or FIFO (/dev/null, /dev/stdout, /dev/full) is written in place: renaming a
  // temporary over it would replace the device node with a regular file and hide errors.
  struct stat special {};
  if (::stat(target.c_str(), &special) == 0 && !S_ISREG(special.st_mode) &&
      !S_ISDIR(special.st_mode)) {
    write_in_place(target, name, bytes);
    return;
  }
  std::filesystem::path directory = target.parent_path();
  if (directory.empty()) directory = ".";
  std::string temp = (directory / ("." + target.filename().string() + ".tmp-XXXXXX")).string();
  int fd = ::mkstemp(temp.data());
  if (fd < 0) throw io_error(name + ": cannot create a temporary file: " + errno_text(errno));

  auto fail = [&](const std::string& what, int error) {
    if (fd >= 0) ::close(fd);
    ::unlink(temp.c_str());
    throw io_error(name + ": " + what + ": " + errno_text(error));
  };
  struct stat existing {};
  mode_t mode = ::stat(target.c_str(), &existing) == 0 && S_ISREG(existing.st_mode)
                    ? (existing.st_mode & 07777)
                    : new_file_mode();
  if (::fchmod(fd, mode) != 0) fail("cannot set permissions", errno);
  std::size_t done = 0;
  while (done < bytes.size()) {
    ssize_t wrote = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (wrote < 0) {
      if (errno == EINTR) continue;
      fail("cannot write", errno);
    }
    done += static_cast<std::size_t>(wrote);
  }
  if (::fsync(fd) != 0) fail("cannot write (fsync)", errno);
  int closed = ::close(fd);
  fd = -1;
  if (closed != 0) fail("cannot write (close)", errno);
  if (::rename(temp.c_str(), target.c_str()) != 0) fail("cannot replace the file", errno);
  // Make the rename itself durable; a failure here no longer threatens the data.
  int dir_fd = ::open(directory.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dir_fd >= 0) {
    ::fsync(dir_fd);
    ::close(dir_fd);
  }
}

}  // namespace

MeshFormat format_from_path(const std::filesystem::path& path) {
  std::string extension = path.extension().string();
  if (!extension.empty()) {
    if (auto format = format_named(std::string_view(extension).substr(1))) return *format;
  }
  throw input_error(
      path.string() + ": unknown mesh format " +
      (extension.empty() ? std::string("(no extension)") : "extension '" + extension + "'") +
      "; expected .off, .obj, .ply or .stl");
}

MeshFormat format_from_name(std::string_view name) {
  if (auto format = format_named(name)) return *format;
  throw input_error("unknown mesh format '" + std::string(name) +
                    "'; expected off, obj, ply or stl");
}

Mesh read_mesh(const std::filesystem::path& path, const ReadOptions& options) {
  const MeshFormat format = format_from_path(path);
  const std::string data = read_whole_file(path);
  return read_buffer(data, format, path.string(), options);
}

Mesh read_mesh(std::istream& in, MeshFormat format, std::string_view name,
               const ReadOptions& options) {
  std::string data{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  if (in.bad()) throw io_error(std::string(name) + ": reading the input stream failed");
  return read_buffer(data, format, name, options);
}

void write_mesh(const Mesh& mesh, std::ostream& out, MeshFormat format,
                const WriteOptions& options) {
  const io_detail::WriteView view = io_detail::make_write_view(mesh, options);
  switch (format) {
    case MeshFormat::off:
      return io_detail::write_off(view, mesh, out);
    case MeshFormat::obj:
      return io_detail::write_obj(view, mesh, out);
    case MeshFormat::ply:
      return io_detail::write_ply(view, mesh, out, options.binary);
    case MeshFormat::stl:
      return io_detail::write_stl(view, mesh, out, options.binary);
  }
}

void write_mesh(const Mesh& mesh, const std::filesystem::path& path, const WriteOptions& options) {
  const MeshFormat format = options.format ? *options.format : format_from_path(path);
  // The whole file is formatted in memory first: every input error is thrown before
  // the file system is touched.
  std::ostringstream content;
  write_mesh(mesh, content, format, options);
  write_atomically(path, content.view());
}

}  // namespace morph
