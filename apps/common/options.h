// Command-line options shared by the apps, on Boost.Program_options.
#pragma once

#include <boost/program_options.hpp>
#include <optional>
#include <string>
#include <vector>

#include "cli.h"
#include "job.h"
#include "pipeline.h"

namespace morph::cli {

namespace po = boost::program_options;

/// The options every app has (output, formats, threads, labels, messages).
struct CommonOptions {
  std::string output;        // -o/--output: a file, or "-" for stdout
  std::string format;        // --format: output format (and stdin's, without --input-format)
  std::string input_format;  // --input-format: read the input(s) as this format
  bool binary = false;
  bool label_facets = false;
  bool stats = false;
  bool fail_on_empty = false;
  bool quiet = false;
  bool verbose = false;
  int threads = 0;  // 0: all cores
  bool help = false;
  bool version = false;
};

/// Adds -o, --format, --input-format, --binary, --label-facets, --fail-on-empty and
/// --threads to `output`, and --stats, -q, -v, --help, --version to `general`.
void add_common_options(po::options_description& output, po::options_description& general,
                        CommonOptions& options);

/// Parses the command line into `vm` and notifies. Throws po::error on bad options.
void parse_command_line(int argc, const char* const argv[], const po::options_description& all,
                        const po::positional_options_description& positional,
                        po::variables_map& vm);

/// Checks the common options and fills the input-independent part of `settings`
/// (formats, flags, thread count). Returns a usage failure for bad values.
std::optional<Failure> apply_common_options(const CommonOptions& options,
                                            const ThreadLimit& threads, Reporter& reporter,
                                            JobSettings& settings);

/// The help text sections shared by the apps: structuring-element grammar, palette,
/// exit codes.
std::string se_grammar_help();
std::string label_palette_help();

/// Runs mesh-dilate, mesh-erode, mesh-open or mesh-close: the whole main().
int run_operation_app(int argc, const char* const argv[], Op op);

}  // namespace morph::cli
