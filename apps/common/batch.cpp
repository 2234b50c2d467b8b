#include "batch.h"

#include <morph/error.h>
#include <oneapi/tbb/blocked_range.h>
#include <oneapi/tbb/parallel_for.h>
#include <oneapi/tbb/partitioner.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace fs = std::filesystem;

namespace morph::cli {

std::vector<std::string> list_directory_meshes(const std::string& dir) {
  std::vector<std::string> files;
  std::error_code ec;
  fs::directory_iterator it(dir, ec);
  if (ec) throw io_error(dir + ": cannot read the directory: " + ec.message());
  for (; it != fs::directory_iterator(); it.increment(ec)) {
    if (ec) throw io_error(dir + ": cannot read the directory: " + ec.message());
    std::error_code type_ec;
    if (it->is_regular_file(type_ec) && has_mesh_extension(it->path().string())) {
      files.push_back(it->path().string());
    }
  }
  std::sort(files.begin(), files.end());
  return files;
}

std::vector<std::string> read_list_file(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw io_error(path + ": cannot open the list: " + std::strerror(errno));
  std::vector<std::string> paths;
  std::string line;
  while (std::getline(in, line)) {
    const auto first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    const auto last = line.find_last_not_of(" \t\r");
    paths.push_back(line.substr(first, last - first + 1));
  }
  if (in.bad()) throw io_error(path + ": cannot read the list");
  return paths;
}

std::string batch_output_path(const std::string& input, const std::string& output_dir,
                              std::optional<MeshFormat> format) {
  const fs::path in(input);
  const std::string ext =
      format ? std::string(".") + format_name(*format) : in.extension().string();
  return (fs::path(output_dir) / (in.stem().string() + ext)).string();
}

namespace {

std::string progress_bar(std::size_t done, std::size_t total, std::size_t failed) {
  constexpr std::size_t kWidth = 30;
  const std::size_t filled = total == 0 ? kWidth : done * kWidth / total;
  std::string bar(1, '[');
  bar.append(filled, '#').append(kWidth - filled, '.').append("] ");
  bar.append(std::to_string(done)).append("/").append(std::to_string(total));
  if (failed > 0) bar.append(", ").append(std::to_string(failed)).append(" failed");
  return bar;
}

std::string file_line(const Job& job, const JobResult& result) {
  std::string line = std::string(status_name(result.status)) + ": " + job.input;
  if (!job.output.empty()) line += " -> " + job.output;
  char ms[32];
  std::snprintf(ms, sizeof ms, "%.1f", result.stats.compute_ms);
  line += " (" + std::to_string(result.stats.vertices) + " vertices, " +
          std::to_string(result.stats.facets) + " facets, " + ms + " ms)";
  return line;
}

}  // namespace

std::vector<JobResult> run_batch(const std::vector<Job>& jobs, const JobSettings& settings,
                                 Reporter& reporter, bool progress_bar_on) {
  std::vector<JobResult> results(jobs.size());
  std::atomic<std::size_t> done{0};
  std::atomic<std::size_t> failed{0};
  if (progress_bar_on) reporter.show_progress(progress_bar(0, jobs.size(), 0));
  // One task per file (simple_partitioner, grain 1): every file is a separate unit, so
  // the interrupt flag is checked before each one.
  tbb::parallel_for(
      tbb::blocked_range<std::size_t>(0, jobs.size(), 1),
      [&](const tbb::blocked_range<std::size_t>& range) {
        for (std::size_t i = range.begin(); i != range.end(); ++i) {
          if (interrupted()) {
            results[i].status = JobStatus::skipped;
            results[i].exit_code = kExitInterrupted;
            results[i].message = "not started: interrupted";
            continue;
          }
          results[i] = run_job(jobs[i], settings, reporter);
          const JobResult& result = results[i];
          if (result.status == JobStatus::failed) {
            ++failed;
            report(reporter, *result.failure);
          } else {
            reporter.info(file_line(jobs[i], result));
          }
          const std::size_t finished = ++done;
          if (progress_bar_on)
            reporter.show_progress(progress_bar(finished, jobs.size(), failed.load()));
        }
      },
      tbb::simple_partitioner());
  if (progress_bar_on) reporter.clear_progress();
  return results;
}

std::string batch_summary(const std::vector<Job>& jobs, const std::vector<JobResult>& results) {
  std::size_t counts[4] = {0, 0, 0, 0};
  std::vector<std::string> failed;
  for (std::size_t i = 0; i < results.size(); ++i) {
    ++counts[static_cast<int>(results[i].status)];
    if (results[i].status == JobStatus::failed) failed.push_back(jobs[i].input);
  }
  const std::size_t ok = counts[static_cast<int>(JobStatus::ok)];
  const std::size_t empty = counts[static_cast<int>(JobStatus::empty)];
  const std::size_t skipped = counts[static_cast<int>(JobStatus::skipped)];
  std::string line = std::to_string(results.size()) + " inputs: " + std::to_string(ok) + " ok, " +
                     std::to_string(empty) + " empty, " + std::to_string(failed.size()) + " failed";
  if (skipped > 0) line += ", " + std::to_string(skipped) + " not started (interrupted)";
  if (!failed.empty()) {
    constexpr std::size_t kMaxNamed = 20;
    line += "; failed:";
    for (std::size_t i = 0; i < failed.size() && i < kMaxNamed; ++i) line += " " + failed[i];
    if (failed.size() > kMaxNamed) {
      line += " and " + std::to_string(failed.size() - kMaxNamed) + " more (see --report)";
    }
  }
  return line;
}

int batch_exit_code(const std::vector<JobResult>& results) {
  if (interrupted()) return kExitInterrupted;
  bool any_failed = false;
  for (const JobResult& result : results) {
    if (result.status == JobStatus::skipped) return kExitInterrupted;
    any_failed = any_failed || result.status == JobStatus::failed;
  }
  return any_failed ? kExitBatchFailed : kExitOk;
}

std::string csv_field(std::string_view text) {
  if (text.find_first_of(",\"\r\n") == std::string_view::npos) return std::string(text);
  std::string out = "\"";
  for (char c : text) {
    if (c == '"') out += '"';
    out += c;
  }
  return out + "\"";
}

void write_report(const std::string& path, const std::vector<Job>& jobs,
                  const std::vector<JobResult>& results) {
  std::ostringstream csv;
  csv << "file,status,vertices,facets,compute_ms,message\n";
  for (std::size_t i = 0; i < results.size(); ++i) {
    const JobResult& r = results[i];
    const bool counted = r.status == JobStatus::ok || r.status == JobStatus::empty;
    char ms[32];
    std::snprintf(ms, sizeof ms, "%.3f", r.stats.compute_ms);
    csv << csv_field(jobs[i].input) << ',' << status_name(r.status) << ','
        << (counted ? std::to_string(r.stats.vertices) : "") << ','
        << (counted ? std::to_string(r.stats.facets) : "") << ',' << (counted ? ms : "") << ','
        << csv_field(one_line(r.message)) << '\n';
  }
  const std::string text = csv.str();

  // Atomic like the mesh writers: a temporary beside the target, then a rename.
  const fs::path target(path);
  const fs::path dir = target.has_parent_path() ? target.parent_path() : fs::path(".");
  std::string temp =
      (dir / std::string(1, '.').append(target.filename().string()).append(".XXXXXX")).string();
  WriteInProgress writing;
  const int fd = ::mkstemp(temp.data());
  if (fd < 0) throw io_error(path + ": cannot create the report: " + std::strerror(errno));
  std::size_t written = 0;
  while (written < text.size()) {
    const ssize_t n = ::write(fd, text.data() + written, text.size() - written);
    if (n < 0) {
      if (errno == EINTR) continue;
      const std::string reason = std::strerror(errno);
      ::close(fd);
      ::unlink(temp.c_str());
      throw io_error(path + ": cannot write the report: " + reason);
    }
    written += static_cast<std::size_t>(n);
  }
  const mode_t mask = ::umask(0);  // mkstemp makes 0600; give the report the usual mode
  ::umask(mask);
  ::fchmod(fd, 0666 & ~mask);
  if (::close(fd) != 0 || std::rename(temp.c_str(), path.c_str()) != 0) {
    const std::string reason = std::strerror(errno);
    ::unlink(temp.c_str());
    throw io_error(path + ": cannot write the report: " + reason);
  }
}

}  // namespace morph::cli
