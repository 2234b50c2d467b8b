#include "cli.h"

#include <morph/error.h>
#include <morph/validate.h>
#include <oneapi/tbb/global_control.h>
#include <oneapi/tbb/info.h>
#include <oneapi/tbb/task_arena.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <new>

namespace morph::cli {

// ---------------------------------------------------------------- messages

Reporter::Reporter(std::string program) : program_(std::move(program)) {}

void Reporter::emit(std::string_view line) {
  std::lock_guard lock(mutex_);
  std::string out;
  if (!progress_.empty()) out += "\r\033[K";
  out += line;
  out += '\n';
  out += progress_;
  std::fwrite(out.data(), 1, out.size(), stderr);
  std::fflush(stderr);
}

void Reporter::error(std::string_view file, std::string_view what, std::string_view hint) {
  std::string line = program_ + ": error: ";
  if (!file.empty()) line.append(file).append(": ");
  line += one_line(what);
  if (!hint.empty()) line.append(". ").append(hint);
  if (line.back() != '.') line += '.';
  emit(line);
}

void Reporter::warning(std::string_view file, std::string_view what) {
  if (quiet_) return;
  std::string line = program_ + ": warning: ";
  if (!file.empty()) line.append(file).append(": ");
  emit(line + one_line(what));
}

void Reporter::note(std::string_view file, std::string_view what) {
  if (!verbose_) return;
  std::string line = program_ + ": note: ";
  if (!file.empty()) line.append(file).append(": ");
  emit(line + one_line(what));
}

void Reporter::info(std::string_view text) {
  if (quiet_) return;
  emit(program_ + ": " + one_line(text));
}

void Reporter::raw(std::string_view text) { emit(text); }

void Reporter::show_progress(std::string line) {
  std::lock_guard lock(mutex_);
  progress_ = std::move(line);
  const std::string out = "\r\033[K" + progress_;
  std::fwrite(out.data(), 1, out.size(), stderr);
  std::fflush(stderr);
}

void Reporter::clear_progress() {
  std::lock_guard lock(mutex_);
  if (progress_.empty()) return;
  progress_.clear();
  std::fputs("\r\033[K", stderr);
  std::fflush(stderr);
}

std::string one_line(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (char c : text) {
    if (c == '\n' || c == '\r' || c == '\t') {
      if (!out.empty() && out.back() != ' ') out += ' ';
    } else {
      out += c;
    }
  }
  while (!out.empty() && out.back() == ' ') out.pop_back();
  return out;
}

// ---------------------------------------------------------------- errors

namespace {

std::string default_hint(int code, std::string_view program) {
  switch (code) {
    case kExitUsage:
      return "Run '" + std::string(program) + " --help' for usage";
    case kExitDataErr:
      return "Check that it is a valid OFF, OBJ, PLY or STL mesh";
    case kExitNoInput:
      return "Check that the path exists and is readable";
    case kExitInvalidMesh:
      return "Operands must be closed convex polyhedra with outward facets (see docs/cli.md, "
             "'Inputs')";
    case kExitCantCreate:
      return "Check that the directory exists and is writable";
    case kExitEmpty:
      return "The structuring element fits nowhere inside the input; use a smaller one, or drop "
             "--fail-on-empty";
    case kExitSoftware:
      return "This is a bug; please report it with the command line and input files";
    default:
      return "";
  }
}

// The library names the file in its messages; do not say it twice.
std::string without_file_prefix(std::string what, std::string_view file) {
  what = one_line(what);
  if (!file.empty() && what.size() > file.size() + 1 && what.compare(0, file.size(), file) == 0 &&
      what[file.size()] == ':') {
    const std::size_t start = what.find_first_not_of(' ', file.size() + 1);
    if (start != std::string::npos) what.erase(0, start);
  }
  while (!what.empty() && (what.back() == '.' || what.back() == ' ')) what.pop_back();
  return what;
}

}  // namespace

Failure make_failure(int code, std::string_view file, std::string_view what,
                     std::string_view program) {
  return Failure{code, std::string(file), without_file_prefix(std::string(what), file),
                 default_hint(code, program)};
}

Failure classify_current_exception(Stage stage, std::string_view file, std::string_view program) {
  int code = kExitSoftware;
  std::string what;
  try {
    throw;
  } catch (const std::bad_alloc&) {
    code = kExitSoftware;
    what = "out of memory";
  } catch (const invalid_mesh& e) {  // not_convex included
    code = kExitInvalidMesh;
    what = e.what();
  } catch (const io_error& e) {
    code = stage == Stage::write                                 ? kExitCantCreate
           : stage == Stage::compute || stage == Stage::validate ? kExitSoftware
                                                                 : kExitNoInput;
    what = e.what();
  } catch (const input_error& e) {  // limit_error included
    code = stage == Stage::usage || stage == Stage::structuring_element || stage == Stage::write
               ? kExitUsage
               : kExitDataErr;
    what = e.what();
  } catch (const std::exception& e) {
    code = kExitSoftware;
    what = std::string("internal error: ") + e.what();
  } catch (...) {
    code = kExitSoftware;
    what = "internal error: unknown exception";
  }
  if (stage == Stage::structuring_element && code == kExitUsage) {
    // The library appends the whole grammar on further lines; --help shows it.
    what = what.substr(0, what.find('\n'));
  }
  Failure failure = make_failure(code, file, what, program);
  if (code == kExitCantCreate && file == "<stdout>") {
    failure.hint = "Check that standard output is writable (a closed pipe, a full disk)";
  }
  if (stage == Stage::structuring_element && code == kExitUsage) {
    failure.hint = "Run '" + std::string(program) + " --help' for the structuring-element grammar";
  }
  return failure;
}

void report(Reporter& reporter, const Failure& failure) {
  reporter.error(failure.file, failure.what, failure.hint);
}

// ---------------------------------------------------------------- SIGINT

namespace {

std::atomic<bool> g_interrupted{false};
std::atomic<int> g_signal_count{0};
std::atomic<int> g_writes_in_progress{0};
std::atomic<int> g_mode{static_cast<int>(InterruptMode::immediate_when_safe)};
static_assert(std::atomic<int>::is_always_lock_free && std::atomic<bool>::is_always_lock_free,
              "the SIGINT handler needs lock-free atomics");

// Messages prepared before the signal: the handler may only call async-signal-safe
// functions (write, _exit).
char g_exit_message[256];
std::size_t g_exit_message_length = 0;
char g_graceful_message[256];
std::size_t g_graceful_message_length = 0;

void prepare_message(char* buffer, std::size_t& length, const std::string& text) {
  length = std::min(text.size(), std::size_t{255});
  std::memcpy(buffer, text.data(), length);
}

extern "C" void on_sigint(int) {
  const int saved_errno = errno;
  const int count = g_signal_count.fetch_add(1) + 1;
  g_interrupted.store(true);
  const bool immediate =
      g_mode.load() == static_cast<int>(InterruptMode::immediate_when_safe) || count >= 2;
  if (immediate && g_writes_in_progress.load() == 0) {
    [[maybe_unused]] ssize_t ignored =
        ::write(STDERR_FILENO, g_exit_message, g_exit_message_length);
    ::_exit(kExitInterrupted);
  }
  if (count == 1 && g_mode.load() == static_cast<int>(InterruptMode::graceful)) {
    [[maybe_unused]] ssize_t ignored =
        ::write(STDERR_FILENO, g_graceful_message, g_graceful_message_length);
  }
  errno = saved_errno;
}

}  // namespace

void install_interrupt_handler(std::string_view program, InterruptMode mode) {
  const std::string prefix = std::string("\n").append(program);
  prepare_message(g_exit_message, g_exit_message_length,
                  prefix + ": interrupted; no partial output was left\n");
  prepare_message(g_graceful_message, g_graceful_message_length,
                  prefix +
                      ": interrupted; finishing the files in progress, starting no new one (Ctrl-C "
                      "again to stop now)\n");
  g_mode.store(static_cast<int>(mode));
  struct sigaction action {};
  action.sa_handler = on_sigint;
  sigemptyset(&action.sa_mask);
  action.sa_flags = SA_RESTART;
  sigaction(SIGINT, &action, nullptr);
}

bool interrupted() { return g_interrupted.load(); }

WriteInProgress::WriteInProgress() { g_writes_in_progress.fetch_add(1); }
WriteInProgress::~WriteInProgress() { g_writes_in_progress.fetch_sub(1); }

// ---------------------------------------------------------------- threads

ThreadLimit::ThreadLimit(int threads) {
  const int all = tbb::info::default_concurrency();
  if (threads > 0) {
    control_ = std::make_shared<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                     static_cast<std::size_t>(threads));
    count_ = std::min(threads, all);
  } else {
    count_ = all;
  }
}

