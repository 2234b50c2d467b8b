#include "job.h"

#include <morph/error.h>
#include <morph/morphology.h>
#include <morph/structuring_element.h>
#include <morph/validate.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <mutex>
#include <stdexcept>

namespace morph::cli {
namespace {

class Stopwatch {
 public:
  double ms() const {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start_)
        .count();
  }
  void restart() { start_ = std::chrono::steady_clock::now(); }

 private:
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
};

MorphResult apply(Op op, const Mesh& a, const Mesh& b, const MorphologyOptions& options) {
  switch (op) {
    case Op::dilate:
      return dilate(a, b, options);
    case Op::erode:
      return erode(a, b, options);
    case Op::open:
      return open(a, b, options);
    case Op::close:
      return close(a, b, options);
  }
  throw std::logic_error("unknown operation");
}

const char* empty_reason_name(EmptyReason reason) {
  switch (reason) {
    case EmptyReason::none:
      return "none";
    case EmptyReason::empty:
      return "empty";
    case EmptyReason::flat:
      return "flat";
  }
  return "?";
}

std::string describe_mesh(const Mesh& mesh) {
  char volume[64];
  std::snprintf(volume, sizeof volume, "%.9g", mesh.n_faces() > 0 ? signed_volume(mesh) : 0.0);
  return std::to_string(mesh.n_vertices()) + " vertices, " + std::to_string(mesh.n_edges()) +
         " edges, " + std::to_string(mesh.n_faces()) + " facets, volume " + volume;
}

// Warnings about options that cannot take effect, said once per process (not once per
// file of a batch).
std::once_flag g_warned_labels_format;
std::once_flag g_warned_labels_erosion;
std::once_flag g_warned_binary;

}  // namespace

std::optional<Failure> prepare_steps(const std::vector<PipelineStep>& steps, Reporter& reporter,
                                     std::vector<PreparedStep>& prepared) {
  prepared.clear();
  for (const PipelineStep& step : steps) {
    std::error_code ec;
    const bool is_file = std::filesystem::is_regular_file(step.se_spec, ec);
    // Name the file when the element is one; else the place the spec came from.
    const std::string about =
        is_file ? (step.where == "--se" ? step.se_spec : step.where + ": " + step.se_spec)
                : step.where;
    Stage stage = is_file ? Stage::read : Stage::structuring_element;
    try {
      Mesh se = make_structuring_element(step.se_spec);
      stage = Stage::validate;
      PreparedMesh checked =
          prepare_convex_polyhedron(se, is_file ? step.se_spec : "structuring element");
      for (const std::string& note : checked.notes) reporter.note(about, note);
      reporter.note(about,
                    "structuring element '" + step.se_spec + "': " + describe_mesh(checked.mesh));
      prepared.push_back(PreparedStep{step, std::move(checked.mesh)});
    } catch (...) {
      return classify_current_exception(stage, about, reporter.program());
    }
  }
  return std::nullopt;
}

const char* status_name(JobStatus status) {
  switch (status) {
    case JobStatus::ok:
      return "ok";
    case JobStatus::empty:
      return "empty";
    case JobStatus::failed:
      return "failed";
    case JobStatus::skipped:
      return "skipped";
  }
  return "?";
}

