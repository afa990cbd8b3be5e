// The `elastic` command-line tool. Library errors become one line on stderr and a documented exit
// code.

#include <signal.h>
#include <tbb/global_control.h>

#include <cstdio>
#include <exception>
#include <iostream>
#include <memory>
#include <optional>
#include <string>

#include "cli_common.h"
#include "command.h"
#include "elastic/core/atomic_file.h"
#include "elastic/core/error.h"
#include "elastic/core/staged_folder.h"
#include "job_file.h"

namespace {

/// On SIGINT, SIGTERM or SIGHUP: remove the temporary files and the uncommitted staging folders
/// being written (async-signal-safe), then die of the same signal, so the parent sees the usual
/// status. Finished files are never touched: each was renamed into place whole, and every
/// destination keeps its old content until its rename.
extern "C" void remove_temporaries_and_reraise(int signal_number) {
  elastic::remove_temporary_files_now();
  elastic::remove_staging_folders_now();
  ::signal(signal_number, SIG_DFL);
  ::raise(signal_number);
}

void install_interrupt_handlers() {
  struct sigaction action {};
  action.sa_handler = remove_temporaries_and_reraise;
  sigemptyset(&action.sa_mask);
  for (const int signal_number : {SIGINT, SIGTERM, SIGHUP}) {
    // A signal the parent asked us to ignore (nohup, a background job) stays ignored.
    struct sigaction previous {};
    if (::sigaction(signal_number, nullptr, &previous) == 0 && previous.sa_handler == SIG_IGN) {
      continue;
    }
    ::sigaction(signal_number, &action, nullptr);
  }
}

/// The subcommand named on the command line ("map", "bench table1"), empty when none was.
std::string chosen_name(const CLI::App& app) {
  std::string name;
  for (const CLI::App* sub = &app; !sub->get_subcommands().empty();) {
    sub = sub->get_subcommands().front();
    name += (name.empty() ? "" : " ") + sub->get_name();
  }
  return name;
}

/// " (see elastic map --help)": where the grammar is, on the error's own line.
std::string usage_hint(const std::string& subcommand) {
  return " (see elastic " + (subcommand.empty() ? std::string() : subcommand + " ") + "--help)";
}

}  // namespace

namespace elastic::cli {
std::vector<Command>& command_registry() {
  static std::vector<Command> registry;
  return registry;
}
}  // namespace elastic::cli

int main(int argc, char** argv) {
  using namespace elastic::cli;
  install_interrupt_handlers();
  CLI::App app{
      "ElasticPaint: paste features from a region of one surface onto another with least "
      "distortion"};
  app.set_version_flag("--version", ELASTIC_VERSION);
  app.require_subcommand(1);

  std::function<int()> run;
  CLI::App* chosen = nullptr;
  for (const Command& command : command_registry()) {
    CLI::App* sub = app.add_subcommand(command.name, command.description);
    // Defaults are captured so that a report's "job" records every value the run used.
    sub->option_defaults()->always_capture_default();
    auto runner = std::make_shared<std::function<int()>>();
    *runner = command.setup(*sub);
    // Every subcommand takes a job file (`version` too: one grammar, docs/cli.md); nested
    // subcommands (e.g. `bench table1`) as well.
    add_job_option(*sub);
    for (CLI::App* nested : sub->get_subcommands({})) {
      add_job_option(*nested);
    }
    sub->callback([runner, sub, &run, &chosen] {
      run = *runner;
      chosen = sub;
    });
  }

  // A first word that is neither a flag nor a subcommand: name it (CLI11 would only say that a
  // subcommand is required).
  if (argc > 1 && argv[1][0] != '-') {
    bool known = false;
    for (const Command& command : command_registry()) {
      known = known || command.name == argv[1];
    }
    if (!known) {
      std::cerr << "elastic: unknown subcommand '" << argv[1] << "'" << usage_hint("") << '\n';
      return kUsage;
    }
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e) == 0 ? kOk : kUsage;
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e) == 0 ? kOk : kUsage;
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e) == 0 ? kOk : kUsage;
  } catch (const CLI::ParseError& e) {
    // CLI11's own messages name the flag ("--particles: Value 0 not in range ..."); they get the
    // tool's prefix and stay on one line like every other error.
    std::cerr << "elastic: " << one_line(e.what()) << usage_hint(chosen_name(app)) << '\n';
    return kUsage;
  }

  std::optional<tbb::global_control> limit;
  try {
    if (chosen != nullptr) {
      // The job file belongs to the innermost subcommand given (`bench table1 --job F`).
      CLI::App* leaf = chosen;
      while (!leaf->get_subcommands().empty()) {
        leaf = leaf->get_subcommands().front();
      }
      apply_job_file(*leaf);
      // --threads N bounds every stage of the run (sampling, naive map, solver, transfer,
      // rendering), not only the stage that reads the flag: a batch of runs side by side
      // (python3 -m elastic.batch) then shares the cores as asked.
      if (const CLI::Option* threads = leaf->get_option_no_throw("--threads");
          threads != nullptr && threads->as<int>() > 0) {
        limit.emplace(tbb::global_control::max_allowed_parallelism, threads->as<std::size_t>());
      }
    }
    return run ? run() : kUsage;
  } catch (const UsageError& e) {
    std::cerr << "elastic: " << one_line(e.what()) << usage_hint(chosen_name(app)) << '\n';
    return kUsage;
  } catch (const elastic::IoError& e) {
    std::cerr << "elastic: " << one_line(e.what()) << '\n';
    return e.direction() == elastic::IoError::Direction::Write ? kCantCreate : kNoInput;
  } catch (const elastic::InvalidInputError& e) {
    std::cerr << "elastic: " << one_line(e.what()) << '\n';
    return kBadInput;
  } catch (const elastic::NumericalError& e) {
    std::cerr << "elastic: " << one_line(e.what()) << '\n';
    return kNumerical;
  } catch (const std::bad_alloc&) {
    std::cerr << "elastic: out of memory\n";
    return kNumerical;
  } catch (const std::exception& e) {
    std::cerr << "elastic: internal error: " << one_line(e.what()) << '\n';
    return kNumerical;
  }
}