ThreadLimit::~ThreadLimit() = default;

// ---------------------------------------------------------------- mesh I/O

Mesh read_input(const std::string& path, std::optional<MeshFormat> format) {
  if (path == kStdStream) {
    if (!format)
      throw input_error("reading stdin needs --input-format (or --format) off|obj|ply|stl");
    return read_mesh(std::cin, *format, "<stdin>");
  }
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec))
    throw io_error(path + ": is a directory, not a mesh file");
  if (!format) return read_mesh(path);
  std::ifstream in(path, std::ios::binary);
  if (!in) throw io_error(path + ": cannot open: " + std::strerror(errno));
  return read_mesh(in, *format, path);
}

MeshFormat output_format_for(const std::string& path, std::optional<MeshFormat> explicit_format) {
  if (explicit_format) return *explicit_format;
  if (path == kStdStream)
    throw input_error("writing to stdout ('-o -') needs --format off|obj|ply|stl");
  const std::string ext = std::filesystem::path(path).extension().string();
  if (!has_mesh_extension(path)) {
    throw input_error("cannot tell the output format from the extension '" + ext +
                      "'; use .off, .obj, .ply or .stl, or give --format");
  }
  return format_from_path(path);
}

void write_output(const Mesh& mesh, const std::string& path, MeshFormat format,
                  const WriteOptions& options) {
  WriteInProgress writing;
  if (path == kStdStream) {
    write_mesh(mesh, std::cout, format, options);
    std::cout.flush();
    if (!std::cout) throw io_error("<stdout>: write failed");
    return;
  }
  WriteOptions with_format = options;
  with_format.format = format;
  write_mesh(mesh, path, with_format);
}

