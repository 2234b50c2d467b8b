// Internals shared by the mesh readers and writers (io_*.cpp); not installed.
//
// Every reader gets the whole input as one byte buffer, so counts in a header can be
// checked against the bytes that follow before anything is reserved. Readers fill a
// MeshData (plain arrays); build_mesh turns it into an OpenMesh mesh, checking each face
// first so that OpenMesh never rejects (and never prints about) a face.
//
// Element numbers in messages are 0-based, in file order ("face 0" is the first face).
#pragma once

#include <morph/error.h>
#include <morph/io.h>
#include <morph/mesh.h>

#include <bit>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <ostream>
#include <string>
#include <string_view>
#include <vector>

namespace morph::io_detail {

// ---------------------------------------------------------------- errors

/// Throws input_error "<name>:<line>: <what>".
[[noreturn]] void fail_at_line(std::string_view name, std::size_t line, std::string_view what);
/// Throws input_error "<name>: <what>" (binary formats: `what` names the element).
[[noreturn]] void fail_in_file(std::string_view name, std::string_view what);
/// Throws limit_error "<name>: <what>".
[[noreturn]] void fail_limit(std::string_view name, std::string_view what);

/// Throws limit_error unless `count` elements of at least `min_bytes` each can fit in
/// `available` bytes and `count <= max_count`. Called before reserving from a header.
void check_count(std::string_view name, std::string_view element, std::uint64_t count,
                 std::uint64_t max_count, std::uint64_t min_bytes, std::uint64_t available);

// ---------------------------------------------------------------- text scanning

/// Lines of a text buffer, with the line terminator ("\n" or "\r\n") removed.
class LineReader {
 public:
  explicit LineReader(std::string_view data, std::size_t first_line = 1)
      : data_(data), next_line_(first_line) {}
  /// The next line; false at the end of the data.
  bool next(std::string_view& line);
  /// The number of the line last returned by next() (1-based).
  std::size_t line() const { return line_; }
  /// Bytes not yet returned.
  std::size_t remaining() const { return data_.size() - pos_; }

 private:
  std::string_view data_;
  std::size_t pos_ = 0;
  std::size_t line_ = 0;
  std::size_t next_line_;
};

/// Whitespace-separated tokens of one line.
class Tokens {
 public:
  explicit Tokens(std::string_view text) : rest_(text) {}
  bool next(std::string_view& token);
  /// True if no token is left.
  bool empty();

 private:
  std::string_view rest_;
};

/// The part of `line` before the first `comment` character.
std::string_view strip_comment(std::string_view line, char comment = '#');
/// True if the buffer holds nothing but whitespace.
bool is_blank(std::string_view data);

/// A coordinate written as decimal text, parsed exactly (from_chars, round to nearest).
/// Throws input_error at `line` for non-numbers, NaN/Inf and values beyond double's range
/// (values below the smallest subnormal round to zero, as a correctly rounded parse does).
double parse_coordinate(std::string_view token, std::string_view name, std::size_t line);
/// The same for a float-typed value (PLY "property float"): the nearest float, widened.
double parse_float_coordinate(std::string_view token, std::string_view name, std::size_t line);
/// A decimal integer; throws input_error at `line`, naming `what`, unless it is one.
std::int64_t parse_integer(std::string_view token, std::string_view name, std::size_t line,
                           std::string_view what);

// ---------------------------------------------------------------- binary data

template <class T>
T from_bytes(const char* p, std::endian order) {
  T value;
  unsigned char bytes[sizeof(T)];
  std::memcpy(bytes, p, sizeof(T));
  if (order != std::endian::native) {
    for (std::size_t i = 0; i < sizeof(T) / 2; ++i) std::swap(bytes[i], bytes[sizeof(T) - 1 - i]);
  }
  std::memcpy(&value, bytes, sizeof(T));
  return value;
}

template <class T>
void append_le(std::string& out, T value) {
  unsigned char bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));
  if (std::endian::native != std::endian::little) {
    for (std::size_t i = 0; i < sizeof(T) / 2; ++i) std::swap(bytes[i], bytes[sizeof(T) - 1 - i]);
  }
  out.append(reinterpret_cast<const char*>(bytes), sizeof(T));
}

// ---------------------------------------------------------------- building meshes

/// A mesh as plain arrays, as the readers produce it.
struct MeshData {
  std::vector<Point> points;
  std::vector<int> corners;            // vertex indices of all faces, concatenated
  std::vector<std::size_t> face_end;   // one past the last corner of each face
  std::vector<std::size_t> face_line;  // text formats: the line of each face; else empty
  int index_base = 0;                  // numbering of vertex indices in the file (messages)

  void add_face_line(std::size_t line) { face_line.push_back(line); }
  void end_face() { face_end.push_back(corners.size()); }
};

/// The OpenMesh mesh of `data`. Throws input_error naming the face for a face with fewer
/// than 3 vertices, a repeated or out-of-range vertex; limit_error beyond the limits;
/// invalid_mesh for a face that cannot join the faces before it in a 2-manifold
/// (an edge already used in the same direction, or a vertex already closed).
Mesh build_mesh(const MeshData& data, std::string_view name, const ReadLimits& limits);

// ---------------------------------------------------------------- writing

/// The elements a writer emits: deleted vertices and faces skipped, indices compacted.
struct WriteView {
  std::vector<Mesh::VertexHandle> vertices;
  std::vector<int> index_of;  // by vertex idx: the written index, -1 if deleted
  std::vector<Mesh::FaceHandle> faces;
  std::vector<Color> colors;  // one per written face, or empty
  std::size_t max_valence = 0;
};

/// Throws input_error if options.face_colors is neither empty nor one per face.
WriteView make_write_view(const Mesh& mesh, const WriteOptions& options);

/// Appends `value` with 17 significant digits (bit-exact when read back).
void append_double(std::string& out, double value);
/// Appends "x y z", each with append_double.
void append_point(std::string& out, const Point& point);
void append_integer(std::string& out, std::uint64_t value);

/// Output in large blocks; throws io_error as soon as the stream fails.
class BlockWriter {
 public:
  explicit BlockWriter(std::ostream& out) : out_(out) { buffer_.reserve(kBlockBytes + 4096); }
  std::string& buffer() { return buffer_; }
  /// Call after each element: writes the block once it is large enough.
  void maybe_flush() {
    if (buffer_.size() >= kBlockBytes) flush();
  }
  /// Writes what is left and flushes the stream.
  void finish();

 private:
  void flush();
  static constexpr std::size_t kBlockBytes = 1 << 16;  // big enough to amortise write calls
  std::ostream& out_;
  std::string buffer_;
};

// ---------------------------------------------------------------- formats

Mesh read_off(std::string_view data, std::string_view name, const ReadLimits& limits);
Mesh read_obj(std::string_view data, std::string_view name, const ReadLimits& limits);
Mesh read_ply(std::string_view data, std::string_view name, const ReadLimits& limits);
Mesh read_stl(std::string_view data, std::string_view name, const ReadLimits& limits);

void write_off(const WriteView& view, const Mesh& mesh, std::ostream& out);
void write_obj(const WriteView& view, const Mesh& mesh, std::ostream& out);
void write_ply(const WriteView& view, const Mesh& mesh, std::ostream& out, bool binary);
void write_stl(const WriteView& view, const Mesh& mesh, std::ostream& out, bool binary);

}  // namespace morph::io_detail
