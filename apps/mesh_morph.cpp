// mesh-morph: chains of operations (--op, --pipeline), mesh checking and conversion,
// and batches of many inputs processed in parallel.
#include <morph/error.h>
#include <morph/version.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <map>
#include <sstream>

#include "common/allocator.h"
#include "common/batch.h"
#include "common/cli.h"
#include "common/job.h"
#include "common/options.h"
#include "common/pipeline.h"

namespace fs = std::filesystem;
using namespace morph::cli;

namespace {

constexpr const char* kProgram = "mesh-morph";
constexpr std::uintmax_t kMaxPipelineFileBytes = 1 << 20;

std::string usage(const po::options_description& visible) {
  std::ostringstream out;
  out << "Usage: mesh-morph INPUT [-o OUTPUT] [--op \"OP SPEC\"]... [options]\n"
      << "       mesh-morph INPUT [-o OUTPUT] --pipeline FILE [options]\n"
      << "       mesh-morph INPUT... | DIR | --list FILE  --output-dir DIR [--report CSV] "
         "[options]\n\n"
      << "Runs a chain of morphological operations on a convex polyhedron in one process: each "
         "--op\n"
      << "(or each line of a pipeline file) is OP SPEC, OP one of dilate, erode, open, close and "
         "SPEC a\n"
      << "structuring element. With no operation it checks that INPUT is a closed convex "
         "polyhedron\n"
      << "(exit 0 if so, 3 if not) and converts it when -o is given; -v prints a summary line.\n"
      << "An empty result stops the chain; an empty mesh is written, with a warning.\n\n"
      << "Several INPUTs, a directory (its .off .obj .ply .stl files) or --list make a batch: the "
         "files\n"
      << "are processed in parallel, results go to --output-dir named after the inputs, one bad "
         "file\n"
      << "never stops the others (exit 1, the summary names the failures). Ctrl-C lets the files "
         "in\n"
      << "progress finish, starts no new one, and exits 130; no partial file is left.\n\n"
      << visible << "\n"
      << "Pipeline files: one step 'OP SPEC' per line; '#' starts a comment (at the start of a "
         "line or\n"
      << "after a space); blank lines are ignored. Example (samples/pipelines/clean.morph):\n"
      << "  # remove spikes, then fill dents\n"
      << "  open  sphere:r=0.05,level=2\n"
      << "  close box:0.1,0.1,0.1\n\n"
      << se_grammar_help() << "\n"
      << label_palette_help() << "\n"
      << "Examples:\n"
      << "  mesh-morph part.off -v                                    check a mesh, print a "
         "summary\n"
      << "  mesh-morph part.stl -o part.ply --binary                  convert\n"
      << "  mesh-morph in.off -o out.ply --op \"open sphere:r=0.05,level=2\" --op \"close "
         "box:0.1,0.1,0.1\"\n"
      << "  mesh-morph in.off -o out.ply --pipeline samples/pipelines/clean.morph --stats\n"
      << "  mesh-morph meshes/ --output-dir out/ --format ply --op \"dilate cube:0.1\" --report "
         "results.csv\n"
      << "  mesh-morph --list inputs.txt --output-dir out/ --pipeline clean.morph --threads 8\n\n"
      << kExitCodeHelp;
  return out.str();
}

std::vector<PipelineStep> read_pipeline_file(const std::string& path) {
  std::error_code ec;
  if (fs::is_directory(path, ec))
    throw morph::io_error(path + ": is a directory, not a pipeline file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw morph::io_error(path + ": cannot open the pipeline file: " + std::strerror(errno));
  const std::uintmax_t size = fs::file_size(path, ec);
  if (!ec && size > kMaxPipelineFileBytes) {
    throw morph::input_error(path + ": pipeline file larger than 1 MiB");
  }
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw morph::io_error(path + ": cannot read the pipeline file");
  return parse_pipeline(text, path);
}

int fail(Reporter& reporter, const Failure& failure) {
  report(reporter, failure);
  return failure.code;
}

int usage_error(Reporter& reporter, const std::string& what) {
  return fail(reporter, make_failure(kExitUsage, "", what, kProgram));
}

// The same file reached by two paths must not be written twice by a batch, nor may a
// batch replace one of its inputs.
std::string identity(const std::string& path) {
  std::error_code ec;
  const fs::path canonical = fs::weakly_canonical(path, ec);
  return ec ? fs::absolute(path).lexically_normal().string() : canonical.string();
}

int run(int argc, const char* const argv[], Reporter& reporter) {
  CommonOptions common;
  std::vector<std::string> inputs;
  std::vector<std::string> ops;
  std::string pipeline_file;
  std::string output_dir;
  std::string list_file;
  std::string report_file;

  po::options_description operations("Operations");
  // clang-format off
  operations.add_options()
    ("op", po::value(&ops)->value_name("\"OP SPEC\"")->composing(),
     "an operation: dilate|erode|open|close and a structuring element, e.g. \"open sphere:r=0.1\"; "
     "repeat to chain, applied in order")
    ("pipeline", po::value(&pipeline_file)->value_name("FILE"), "run the steps of a pipeline file (instead of --op)");
  po::options_description batch("Batch");
  batch.add_options()
    ("output-dir", po::value(&output_dir)->value_name("DIR"),
     "write each input's result to DIR/<input name>.<ext> (created if missing); ext from --format, "
     "else the input's")
    ("list", po::value(&list_file)->value_name("FILE"), "read input paths from FILE, one per line ('#' comments)")
    ("report", po::value(&report_file)->value_name("CSV"),
     "write a CSV report: file,status,vertices,facets,compute_ms,message");
  // clang-format on
  po::options_description output("Output");
  po::options_description general("General");
  add_common_options(output, general, common);
  po::options_description hidden;
  hidden.add_options()("input", po::value(&inputs)->composing());
  po::options_description visible;
  visible.add(operations).add(batch).add(output).add(general);
  po::options_description all;
  all.add(visible).add(hidden);
  po::positional_options_description positional;
  positional.add("input", -1);

  po::variables_map vm;
  try {
    parse_command_line(argc, argv, all, positional, vm);
  } catch (const po::error& e) {
    return usage_error(reporter, e.what());
  }
  if (common.help) {
    std::cout << usage(visible);
    return kExitOk;
  }
  if (common.version) {
    std::cout << kProgram << " (libmorph) " << morph::kVersion << "\n";
    return kExitOk;
  }
  reporter.set_quiet(common.quiet);
  reporter.set_verbose(common.verbose);

  // The steps.
  if (!ops.empty() && !pipeline_file.empty())
    return usage_error(reporter, "give either --op or --pipeline, not both");
  std::vector<PipelineStep> steps;
  try {
    if (!pipeline_file.empty()) {
      steps = read_pipeline_file(pipeline_file);
    } else {
      for (std::size_t i = 0; i < ops.size(); ++i) {
        steps.push_back(parse_step(ops[i], "--op " + std::to_string(i + 1)));
      }
    }
  } catch (...) {
    return fail(reporter, classify_current_exception(Stage::usage, "", kProgram));
  }

  // The inputs.
  if (!list_file.empty()) {
    try {
      const std::vector<std::string> listed = read_list_file(list_file);
      inputs.insert(inputs.end(), listed.begin(), listed.end());
    } catch (...) {
      return fail(reporter, classify_current_exception(Stage::read, list_file, kProgram));
    }
  }
  if (inputs.empty()) {
    return usage_error(reporter, list_file.empty()
                                     ? "missing INPUT (a mesh file, a directory, or '-' for stdin)"
                                     : list_file + " lists no input");
  }
  bool batch_mode =
      !output_dir.empty() || !list_file.empty() || !report_file.empty() || inputs.size() > 1;
  std::vector<std::string> files;
  for (const std::string& input : inputs) {
    std::error_code ec;
    if (input != kStdStream && fs::is_directory(input, ec)) {
      batch_mode = true;
      try {
        const std::vector<std::string> found = list_directory_meshes(input);
        if (found.empty()) {
          return fail(reporter,
                      make_failure(kExitNoInput, input,
                                   "no .off, .obj, .ply or .stl file in the directory", kProgram));
        }
        files.insert(files.end(), found.begin(), found.end());
      } catch (...) {
        return fail(reporter, classify_current_exception(Stage::read, input, kProgram));
      }
    } else {
      files.push_back(input);
    }
  }

  const ThreadLimit threads(common.threads);
  JobSettings settings;
  if (std::optional<Failure> failure = apply_common_options(common, threads, reporter, settings)) {
    return fail(reporter, *failure);
  }
  settings.op_label = steps.empty() ? "check" : describe_steps(steps);

  if (!batch_mode) {
    if (std::optional<Failure> failure = prepare_steps(steps, reporter, settings.steps))
      return fail(reporter, *failure);
    install_interrupt_handler(kProgram, InterruptMode::immediate_when_safe);
    if (!steps.empty() && common.output.empty()) {
      reporter.warning("", "no -o OUTPUT given: the result is computed but not written");
    }
    const JobResult result = run_job(Job{files.front(), common.output}, settings, reporter);
    if (result.failure) report(reporter, *result.failure);
    return exit_code_after(result);
  }

  // Batch: check everything that concerns the whole batch before any work.
  if (!common.output.empty()) {
    return usage_error(
        reporter,
        "-o names one output; with several inputs, a directory or --list use --output-dir DIR");
  }
  std::vector<Job> jobs;
  std::map<std::string, std::string> output_owner;  // output identity -> the input writing it
  std::map<std::string, std::string> input_identities;
  for (const std::string& file : files) {
    if (file == kStdStream) return usage_error(reporter, "stdin ('-') cannot be part of a batch");
    input_identities.emplace(identity(file), file);
  }
  for (const std::string& file : files) {
    Job job{file, ""};
    if (!output_dir.empty()) {
      job.output = batch_output_path(file, output_dir, settings.output_format);
      const std::string id = identity(job.output);
      const auto [it, inserted] = output_owner.emplace(id, file);
      if (!inserted) {
        return usage_error(reporter, "'" + it->second + "' and '" + file +
                                         "' would both be written to '" + job.output +
                                         "'; rename one, or use another --format");
      }
      if (const auto in = input_identities.find(id); in != input_identities.end()) {
        return usage_error(reporter, "the result of '" + file + "' would overwrite the input '" +
                                         in->second + "'; choose another --output-dir");
      }
    }
    jobs.push_back(std::move(job));
  }
  if (!report_file.empty()) {
    const fs::path parent =
        fs::path(report_file).has_parent_path() ? fs::path(report_file).parent_path() : ".";
    std::error_code ec;
    if (!fs::is_directory(parent, ec)) {
      return fail(reporter, make_failure(kExitCantCreate, report_file,
                                         "the report's directory does not exist", kProgram));
    }
  }
  if (!output_dir.empty()) {
    std::error_code ec;
    fs::create_directories(output_dir, ec);
    if (ec || !fs::is_directory(output_dir)) {
      return fail(reporter, make_failure(kExitCantCreate, output_dir,
                                         "cannot create the output directory" +
                                             (ec ? ": " + ec.message() : ""),
                                         kProgram));
    }
  } else if (!steps.empty()) {
    reporter.warning("", "no --output-dir given: the results are computed but not written");
  }
  if (std::optional<Failure> failure = prepare_steps(steps, reporter, settings.steps))
    return fail(reporter, *failure);

  install_interrupt_handler(kProgram, InterruptMode::graceful);
  const bool progress = !common.quiet && ::isatty(STDERR_FILENO) == 1;
  const std::vector<JobResult> results = run_batch(jobs, settings, reporter, progress);
  int code = batch_exit_code(results);
  const std::string summary = batch_summary(jobs, results);
  if (code == kExitOk) {
    reporter.info(summary);
  } else {
    reporter.raw(std::string(kProgram) + ": " + summary);
  }
  if (!report_file.empty()) {
    try {
      write_report(report_file, jobs, results);
      reporter.note(report_file, "report written");
    } catch (...) {
      const Failure failure = classify_current_exception(Stage::write, report_file, kProgram);
      report(reporter, failure);
      if (code != kExitInterrupted) code = failure.code;
    }
  }
  return code;
}

}  // namespace

int main(int argc, char* argv[]) {
  keep_freed_memory();
  Reporter reporter(kProgram);
  try {
    return run(argc, argv, reporter);
  } catch (...) {
    report(reporter, classify_current_exception(Stage::compute, "", kProgram));
    return kExitSoftware;
  }
}
