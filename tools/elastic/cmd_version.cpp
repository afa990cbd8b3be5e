// `elastic version`: library and dependency versions, for bug reports.
#include <iostream>

#include "command.h"

ELASTIC_COMMAND("version", "Print the version of elastic", [](CLI::App&) {
  return [] {
    std::cout << "elastic " << ELASTIC_VERSION << '\n';
    return 0;
  };
});
