// mesh-close: see 'mesh-close --help' and docs/cli.md.
#include "common/options.h"

int main(int argc, char* argv[]) {
  return morph::cli::run_operation_app(argc, argv, morph::cli::Op::close);
}
