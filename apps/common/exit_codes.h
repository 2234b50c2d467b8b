// The exit status of every libmorph app, stated once (docs/cli.md has the same table).
#pragma once

namespace morph::cli {

enum ExitCode : int {
  kExitOk = 0,             // success (an empty erosion/opening too, unless --fail-on-empty)
  kExitBatchFailed = 1,    // a batch finished but some inputs failed
  kExitInvalidMesh = 3,    // an input is not a closed convex polyhedron
  kExitEmpty = 4,          // the result is empty and --fail-on-empty was given
  kExitUsage = 64,         // bad option, bad --se spec, bad pipeline file
  kExitDataErr = 65,       // malformed input file
  kExitNoInput = 66,       // input missing or unreadable
  kExitSoftware = 70,      // internal error
  kExitCantCreate = 73,    // output cannot be written
  kExitInterrupted = 130,  // interrupted by SIGINT
};

/// The table above as text for --help.
inline constexpr const char* kExitCodeHelp =
    "Exit status:\n"
    "  0    success (an empty result is a success with a warning, unless --fail-on-empty)\n"
    "  1    batch finished but some inputs failed (the summary names them)\n"
    "  3    an input is not a closed convex polyhedron\n"
    "  4    the result is empty and --fail-on-empty was given (nothing is written)\n"
    "  64   usage error: bad option, bad --se spec, bad pipeline file\n"
    "  65   malformed input file\n"
    "  66   input missing or unreadable\n"
    "  70   internal error\n"
    "  73   output cannot be written\n"
    "  130  interrupted (SIGINT); finished outputs stay, no partial file is left\n";

}  // namespace morph::cli
