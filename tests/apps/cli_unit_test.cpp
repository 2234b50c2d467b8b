// Unit tests of the apps' common library (apps/common): the pipeline parser (also the
// entry point of a fuzz target), error classification, JSON and CSV quoting.
#define DOCTEST_CONFIG_IMPLEMENT_WITH_MAIN
#include <doctest/doctest.h>
#include <morph/error.h>

#include <string>

#include "common/batch.h"
#include "common/cli.h"
#include "common/pipeline.h"

using namespace morph::cli;

namespace {

std::string parse_error(std::string_view text) {
  try {
    parse_pipeline(text, "p.morph");
  } catch (const morph::input_error& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST_CASE("cli.unit.pipeline.steps_comments_blank_lines") {
  const auto steps = parse_pipeline(
      "# header\n"
      "\n"
      "  open   sphere:r=0.05,level=2   # trailing\n"
      "close box:0.1,0.1,0.1\r\n"
      "dilate tools/a#1.off\n"
      "\t# indented comment\n"
      "erode cube:0.1",  // no final newline
      "p.morph");
  REQUIRE(steps.size() == 4);
  CHECK(steps[0].op == Op::open);
  CHECK(steps[0].se_spec == "sphere:r=0.05,level=2");
  CHECK(steps[0].where == "p.morph:3");
  CHECK(steps[1].op == Op::close);
  CHECK(steps[1].se_spec == "box:0.1,0.1,0.1");
  CHECK(steps[2].se_spec == "tools/a#1.off");  // '#' inside a word is not a comment
  CHECK(steps[3].op == Op::erode);
  CHECK(steps[3].where == "p.morph:7");
  CHECK(
      describe_steps(steps) ==
      "open sphere:r=0.05,level=2 | close box:0.1,0.1,0.1 | dilate tools/a#1.off | erode cube:0.1");
}

TEST_CASE("cli.unit.pipeline.errors_name_file_and_line") {
  CHECK(parse_error("open cube:1\nopne cube:1\n").find("p.morph:2: unknown operation 'opne'") == 0);
  CHECK(parse_error("# c\nerode\n").find("p.morph:2: 'erode' needs a structuring element") == 0);
  CHECK(parse_error("Open cube:1\n").find("p.morph:1: unknown operation") == 0);  // case matters
  CHECK(parse_error("").find("no step") != std::string::npos);
  CHECK(parse_error("# only comments\n\n").find("p.morph:2: no step") == 0);
  CHECK(parse_error(std::string(kMaxPipelineLineLength + 1, 'x')).find("longer than") !=
        std::string::npos);
  CHECK(parse_error(std::string("open cube:1\0x\n", 14)).find("NUL") != std::string::npos);
  // Non-printable bytes are not echoed back as they are.
  const std::string message = parse_error("\x01\x02\xff cube:1\n");
  CHECK(message.find("'" + std::string(3, '?') + "'") != std::string::npos);
}

TEST_CASE("cli.unit.pipeline.step_limit") {
  std::string text;
  for (std::size_t i = 0; i <= kMaxPipelineSteps; ++i) text += "dilate cube:1\n";
  CHECK(parse_error(text).find("more than") != std::string::npos);
}

TEST_CASE("cli.unit.pipeline.parse_step") {
  const PipelineStep step = parse_step("  dilate   cube:0.2  ", "--op 1");
  CHECK(step.op == Op::dilate);
  CHECK(step.se_spec == "cube:0.2");
  CHECK_THROWS_AS(parse_step("", "--op 1"), morph::input_error);
  CHECK_THROWS_AS(parse_step("shrink cube:1", "--op 1"), morph::input_error);
  for (const char* name : {"dilate", "erode", "open", "close"}) {
    REQUIRE(op_from_name(name).has_value());
    CHECK(std::string(op_name(*op_from_name(name))) == name);
  }
  CHECK_FALSE(op_from_name("dilation").has_value());
}

TEST_CASE("cli.unit.classify.exit_codes_by_stage") {
  auto code = [](auto exception, Stage stage) {
    try {
      throw exception;
    } catch (...) {
      return classify_current_exception(stage, "f.off", "prog").code;
    }
  };
  CHECK(code(morph::io_error("x"), Stage::read) == kExitNoInput);
  CHECK(code(morph::io_error("x"), Stage::write) == kExitCantCreate);
  CHECK(code(morph::input_error("x"), Stage::read) == kExitDataErr);
  CHECK(code(morph::limit_error("x"), Stage::read) == kExitDataErr);
  CHECK(code(morph::input_error("x"), Stage::structuring_element) == kExitUsage);
  CHECK(code(morph::input_error("x"), Stage::usage) == kExitUsage);
  CHECK(code(morph::not_convex("x"), Stage::validate) == kExitInvalidMesh);
  CHECK(code(morph::invalid_mesh("x"), Stage::compute) == kExitInvalidMesh);
  CHECK(code(std::runtime_error("x"), Stage::compute) == kExitSoftware);
  CHECK(code(std::bad_alloc(), Stage::compute) == kExitSoftware);
}

TEST_CASE("cli.unit.classify.message_is_one_line_without_repeating_the_file") {
  try {
    throw morph::input_error("f.off: line 3: bad\nnumber.");
  } catch (...) {
    const Failure failure = classify_current_exception(Stage::read, "f.off", "prog");
    CHECK(failure.file == "f.off");
    CHECK(failure.what == "line 3: bad number");
    CHECK_FALSE(failure.hint.empty());
  }
}

TEST_CASE("cli.unit.json_and_csv_quoting") {
  CHECK(json_string("a\"b\\c\n") == "\"a\\\"b\\\\c\\u000a\"");
  CHECK(csv_field("plain") == "plain");
  CHECK(csv_field("a,b") == "\"a,b\"");
  CHECK(csv_field("say \"hi\"") == "\"say \"\"hi\"\"\"");
  RunStats stats;
  stats.op = "dilate";
  stats.input = "in.off";
  stats.translated = 3;
  const std::string json = stats_json(stats);
  CHECK(json.find("\"translated\":3") != std::string::npos);
  CHECK(json.find("\"corner\":null") != std::string::npos);
  CHECK(json.find("\"output\":null") != std::string::npos);
  CHECK(json.find('\n') == std::string::npos);
}

TEST_CASE("cli.unit.batch_output_path") {
  CHECK(batch_output_path("in/part.STL", "out", std::nullopt) == "out/part.STL");
  CHECK(batch_output_path("in/part.stl", "out", morph::MeshFormat::ply) == "out/part.ply");
  CHECK(has_mesh_extension("a.Off"));
  CHECK_FALSE(has_mesh_extension("a.txt"));
}
