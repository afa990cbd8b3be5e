#pragma once
// Subcommand registry of the `elastic` tool. Each subcommand lives in its own cmd_<name>.cpp and
// registers itself with ELASTIC_COMMAND; main.cpp builds the CLI11 app from the registry.

#include <CLI/CLI.hpp>
#include <functional>
#include <string>
#include <vector>

namespace elastic::cli {

/// Exit codes (sysexits.h values, so scripts can tell failures apart).
enum ExitCode : int {
  kOk = 0,
  kUsage = 64,      ///< bad flags or arguments
  kBadInput = 65,   ///< an input file or value is malformed or unacceptable
  kNoInput = 66,    ///< an input file does not exist or cannot be read
  kNumerical = 70,  ///< a computation failed on valid input
  kCantCreate = 73  ///< an output file cannot be written
};

struct Command {
  std::string name;
  std::string description;
  /// Adds the subcommand's options to `sub` and returns the function that runs it (exit code).
  std::function<std::function<int()>(CLI::App& sub)> setup;
};

std::vector<Command>& command_registry();

struct CommandRegistrar {
  explicit CommandRegistrar(Command command) { command_registry().push_back(std::move(command)); }
};

}  // namespace elastic::cli

#define ELASTIC_CONCAT_INNER(a, b) a##b
#define ELASTIC_CONCAT(a, b) ELASTIC_CONCAT_INNER(a, b)
/// ELASTIC_COMMAND("name", "description", [](CLI::App& sub) { ...; return [&]{ return 0; }; });
/// (variadic so that the setup lambda may contain commas, e.g. a capture list [a, &sub]).
#define ELASTIC_COMMAND(name, description, ...)                 \
  static const ::elastic::cli::CommandRegistrar ELASTIC_CONCAT( \
      elastic_command_, __LINE__)(::elastic::cli::Command{name, description, __VA_ARGS__})
