// Fuzz target: the pipeline file parser of the apps (pure: no file access). The header
// promises morph::input_error and nothing else; every parsed step has a known op and a
// non-empty spec.
#include <morph/error.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "pipeline.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    const auto steps = morph::cli::parse_pipeline(text, "fuzz.morph");
    if (steps.empty() || steps.size() > morph::cli::kMaxPipelineSteps) std::abort();
    for (const auto& step : steps) {
      if (step.se_spec.empty() || !morph::cli::op_from_name(morph::cli::op_name(step.op)))
        std::abort();
    }
    (void)morph::cli::describe_steps(steps);
  } catch (const morph::input_error&) {
  }
  try {
    (void)morph::cli::parse_step(text.substr(0, 512), "--op 1");
  } catch (const morph::input_error&) {
  }
  return 0;
}
