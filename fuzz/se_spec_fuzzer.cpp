// Fuzz target: morph::make_structuring_element on arbitrary spec strings. Strings that
// could name a file ('/', '\\', '.') are skipped so the fuzzer never touches the file
// system (scripts/fuzz.sh also runs it in an empty directory). Only morph::error may be
// thrown; a built element must be a convex polyhedron.
#include <morph/error.h>
#include <morph/structuring_element.h>
#include <morph/validate.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view spec(reinterpret_cast<const char*>(data), size);
  if (size > 256 || spec.find_first_of("/\\.") != std::string_view::npos) return 0;
  morph::Mesh se;
  try {
    se = morph::make_structuring_element(spec);
  } catch (const morph::error&) {
    return 0;
  }
  if (se.n_faces() < 4 || !morph::check_convex_polyhedron(se).ok()) std::abort();
  return 0;
}
