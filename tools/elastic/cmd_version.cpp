// `elastic version`: library and dependency versions, for bug reports.
#include <iostream>

#include "allocator.h"
#include "command.h"

ELASTIC_COMMAND("version", "Print the version of elastic", [](CLI::App& sub) {
  // -q is accepted as on every subcommand; the version is the result, so it is still printed.
  // The flag's variable must outlive this function: the command line is parsed after it returns
  // (a local shared_ptr freed here was written after its free: AddressSanitizer,
  // Grammar.EverySubcommandTakesQuiet under scripts/test-sanitize).
  static bool quiet = false;
  sub.add_flag("-q,--quiet", quiet, "Accepted as everywhere (the version is still printed)");
  return [] {
    std::cout << "elastic " << ELASTIC_VERSION << '\n'
              << "allocator: " << elastic::cli::allocator_description() << '\n';
    return 0;
  };
});
