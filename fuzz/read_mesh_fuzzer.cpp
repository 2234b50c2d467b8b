// Fuzz target: morph::read_mesh(std::istream&, MeshFormat, name) on arbitrary bytes, for
// the format fixed at compile time (MORPH_FUZZ_FORMAT). A reader may only throw
// morph::error; a mesh it accepts must write and read back (OFF) with the same counts.
#include <morph/error.h>
#include <morph/io.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <sstream>
#include <string>

#define MORPH_STR2(x) #x
#define MORPH_STR(x) MORPH_STR2(x)

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const morph::MeshFormat format = morph::format_from_name(MORPH_STR(MORPH_FUZZ_FORMAT));
  std::istringstream in(std::string(reinterpret_cast<const char*>(data), size));
  morph::Mesh mesh;
  try {
    mesh = morph::read_mesh(in, format, "fuzz");
  } catch (const morph::error&) {
    return 0;
  }
  // Round trip: what was read is a well-formed mesh, so OFF must carry it unchanged.
  std::stringstream off;
  morph::write_mesh(mesh, off, morph::MeshFormat::off);
  const morph::Mesh again = morph::read_mesh(off, morph::MeshFormat::off, "fuzz round trip");
  if (again.n_faces() != mesh.n_faces() || again.n_vertices() > mesh.n_vertices()) std::abort();
  return 0;
}