JobResult run_job(const Job& job, const JobSettings& settings, Reporter& reporter) {
  JobResult result;
  RunStats& stats = result.stats;
  stats.op = settings.op_label;
  stats.input = job.input;
  stats.output = job.output;
  stats.threads = settings.threads;
  const std::string name = job.input == kStdStream ? "<stdin>" : job.input;
  const std::string output_name = job.output == kStdStream ? "<stdout>" : job.output;

  Stage stage = Stage::usage;
  std::string about = name;
  try {
    // Formats are checked first: a missing --format or a bad extension fails before any work.
    if (job.input == kStdStream && !settings.stdin_format) {
      throw input_error("reading stdin needs --input-format (or --format) off|obj|ply|stl");
    }
    about = output_name;
    std::optional<MeshFormat> output_format;
    if (!job.output.empty()) output_format = output_format_for(job.output, settings.output_format);

    stage = Stage::read;
    about = name;
    Stopwatch watch;
    const Mesh input = read_input(
        job.input, job.input == kStdStream ? settings.stdin_format : settings.input_format);
    stats.read_ms = watch.ms();

    stage = Stage::validate;
    watch.restart();
    PreparedMesh prepared = prepare_convex_polyhedron(input, name);
    stats.validate_ms = watch.ms();
    for (const std::string& note : prepared.notes) reporter.note(name, note);
    reporter.note(name, "valid convex polyhedron: " + describe_mesh(prepared.mesh));

    stage = Stage::compute;
    Mesh current = std::move(prepared.mesh);
    std::vector<FacetOrigin> origins;
    bool has_origins = false;
    EmptyReason empty_reason = EmptyReason::none;
    std::string empty_message;
    MorphologyOptions options;
    options.threads = settings.threads;
    for (std::size_t i = 0; i < settings.steps.size(); ++i) {
      const PreparedStep& step = settings.steps[i];
      watch.restart();
      MorphResult step_result = apply(step.step.op, current, step.se, options);
      const double step_ms = watch.ms();
      stats.compute_ms += step_ms;
      const std::string label = std::string(op_name(step.step.op)) + " " + step.step.se_spec;
      if (step_result.is_empty()) {
        empty_reason = step_result.empty_reason;
        empty_message =
            step_result.message.empty() ? "the result has no interior" : step_result.message;
        current = Mesh();
        origins.clear();
        has_origins = false;
        if (i + 1 < settings.steps.size()) {
          reporter.note(
              name, "the result is empty after '" + label + "'; the remaining steps are skipped");
        }
        break;
      }
      current = std::move(step_result.mesh);
      origins = std::move(step_result.origins);
      // Every operation labels every facet (MorphResult::origins).
      has_origins = !origins.empty();
      if (has_origins && origins.size() != current.n_faces()) {
        throw std::logic_error("'" + label + "' returned " + std::to_string(origins.size()) +
                               " facet origins for " + std::to_string(current.n_faces()) +
                               " facets");
      }
      char ms[32];
      std::snprintf(ms, sizeof ms, "%.3f", step_ms);
      reporter.note(name, "after '" + label + "': " + describe_mesh(current) + " (" + ms + " ms)");
    }
    count_result(stats, current, has_origins ? &origins : nullptr);
    stats.empty = empty_reason != EmptyReason::none;
    stats.empty_reason = empty_reason_name(empty_reason);

    if (stats.empty) {
      result.message = "the result is empty: " + one_line(empty_message);
      if (settings.fail_on_empty) {
        result.status = JobStatus::failed;
        result.failure = make_failure(kExitEmpty, name, result.message, reporter.program());
        result.exit_code = kExitEmpty;
        stats.output.clear();
        if (settings.stats) reporter.raw(stats_json(stats));
        return result;
      }
      reporter.warning(name,
                       result.message + (job.output.empty() ? "" : "; writing an empty mesh"));
    }

    if (!job.output.empty()) {
      stage = Stage::write;
      about = output_name;
      WriteOptions write_options;
      const bool binary_format =
          *output_format == MeshFormat::ply || *output_format == MeshFormat::stl;
      write_options.binary = settings.binary && binary_format;
      if (settings.binary && !binary_format) {
        std::call_once(g_warned_binary, [&] {
          reporter.warning(output_name, std::string("--binary has no effect on ") +
                                            format_name(*output_format) +
                                            " (only PLY and STL have a binary variant)");
        });
      }
      if (settings.label_facets) {
        const bool colour_format =
            *output_format == MeshFormat::ply || *output_format == MeshFormat::off;
        if (!colour_format) {
          std::call_once(g_warned_labels_format, [&] {
            reporter.warning(output_name,
                             std::string("--label-facets: ") + format_name(*output_format) +
                                 " has no face colours; write PLY or OFF to keep the labels");
          });
        } else if (has_origins) {
          write_options.face_colors = facet_colors(origins);
        } else if (!stats.empty) {
          std::call_once(g_warned_labels_erosion, [&] {
            reporter.warning(
                output_name,
                "--label-facets: the result of no operation has no facet origins; no colours "
                "written");
          });
        }
      }
      watch.restart();
      write_output(current, job.output, *output_format, write_options);
      stats.write_ms = watch.ms();
      reporter.note(
          name, "wrote " + output_name + " (" + format_name(*output_format) +
                    (write_options.binary ? ", binary" : "") +
                    (write_options.face_colors.empty() ? "" : ", facets coloured by origin") + ")");
    }
    result.status = stats.empty ? JobStatus::empty : JobStatus::ok;
    result.exit_code = kExitOk;
    if (settings.stats) reporter.raw(stats_json(stats));
  } catch (...) {
    result.failure = classify_current_exception(stage, about, reporter.program());
    result.status = JobStatus::failed;
    result.exit_code = result.failure->code;
    result.message = result.failure->what;
  }
  return result;
}

int exit_code_after(const JobResult& result) {
  return interrupted() ? static_cast<int>(kExitInterrupted) : result.exit_code;
}

}  // namespace morph::cli
