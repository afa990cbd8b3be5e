// The `elastic` command-line tool. Library errors become one line on stderr and a documented exit
// code.

#include <cstdio>
#include <exception>
#include <iostream>
#include <memory>

#include "command.h"
#include "elastic/core/error.h"

namespace elastic::cli {
std::vector<Command>& command_registry() {
  static std::vector<Command> registry;
  return registry;
}
}  // namespace elastic::cli

int main(int argc, char** argv) {
  using namespace elastic::cli;
  CLI::App app{
      "ElasticPaint: paste features from a region of one surface onto another with least "
      "distortion"};
  app.set_version_flag("--version", ELASTIC_VERSION);
  app.require_subcommand(1);

  std::function<int()> run;
  for (const Command& command : command_registry()) {
    CLI::App* sub = app.add_subcommand(command.name, command.description);
    auto runner = std::make_shared<std::function<int()>>();
    *runner = command.setup(*sub);
    sub->callback([runner, &run] { run = *runner; });
  }

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? kOk : kUsage;
  }

  try {
    return run ? run() : kUsage;
  } catch (const elastic::IoError& e) {
    std::cerr << "elastic: " << e.what() << '\n';
    return e.direction() == elastic::IoError::Direction::Write ? kCantCreate : kNoInput;
  } catch (const elastic::InvalidInputError& e) {
    std::cerr << "elastic: " << e.what() << '\n';
    return kBadInput;
  } catch (const elastic::NumericalError& e) {
    std::cerr << "elastic: " << e.what() << '\n';
    return kNumerical;
  } catch (const std::bad_alloc&) {
    std::cerr << "elastic: out of memory\n";
    return kNumerical;
  } catch (const std::exception& e) {
    std::cerr << "elastic: internal error: " << e.what() << '\n';
    return kNumerical;
  }
}
