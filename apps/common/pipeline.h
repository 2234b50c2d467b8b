// Pipelines: a chain of morphological operations, each with a structuring-element spec,
// given as --op arguments or as a pipeline file.
//
// Pipeline file grammar (docs/cli.md):
//   file    := { line '\n' }
//   line    := [ step ] [ comment ]
//   step    := op  spec          op is one of dilate, erode, open, close
//   comment := '#' ...           at the start of a line or after whitespace
// Blank lines and comments are ignored; the spec is the rest of the step (trimmed), in the
// grammar of morph::make_structuring_element. A file must hold at least one step.
//
// Parsing is pure (no file access, no structuring element built) so that a fuzz target
// can call parse_pipeline() on any bytes; it throws morph::input_error naming
// "source:line" and never anything else.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace morph::cli {

enum class Op { dilate, erode, open, close };

/// "dilate", "erode", "open", "close".
const char* op_name(Op op);

/// The op named by a word; nullopt for any other word.
std::optional<Op> op_from_name(std::string_view name);

/// One step of a pipeline.
struct PipelineStep {
  Op op = Op::dilate;
  std::string se_spec;  // structuring-element spec, not yet checked
  std::string where;    // "file:line" or "--op 2", for messages
};

/// Limits that keep a hostile pipeline file from making the parser allocate without bound.
inline constexpr std::size_t kMaxPipelineSteps = 10'000;
inline constexpr std::size_t kMaxPipelineLineLength = 4'096;  // bytes, without the newline

/// Parses one step "op spec" (as given to --op). `where` names it in messages.
/// Throws input_error("<where>: ...") when the op is unknown or the spec is missing.
PipelineStep parse_step(std::string_view text, std::string_view where);

/// Parses a whole pipeline file held in `text`; `source` (the file name) prefixes
/// messages as "source:line: ...". Throws input_error on the first bad line, or when
/// the file has no step.
std::vector<PipelineStep> parse_pipeline(std::string_view text, std::string_view source);

/// The steps as "op spec" strings (for stats and verbose output).
std::string describe_steps(const std::vector<PipelineStep>& steps);

}  // namespace morph::cli
