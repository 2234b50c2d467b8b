// Reading and writing meshes with full double precision: OFF, OBJ, PLY (ascii and
// binary) and STL (ascii and binary).
//
// Readers never pass coordinates through float. Writers print 17 significant digits
// (max_digits10), so a write-then-read round trip is bit-exact. Every malformed input
// is an input_error naming the file and the line or element; sizes beyond ReadLimits
// are a limit_error (readers may also throw invalid_mesh for faces that cannot form a
// manifold mesh). Reading and writing are linear in the file size. Files are written atomically: a
// temporary file beside the target, then a rename, so a failed write never leaves a partial file
// nor clobbers the target.
#pragma once

#include <morph/mesh.h>

#include <array>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <iosfwd>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace morph {

enum class MeshFormat { off, obj, ply, stl };

/// The format named by a file's extension (case-insensitive: .off .obj .ply .stl).
/// Throws input_error for any other extension.
MeshFormat format_from_path(const std::filesystem::path& path);

/// The format named by a word ("off", "obj", "ply", "stl"); throws input_error otherwise.
MeshFormat format_from_name(std::string_view name);

/// Limits on what a reader accepts; beyond them it throws limit_error. Counts are also
/// checked against the size of the input, so a 60-byte file cannot claim a billion
/// vertices and make the reader allocate gigabytes.
struct ReadLimits {
  std::size_t max_vertices = 50'000'000;   // per mesh
  std::size_t max_faces = 100'000'000;     // per mesh
  std::size_t max_face_valence = 100'000;  // vertices of one face
};

struct ReadOptions {
  ReadLimits limits;
  /// STL stores triangles with repeated corners; exactly equal corners are merged
  /// into one vertex (always on: STL has no shared vertices otherwise).
};

/// Reads a mesh, choosing the format by extension (ascii or binary detected from the
/// content for PLY and STL).
/// Throws io_error if the file cannot be opened or read, input_error if malformed.
Mesh read_mesh(const std::filesystem::path& path, const ReadOptions& options = {});

/// Reads a mesh of the given format from a stream; `name` is used in error messages.
Mesh read_mesh(std::istream& in, MeshFormat format, std::string_view name,
               const ReadOptions& options = {});

using Color = std::array<std::uint8_t, 3>;

struct WriteOptions {
  /// Format; by default taken from the path's extension.
  std::optional<MeshFormat> format;
  /// PLY and STL only: write the binary variant (little-endian) instead of ascii.
  bool binary = false;
  /// Optional per-face colours (one per face, in face-index order). Written by OFF
  /// (as "r g b" after the face) and PLY (face properties red, green, blue); other
  /// formats ignore them.
  std::vector<Color> face_colors;
};

/// Writes a mesh atomically (temporary file + rename). Throws io_error when the file
/// cannot be written; the target is then left as it was.
void write_mesh(const Mesh& mesh, const std::filesystem::path& path,
                const WriteOptions& options = {});

/// Writes a mesh to a stream in the given format (options.format is ignored).
/// Throws io_error when the stream fails.
void write_mesh(const Mesh& mesh, std::ostream& out, MeshFormat format,
                const WriteOptions& options = {});

}  // namespace morph
