#include "options.h"

#include <morph/error.h>
#include <morph/io.h>
#include <morph/structuring_element.h>
#include <morph/version.h>

#include <iostream>
#include <sstream>

#include "allocator.h"

namespace morph::cli {

void add_common_options(po::options_description& output, po::options_description& general,
                        CommonOptions& o) {
  // clang-format off
  output.add_options()
    ("output,o", po::value(&o.output)->value_name("FILE"),
     "output mesh; its format follows the extension (.off .obj .ply .stl); '-' writes stdout (needs --format)")
    ("format", po::value(&o.format)->value_name("NAME"),
     "output format off|obj|ply|stl, whatever the extension; also the format of stdin without --input-format")
    ("input-format", po::value(&o.input_format)->value_name("NAME"),
     "read the input as off|obj|ply|stl, whatever its extension (needed for stdin '-' unless --format)")
    ("binary", po::bool_switch(&o.binary), "write binary PLY/STL (ascii by default)")
    ("label-facets", po::bool_switch(&o.label_facets),
     "colour the result's facets by origin (PLY and OFF; palette below)")
    ("fail-on-empty", po::bool_switch(&o.fail_on_empty),
     "an empty result is an error (exit 4, nothing written) instead of a warning")
    ("threads", po::value(&o.threads)->value_name("N"), "use at most N threads (default 0: all cores)");
  general.add_options()
    ("stats", po::bool_switch(&o.stats),
     "print one line of JSON on stderr: counts, facets by origin, timings (see docs/cli.md)")
    ("quiet,q", po::bool_switch(&o.quiet), "print errors only")
    ("verbose,v", po::bool_switch(&o.verbose), "print notes: validation, each step, timings")
    ("help,h", po::bool_switch(&o.help), "print this help and exit")
    ("version", po::bool_switch(&o.version), "print the version and exit");
  // clang-format on
}

void parse_command_line(int argc, const char* const argv[], const po::options_description& all,
                        const po::positional_options_description& positional,
                        po::variables_map& vm) {
  po::store(
      po::command_line_parser(argc, argv)
          .options(all)
          .positional(positional)
          .style(po::command_line_style::default_style & ~po::command_line_style::allow_guessing)
          .run(),
      vm);
  po::notify(vm);
}

std::optional<Failure> apply_common_options(const CommonOptions& o, const ThreadLimit& threads,
                                            Reporter& reporter, JobSettings& settings) {
  const std::string& program = reporter.program();
  if (o.quiet && o.verbose)
    return make_failure(kExitUsage, "", "--quiet and --verbose exclude each other", program);
  if (o.threads < 0)
    return make_failure(kExitUsage, "", "--threads must be 0 (all cores) or more", program);
  try {
    if (!o.format.empty()) settings.output_format = format_from_name(o.format);
  } catch (const input_error&) {
    return make_failure(kExitUsage, "",
                        "--format '" + o.format + "' is not one of off, obj, ply, stl", program);
  }
  try {
    if (!o.input_format.empty()) settings.input_format = format_from_name(o.input_format);
  } catch (const input_error&) {
    return make_failure(kExitUsage, "",
                        "--input-format '" + o.input_format + "' is not one of off, obj, ply, stl",
                        program);
  }
  settings.stdin_format = settings.input_format ? settings.input_format : settings.output_format;
  settings.binary = o.binary;
  settings.label_facets = o.label_facets;
  settings.fail_on_empty = o.fail_on_empty;
  settings.stats = o.stats;
  settings.threads = threads.count();
  return std::nullopt;
}

std::string se_grammar_help() {
  std::string grammar = structuring_element_grammar();
  while (!grammar.empty() && grammar.back() == '\n') grammar.pop_back();
  return "Structuring elements (--se SPEC), centred on the origin:\n" + grammar + "\n";
}

std::string label_palette_help() {
  return "Facet labels (--label-facets), fixed palette (RGB):\n"
         "  translated  0 114 178   blue    a facet of the input moved by a vertex of the element\n"
         "  corner      230 159 0   orange  a facet of the element placed at a vertex of the "
         "input\n"
         "  edge        0 158 115   green   a parallelogram: an input edge (+) an element edge\n"
         "  (an erosion's facets are facets of the input moved inwards by a vertex of the "
         "element:\n"
         "  translated; a closing's are the translated facets of the dilation they lie on)\n";
}

namespace {

struct OperationHelp {
  const char* summary;
  const char* example_se;
};

OperationHelp operation_help(Op op) {
  switch (op) {
    case Op::dilate:
      return {
          "Dilates a convex polyhedron by a convex structuring element B:\n"
          "  A (+) B = { a + b : a in A, b in B }   (the Minkowski sum; exact FIMS kernel)\n",
          "sphere:r=0.05,level=2"};
    case Op::erode:
      return {
          "Erodes a convex polyhedron by a convex structuring element B:\n"
          "  A (-) B = { x : x + B inside A }\n"
          "When B fits nowhere inside A the result is empty: exit 0 with a warning and an empty\n"
          "mesh written, or exit 4 and nothing written with --fail-on-empty.\n",
          "cube:0.1"};
    case Op::open:
      return {
          "Opens a convex polyhedron by a convex structuring element B:\n"
          "  (A (-) B) (+) B   the union of the translates of B inside A (rounds edges and "
          "corners)\n"
          "An empty erosion gives an empty result (exit 0 with a warning; 4 with "
          "--fail-on-empty).\n",
          "sphere:r=0.05,level=2"};
    case Op::close:
      return {
          "Closes a convex polyhedron by a convex structuring element B:\n"
          "  (A (+) B) (-) B   (for a convex input this is the input itself)\n",
          "box:0.1,0.1,0.1"};
  }
  return {"", ""};
}

std::string operation_usage(const std::string& program, Op op,
                            const po::options_description& visible) {
  const OperationHelp help = operation_help(op);
  const std::string se = help.example_se;
  std::ostringstream out;
  out << "Usage: " << program << " INPUT --se SPEC -o OUTPUT [options]\n\n"
      << help.summary
      << "\nINPUT is a mesh file (.off .obj .ply .stl) or '-' for stdin (with --input-format).\n"
      << "It must be a closed convex polyhedron; an inverted one is flipped (a note with -v).\n"
      << visible << "\n"
      << se_grammar_help() << "\n"
      << label_palette_help() << "\n"
      << "Examples:\n"
      << "  " << program << " part.off --se " << se << " -o result.ply --label-facets\n"
      << "  " << program << " part.stl --se tool.off -o result.stl --binary --threads 4 --stats\n"
      << "  cat part.off | " << program << " - --format off --se " << se << " -o - > result.off\n\n"
      << kExitCodeHelp;
  return out.str();
}

}  // namespace

int run_operation_app(int argc, const char* const argv[], Op op) {
  keep_freed_memory();
  const std::string program = std::string("mesh-") + op_name(op);
  Reporter reporter(program);
  install_interrupt_handler(program, InterruptMode::immediate_when_safe);
  try {
    CommonOptions common;
    std::string input;
    std::string se;
    po::options_description operation("Operation");
    operation.add_options()(
        "se", po::value(&se)->value_name("SPEC"),
        "structuring element: a parametric spec or a convex mesh file (grammar below)");
    po::options_description output("Output");
    po::options_description general("General");
    add_common_options(output, general, common);
    po::options_description hidden;
    hidden.add_options()("input", po::value(&input));
    po::options_description visible;
    visible.add(operation).add(output).add(general);
    po::options_description all;
    all.add(visible).add(hidden);
    po::positional_options_description positional;
    positional.add("input", 1);

    po::variables_map vm;
    try {
      parse_command_line(argc, argv, all, positional, vm);
    } catch (const po::error& e) {
      report(reporter, make_failure(kExitUsage, "", e.what(), program));
      return kExitUsage;
    }
    if (common.help) {
      std::cout << operation_usage(program, op, visible);
      return kExitOk;
    }
    if (common.version) {
      std::cout << program << " (libmorph) " << kVersion << "\n";
      return kExitOk;
    }
    reporter.set_quiet(common.quiet);
    reporter.set_verbose(common.verbose);
    if (input.empty()) {
      report(reporter, make_failure(kExitUsage, "", "missing INPUT (a mesh file, or '-' for stdin)",
                                    program));
      return kExitUsage;
    }
    if (se.empty()) {
      report(reporter,
             make_failure(kExitUsage, "", "missing --se SPEC (the structuring element)", program));
      return kExitUsage;
    }
    if (common.output.empty()) {
      report(reporter, make_failure(kExitUsage, "",
                                    "missing -o OUTPUT (a mesh file, or '-' for stdout)", program));
      return kExitUsage;
    }

    const ThreadLimit threads(common.threads);
    JobSettings settings;
    if (std::optional<Failure> failure =
            apply_common_options(common, threads, reporter, settings)) {
      report(reporter, *failure);
      return failure->code;
    }
    settings.op_label = op_name(op);
    if (std::optional<Failure> failure =
            prepare_steps({PipelineStep{op, se, "--se"}}, reporter, settings.steps)) {
      report(reporter, *failure);
      return failure->code;
    }
    const JobResult result = run_job(Job{input, common.output}, settings, reporter);
    if (result.failure) report(reporter, *result.failure);
    return exit_code_after(result);
  } catch (...) {
    report(reporter, classify_current_exception(Stage::compute, "", program));
    return kExitSoftware;
  }
}

}  // namespace morph::cli
