// One unit of work of every app: read one input, check it, run the chain of operations,
// write the result. Single-file apps run one job; a batch runs one per input file.
#pragma once

#include <morph/mesh.h>

#include <optional>
#include <string>
#include <vector>

#include "cli.h"
#include "pipeline.h"

namespace morph::cli {

/// A pipeline step with its structuring element built and checked.
struct PreparedStep {
  PipelineStep step;
  Mesh se;
};

/// Builds and checks the structuring element of every step. A spec naming an existing
/// file is read as a mesh (its errors are those of an input file: 65, 66, 3); any other
/// bad spec is a usage error (64). Throws nothing: returns the failure instead.
/// Notes (e.g. an inverted SE file flipped) go to the reporter with --verbose.
std::optional<Failure> prepare_steps(const std::vector<PipelineStep>& steps, Reporter& reporter,
                                     std::vector<PreparedStep>& prepared);

/// Everything about how to run jobs that does not depend on the input.
struct JobSettings {
  std::vector<PreparedStep> steps;          // empty: check and convert only
  std::string op_label;                     // for --stats "op"
  std::optional<MeshFormat> input_format;   // --input-format: read every input as this format
  std::optional<MeshFormat> stdin_format;   // --input-format, else --format: the format of stdin
  std::optional<MeshFormat> output_format;  // --format: overrides the output's extension
  bool binary = false;                      // --binary (PLY, STL)
  bool label_facets = false;                // --label-facets
  bool fail_on_empty = false;               // --fail-on-empty
  bool stats = false;                       // --stats: print the JSON line
  int threads = 1;                          // in effect (for stats; the cap is a ThreadLimit)
};

/// One input and where its result goes ("" means nowhere, "-" is stdout).
struct Job {
  std::string input;
  std::string output;
};

enum class JobStatus { ok, empty, failed, skipped };

const char* status_name(JobStatus status);

struct JobResult {
  JobStatus status = JobStatus::failed;
  int exit_code = kExitSoftware;   // 0, 4, or the failure's code
  std::optional<Failure> failure;  // set when status is failed
  std::string message;             // why empty, or the failure on one line
  RunStats stats;
};

/// Runs one job; never throws. Prints notes (-v), the empty-result warning and the
/// --stats line through `reporter`; does NOT print the failure (the caller decides how).
/// When the result is empty and fail_on_empty is set, nothing is written and the exit
/// code is 4.
JobResult run_job(const Job& job, const JobSettings& settings, Reporter& reporter);

/// The exit status of a single-file run: 130 when SIGINT came during the (completed,
/// atomic) write, else the job's own.
int exit_code_after(const JobResult& result);

}  // namespace morph::cli
