// `elastic version`: library and dependency versions, for bug reports.
#include <iostream>
#include <memory>

#include "command.h"

ELASTIC_COMMAND("version", "Print the version of elastic", [](CLI::App& sub) {
  // -q is accepted as on every subcommand; the version is the result, so it is still printed.
  auto quiet = std::make_shared<bool>(false);
  sub.add_flag("-q,--quiet", *quiet, "Accepted as everywhere (the version is still printed)");
  return [] {
    std::cout << "elastic " << ELASTIC_VERSION << '\n';
    return 0;
  };
});
