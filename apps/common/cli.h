// Shared plumbing of the libmorph apps: messages on stderr, error → exit-code mapping,
// SIGINT handling, thread cap, mesh input/output (files or stdin/stdout), facet
// colours and the --stats JSON line.
#pragma once

#include <morph/io.h>
#include <morph/minkowski_sum.h>

#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "exit_codes.h"

namespace morph::cli {

// ---------------------------------------------------------------- messages

/// Prints one-line messages on stderr as "<program>: <kind>: <file>: <text>", from any
/// thread. When a progress bar is shown, messages are printed above it.
class Reporter {
 public:
  explicit Reporter(std::string program);

  const std::string& program() const { return program_; }
  bool quiet() const { return quiet_; }
  bool verbose() const { return verbose_; }
  void set_quiet(bool quiet) { quiet_ = quiet; }
  void set_verbose(bool verbose) { verbose_ = verbose; }

  /// "prog: error: file: what. hint" (always printed). `file` may be empty.
  void error(std::string_view file, std::string_view what, std::string_view hint);
  /// "prog: warning: file: what" (not with --quiet).
  void warning(std::string_view file, std::string_view what);
  /// "prog: note: file: what" (only with --verbose).
  void note(std::string_view file, std::string_view what);
  /// "prog: text" (not with --quiet).
  void info(std::string_view text);
  /// The text as it is (the --stats JSON line): printed even with --quiet.
  void raw(std::string_view text);

  /// Shows (or replaces) a one-line progress bar at the bottom of the terminal.
  void show_progress(std::string line);
  /// Removes the progress bar.
  void clear_progress();

 private:
  void emit(std::string_view line);

  std::string program_;
  bool quiet_ = false;
  bool verbose_ = false;
  std::mutex mutex_;
  std::string progress_;  // the bar currently shown, empty if none
};

/// Replaces newlines and tabs by spaces, so that a library message fits on one line.
std::string one_line(std::string_view text);

// ---------------------------------------------------------------- errors

/// Where in the work an exception was thrown: the same exception type means a
/// different exit status at a different stage (an io_error reading is 66, writing 73).
enum class Stage { usage, structuring_element, read, validate, compute, write };

/// A failure ready to print and to return as the exit status.
struct Failure {
  int code = kExitSoftware;
  std::string file;  // what it is about: a file name, "--se SPEC", a pipeline line
  std::string what;  // one line, without a final full stop
  std::string hint;  // what to do, one sentence
};

/// Classifies the exception being handled (call inside a catch block) thrown at
/// `stage` while working on `file`. `program` is used in hints ("run 'prog --help'").
Failure classify_current_exception(Stage stage, std::string_view file, std::string_view program);

/// A failure of the given code with the standard hint for it.
Failure make_failure(int code, std::string_view file, std::string_view what,
                     std::string_view program);

/// Prints a failure through the reporter as one error line.
void report(Reporter& reporter, const Failure& failure);

// ---------------------------------------------------------------- SIGINT

enum class InterruptMode {
  /// Single-file apps: exit 130 at once, unless a file is being written; then the
  /// write finishes (it is atomic) and the app exits 130 after it.
  immediate_when_safe,
  /// Batches: the first Ctrl-C lets the files in progress finish and starts no new
  /// one; a second Ctrl-C exits at once when no file is being written.
  graceful,
};

/// Installs the SIGINT handler (once per process).
void install_interrupt_handler(std::string_view program, InterruptMode mode);

/// True once SIGINT has been received.
bool interrupted();

/// Marks a file write in progress, so that the SIGINT handler does not exit under it.
class WriteInProgress {
 public:
  WriteInProgress();
  ~WriteInProgress();
  WriteInProgress(const WriteInProgress&) = delete;
  WriteInProgress& operator=(const WriteInProgress&) = delete;
};

// ---------------------------------------------------------------- threads

/// Caps TBB's parallelism for the life of the object (tbb::global_control).
class ThreadLimit {
 public:
  /// `threads` <= 0: all cores.
  explicit ThreadLimit(int threads);
  ~ThreadLimit();
  /// The number of threads in effect.
  int count() const { return count_; }

 private:
  std::shared_ptr<void> control_;
  int count_ = 1;
};

// ---------------------------------------------------------------- mesh I/O

/// "-" names stdin (for input) or stdout (for output).
inline constexpr std::string_view kStdStream = "-";

/// Reads the input mesh: a file ("-" is stdin, which needs `format`). With `format`
/// given, a file is read as that format whatever its extension.
/// Throws like morph::read_mesh (io_error, input_error).
Mesh read_input(const std::string& path, std::optional<MeshFormat> format);

/// The format to write `path` in: `explicit_format` if given, else the extension's.
/// Throws input_error when neither tells (stdout without --format, unknown extension).
MeshFormat output_format_for(const std::string& path, std::optional<MeshFormat> explicit_format);

/// Writes `mesh` to `path` ("-" is stdout) atomically, marked as a write in progress
/// for the SIGINT handler. Throws io_error when it cannot be written.
void write_output(const Mesh& mesh, const std::string& path, MeshFormat format,
                  const WriteOptions& options);

/// The lower-case name of a format ("off", ...).
const char* format_name(MeshFormat format);

/// True for the file extensions the readers know (.off .obj .ply .stl, any case).
bool has_mesh_extension(const std::string& path);

// ---------------------------------------------------------------- facet labels

/// The fixed palette of --label-facets (docs/cli.md), colour-blind safe (Okabe-Ito).
inline constexpr Color kTranslatedColor = {0, 114, 178};  // blue: translated facets of A
inline constexpr Color kCornerColor = {230, 159, 0};      // orange: corner facets (from B)
inline constexpr Color kEdgeColor = {0, 158, 115};        // green: edge facets (parallelograms)

/// One colour per facet origin.
std::vector<Color> facet_colors(const std::vector<FacetOrigin>& origins);

// ---------------------------------------------------------------- stats

/// What --stats reports about one run.
struct RunStats {
  std::string op;  // "dilate", ..., or the pipeline ("open sphere:r=1 | close cube:1")
  std::string input;
  std::string output;  // empty when nothing is written
  std::size_t vertices = 0;
  std::size_t edges = 0;
  std::size_t facets = 0;
  // Facet counts by origin; absent when the result has no origins (no operation).
  std::optional<std::size_t> translated, corner, edge;
  bool empty = false;
  std::string empty_reason = "none";  // "none", "empty" or "flat"
  double volume = 0;
  double read_ms = 0;      // reading the input
  double validate_ms = 0;  // checking it is a convex polyhedron
  double compute_ms = 0;   // the operations alone
  double write_ms = 0;     // writing the output
  int threads = 1;
};

/// Fills vertices, edges, facets, volume and the counts by origin from a result.
void count_result(RunStats& stats, const Mesh& mesh, const std::vector<FacetOrigin>* origins);

/// The stats as one line of JSON (no newline).
std::string stats_json(const RunStats& stats);

/// Escapes a string for JSON, with the quotes.
std::string json_string(std::string_view text);

}  // namespace morph::cli
