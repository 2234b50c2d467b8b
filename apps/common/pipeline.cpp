#include "pipeline.h"

#include <morph/error.h>

#include <array>

namespace morph::cli {
namespace {

constexpr std::array<Op, 4> kOps = {Op::dilate, Op::erode, Op::open, Op::close};

bool is_space(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v'; }

std::string_view trim(std::string_view s) {
  while (!s.empty() && is_space(s.front())) s.remove_prefix(1);
  while (!s.empty() && is_space(s.back())) s.remove_suffix(1);
  return s;
}

// A '#' at the start of the line or after whitespace starts a comment; a '#' inside a
// word (a file name "a#b.off") does not.
std::string_view strip_comment(std::string_view line) {
  for (std::size_t i = 0; i < line.size(); ++i) {
    if (line[i] == '#' && (i == 0 || is_space(line[i - 1]))) return line.substr(0, i);
  }
  return line;
}

// Printable, bounded excerpt of user text for messages (the text may be any bytes).
std::string excerpt(std::string_view s) {
  constexpr std::size_t kMax = 40;
  std::string out;
  for (std::size_t i = 0; i < s.size() && i < kMax; ++i) {
    const unsigned char c = static_cast<unsigned char>(s[i]);
    out += (c >= 0x20 && c < 0x7f) ? static_cast<char>(c) : '?';
  }
  if (s.size() > kMax) out += "...";
  return out;
}

}  // namespace

const char* op_name(Op op) {
  switch (op) {
    case Op::dilate:
      return "dilate";
    case Op::erode:
      return "erode";
    case Op::open:
      return "open";
    case Op::close:
      return "close";
  }
  return "?";
}

std::optional<Op> op_from_name(std::string_view name) {
  for (Op op : kOps) {
    if (name == op_name(op)) return op;
  }
  return std::nullopt;
}

PipelineStep parse_step(std::string_view text, std::string_view where) {
  const std::string_view step = trim(text);
  std::size_t end = 0;
  while (end < step.size() && !is_space(step[end])) ++end;
  const std::string_view word = step.substr(0, end);
  const std::string_view spec = trim(step.substr(end));
  if (word.empty()) {
    throw input_error(
        std::string(where) +
        ": empty step (expected '<op> <spec>', op one of dilate, erode, open, close)");
  }
  const std::optional<Op> op = op_from_name(word);
  if (!op) {
    throw input_error(std::string(where) + ": unknown operation '" + excerpt(word) +
                      "' (expected dilate, erode, open or close)");
  }
  if (spec.empty()) {
    throw input_error(std::string(where) + ": '" + std::string(word) +
                      "' needs a structuring element (e.g. '" + std::string(word) +
                      " sphere:r=0.1')");
  }
  return PipelineStep{*op, std::string(spec), std::string(where)};
}

std::vector<PipelineStep> parse_pipeline(std::string_view text, std::string_view source) {
  std::vector<PipelineStep> steps;
  std::size_t line_number = 0;
  while (!text.empty()) {
    ++line_number;
    const std::size_t newline = text.find('\n');
    const std::string_view line = text.substr(0, newline);
    text = newline == std::string_view::npos ? std::string_view{} : text.substr(newline + 1);
    const std::string where = std::string(source) + ":" + std::to_string(line_number);
    if (line.size() > kMaxPipelineLineLength) {
      throw input_error(where + ": line longer than " + std::to_string(kMaxPipelineLineLength) +
                        " bytes");
    }
    if (line.find('\0') != std::string_view::npos) {
      throw input_error(where + ": NUL byte (a pipeline file is text)");
    }
    const std::string_view content = trim(strip_comment(line));
    if (content.empty()) continue;
    if (steps.size() == kMaxPipelineSteps) {
      throw input_error(where + ": more than " + std::to_string(kMaxPipelineSteps) + " steps");
    }
    steps.push_back(parse_step(content, where));
  }
  if (steps.empty()) {
    throw input_error(
        std::string(source) + ":" + std::to_string(line_number > 0 ? line_number : 1) +
        ": no step in the pipeline (expected lines '<op> <spec>', e.g. 'open sphere:r=0.1')");
  }
  return steps;
}

std::string describe_steps(const std::vector<PipelineStep>& steps) {
  std::string out;
  for (const PipelineStep& step : steps) {
    if (!out.empty()) out += " | ";
    out += op_name(step.op);
    out += ' ';
    out += step.se_spec;
  }
  return out;
}

}  // namespace morph::cli