const char* format_name(MeshFormat format) {
  switch (format) {
    case MeshFormat::off:
      return "off";
    case MeshFormat::obj:
      return "obj";
    case MeshFormat::ply:
      return "ply";
    case MeshFormat::stl:
      return "stl";
  }
  return "?";
}

bool has_mesh_extension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return std::tolower(c); });
  return ext == ".off" || ext == ".obj" || ext == ".ply" || ext == ".stl";
}

// ---------------------------------------------------------------- facet labels

std::vector<Color> facet_colors(const std::vector<FacetOrigin>& origins) {
  std::vector<Color> colors;
  colors.reserve(origins.size());
  for (const FacetOrigin& origin : origins) {
    switch (origin.kind) {
      case FacetKind::translated:
        colors.push_back(kTranslatedColor);
        break;
      case FacetKind::corner:
        colors.push_back(kCornerColor);
        break;
      case FacetKind::edge:
        colors.push_back(kEdgeColor);
        break;
    }
  }
  return colors;
}

// ---------------------------------------------------------------- stats

void count_result(RunStats& stats, const Mesh& mesh, const std::vector<FacetOrigin>* origins) {
  stats.vertices = mesh.n_vertices();
  stats.edges = mesh.n_edges();
  stats.facets = mesh.n_faces();
  stats.volume = mesh.n_faces() > 0 ? signed_volume(mesh) : 0.0;
  stats.translated.reset();
  stats.corner.reset();
  stats.edge.reset();
  if (origins == nullptr) return;
  std::size_t counts[3] = {0, 0, 0};
  for (const FacetOrigin& origin : *origins) ++counts[static_cast<int>(origin.kind)];
  stats.translated = counts[static_cast<int>(FacetKind::translated)];
  stats.corner = counts[static_cast<int>(FacetKind::corner)];
  stats.edge = counts[static_cast<int>(FacetKind::edge)];
}

std::string json_string(std::string_view text) {
  std::string out = "\"";
  for (char c : text) {
    const unsigned char u = static_cast<unsigned char>(c);
    if (c == '"' || c == '\\') {
      out += '\\';
      out += c;
    } else if (u < 0x20) {
      char buffer[8];
      std::snprintf(buffer, sizeof buffer, "\\u%04x", u);
      out += buffer;
    } else {
      out += c;
    }
  }
  return out + "\"";
}

namespace {

std::string json_number(double value, const char* format) {
  if (!std::isfinite(value)) return "null";
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, format, value);
  return buffer;
}

std::string json_count(const std::optional<std::size_t>& count) {
  return count ? std::to_string(*count) : "null";
}

}  // namespace

std::string stats_json(const RunStats& s) {
  std::string out = "{";
  out += "\"op\":" + json_string(s.op);
  out += ",\"input\":" + json_string(s.input);
  out += ",\"output\":" + (s.output.empty() ? std::string("null") : json_string(s.output));
  out += ",\"vertices\":" + std::to_string(s.vertices);
  out += ",\"edges\":" + std::to_string(s.edges);
  out += ",\"facets\":" + std::to_string(s.facets);
  out += ",\"translated\":" + json_count(s.translated);
  out += ",\"corner\":" + json_count(s.corner);
  out += ",\"edge\":" + json_count(s.edge);
  out += std::string(",\"empty\":") + (s.empty ? "true" : "false");
  out += ",\"empty_reason\":" + json_string(s.empty_reason);
  out += ",\"volume\":" + json_number(s.volume, "%.17g");
  out += ",\"read_ms\":" + json_number(s.read_ms, "%.3f");
  out += ",\"validate_ms\":" + json_number(s.validate_ms, "%.3f");
  out += ",\"compute_ms\":" + json_number(s.compute_ms, "%.3f");
  out += ",\"write_ms\":" + json_number(s.write_ms, "%.3f");
  out += ",\"threads\":" + std::to_string(s.threads);
  return out + "}";
}

}  // namespace morph::cli
