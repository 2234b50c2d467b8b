// Faults and hardening: writes that fail (disk full, unwritable directory, devices),
// inputs left untouched, structuring-element bounds, and replay of the fuzz corpora
// (tests/fuzz_corpus: seeds and every input that once crashed or hung a fuzz target).
#include <doctest/doctest.h>
#include <morph/error.h>
#include <morph/io.h>
#include <morph/morphology.h>
#include <morph/structuring_element.h>
#include <morph/validate.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <sstream>
#include <string>

namespace fs = std::filesystem;

namespace {

std::string read_bytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

std::size_t hash_file(const fs::path& path) { return std::hash<std::string>{}(read_bytes(path)); }

// A fresh empty directory under the system temporary directory.
fs::path scratch(const std::string& name) {
  const fs::path dir =
      fs::temp_directory_path() / ("morph_fault_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

bool has_temporary(const fs::path& dir) {
  for (const auto& entry : fs::directory_iterator(dir))
    if (entry.path().filename().string().find(".tmp-") != std::string::npos) return true;
  return false;
}

const fs::path kCorpus = fs::path(MORPH_SAMPLES_DIR) / ".." / "tests" / "fuzz_corpus";

}  // namespace

TEST_CASE("fault: disk full through the path API is io_error, the device stays, no temporary") {
  const fs::path dir = scratch("full");
  // A private /dev/full (char 1,7): the test never touches the real one. Needs root.
  const fs::path full = dir / "full.off";
  if (::mknod(full.c_str(), S_IFCHR | 0666, makedev(1, 7)) != 0) {
    MESSAGE("mknod not permitted; disk-full test skipped");
    return;
  }
  CHECK_THROWS_AS(morph::write_mesh(morph::make_box(1, 2, 3), full), morph::io_error);
  struct stat info {};
  REQUIRE(::stat(full.c_str(), &info) == 0);
  CHECK(S_ISCHR(info.st_mode));  // regression: it used to be replaced by a regular file
  CHECK_FALSE(has_temporary(dir));
  fs::remove_all(dir);
}

TEST_CASE("fault: writing to a device like /dev/null writes in place") {
  const fs::path dir = scratch("null");
  const fs::path null = dir / "null.ply";
  if (::mknod(null.c_str(), S_IFCHR | 0666, makedev(1, 3)) != 0) {
    MESSAGE("mknod not permitted; device test skipped");
    return;
  }
  CHECK_NOTHROW(morph::write_mesh(morph::make_box(1, 2, 3), null));
  struct stat info {};
  REQUIRE(::stat(null.c_str(), &info) == 0);
  CHECK(S_ISCHR(info.st_mode));
  CHECK_FALSE(has_temporary(dir));
  fs::remove_all(dir);
}

TEST_CASE("fault: a stream on /dev/full is io_error") {
  std::ofstream out("/dev/full", std::ios::binary);
  REQUIRE(out.is_open());
  CHECK_THROWS_AS(morph::write_mesh(morph::make_icosphere(1, 3), out, morph::MeshFormat::off),
                  morph::io_error);
}

TEST_CASE("fault: an output directory that cannot exist (its parent is a file) is io_error") {
  const fs::path dir = scratch("notdir");
  const fs::path file = dir / "plain.txt";
  std::ofstream(file) << "not a directory\n";
  const std::size_t before = hash_file(file);
  CHECK_THROWS_AS(morph::write_mesh(morph::make_box(1, 1, 1), file / "out.off"), morph::io_error);
  CHECK(hash_file(file) == before);
  CHECK_FALSE(has_temporary(dir));
  fs::remove_all(dir);
}

TEST_CASE("fault: inputs are untouched by reading, morphology and failed writes") {
  const fs::path dir = scratch("inputs");
  const fs::path input = dir / "cube.off";
  fs::copy_file(fs::path(MORPH_SAMPLES_DIR) / "cube.off", input);
  const std::size_t before = hash_file(input);
  const auto mtime = fs::last_write_time(input);
  const morph::Mesh a = morph::read_mesh(input);
  const morph::MorphResult opened = morph::open(a, morph::make_structuring_element("cube:0.1"));
  CHECK_FALSE(opened.is_empty());
  // A write that fails before touching the disk (bad colour count) and one into a file.
  morph::WriteOptions bad;
  bad.face_colors.resize(1);
  CHECK_THROWS_AS(morph::write_mesh(opened.mesh, input, bad), morph::input_error);
  CHECK_THROWS_AS(morph::write_mesh(opened.mesh, input / "x.off"), morph::io_error);
  CHECK(hash_file(input) == before);
  CHECK(fs::last_write_time(input) == mtime);
  CHECK_FALSE(has_temporary(dir));
  fs::remove_all(dir);
}

TEST_CASE("limits: structuring-element parameters are bounded with clear errors") {
  const auto message = [](const char* spec) {
    try {
      morph::make_structuring_element(spec);
    } catch (const morph::input_error& error) {
      return std::string(error.what());
    }
    return std::string("(accepted)");
  };
  CHECK(message("sphere:r=1,level=8").find("sphere level must be an integer in 0..7") !=
        std::string::npos);
  // Found by fuzz_se_spec: n=4096 meant 16.7 million faces; now n^2 <= 262,144.
  CHECK(message("uvsphere:r=1,n=513").find("uvsphere n must be an integer in 3..512") !=
        std::string::npos);
  CHECK(message("cylinder:r=1,h=1,n=4097").find("cylinder n must be an integer in 3..4096") !=
        std::string::npos);
  CHECK(morph::make_structuring_element("cylinder:r=1,h=1,n=4096").n_faces() == 4098);
  // Found by fuzz_se_spec: at r=1e-100 every facet had zero area for validation.
  CHECK(message("sphere:r=1e-51").find("between 1e-50 and 1e50") != std::string::npos);
  for (const char* spec :
       {"sphere:r=1e-50", "cube:1e-50", "box:1e-50,2e-50,3e-50", "sphere:r=1e50"})
    CHECK_MESSAGE(morph::check_convex_polyhedron(morph::make_structuring_element(spec)).ok(),
                  std::string(spec));
}

TEST_CASE("fuzz corpora replay: readers and the SE parser throw only morph::error") {
  REQUIRE(fs::is_directory(kCorpus));
  int inputs = 0;
  for (const char* format : {"off", "obj", "ply", "stl"}) {
    for (const auto& entry : fs::directory_iterator(kCorpus / ("read_" + std::string(format)))) {
      std::istringstream in(read_bytes(entry.path()));
      CAPTURE(entry.path().string());
      try {
        morph::read_mesh(in, morph::format_from_name(format), entry.path().string());
      } catch (const morph::error&) {
      }
      ++inputs;
    }
  }
  for (const auto& entry : fs::directory_iterator(kCorpus / "se_spec")) {
    const std::string spec = read_bytes(entry.path());
    CAPTURE(spec);
    if (spec.find_first_of("/\\.") != std::string::npos) continue;  // as the fuzz target
    try {
      const morph::Mesh se = morph::make_structuring_element(spec);
      CHECK(morph::check_convex_polyhedron(se).ok());
    } catch (const morph::error&) {
    }
    ++inputs;
  }
  CHECK(inputs >= 10);
}
