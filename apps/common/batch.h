// Batches: many inputs, processed in parallel, one bad file never stopping the others.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "job.h"

namespace morph::cli {

/// The mesh files (.off .obj .ply .stl, any case) directly in `dir`, sorted by name.
/// Throws io_error when the directory cannot be read.
std::vector<std::string> list_directory_meshes(const std::string& dir);

/// The paths in a list file: one per line, blank lines and lines starting with '#'
/// skipped, surrounding whitespace trimmed; relative paths are taken as they are
/// (relative to the current directory). Throws io_error when it cannot be read.
std::vector<std::string> read_list_file(const std::string& path);

/// Where a batch writes the result of `input`: `output_dir`/<input's stem>.<ext>, with
/// ext the name of `format` if given, else the input's own extension.
std::string batch_output_path(const std::string& input, const std::string& output_dir,
                              std::optional<MeshFormat> format);

/// Runs the jobs in parallel (TBB, one task per file). After a SIGINT no new job is
/// started (those are `skipped`); jobs in progress finish. Prints one line per file
/// (ok/empty on stderr unless --quiet, failures always) and, when `progress_bar`, a
/// progress bar kept at the bottom of the terminal.
std::vector<JobResult> run_batch(const std::vector<Job>& jobs, const JobSettings& settings,
                                 Reporter& reporter, bool progress_bar);

/// The closing line: counts by status and the names of the failed inputs.
std::string batch_summary(const std::vector<Job>& jobs, const std::vector<JobResult>& results);

/// 130 if SIGINT was received or any job skipped, else 1 if any failed, else 0.
int batch_exit_code(const std::vector<JobResult>& results);

/// Writes the CSV report (columns file,status,vertices,facets,compute_ms,message)
/// atomically: a temporary file beside `path`, then a rename. Throws io_error.
void write_report(const std::string& path, const std::vector<Job>& jobs,
                  const std::vector<JobResult>& results);

/// One CSV field, quoted when it holds a comma, a quote or a line break.
std::string csv_field(std::string_view text);

}  // namespace morph::cli
