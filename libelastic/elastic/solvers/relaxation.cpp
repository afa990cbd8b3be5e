#include "elastic/solvers/relaxation.h"

#include <tbb/task_arena.h>

#include <string>

#include "elastic/core/error.h"
#include "elastic/solvers/explicit_integrator.h"
#include "elastic/solvers/lbfgs_solver.h"

namespace elastic {

std::string_view to_string(SolverKind kind) {
  return kind == SolverKind::Fast ? "fast" : "faithful";
}

SolverKind parse_solver_kind(std::string_view text, std::string_view input) {
  if (text == "fast") return SolverKind::Fast;
  if (text == "faithful") return SolverKind::Faithful;
  throw InvalidInputError(std::string(input),
                          "unknown solver '" + std::string(text) + "' (expected fast or faithful)");
}

std::string_view to_string(Preconditioner kind) {
  switch (kind) {
    case Preconditioner::Direct:
      return "direct";
    case Preconditioner::Multigrid:
      return "multigrid";
  }
  return "unknown";
}

Preconditioner parse_preconditioner(std::string_view text, std::string_view input) {
  if (text == "direct") return Preconditioner::Direct;
  if (text == "multigrid") return Preconditioner::Multigrid;
  throw InvalidInputError(std::string(input), "unknown preconditioner '" + std::string(text) +
                                                  "' (expected multigrid or direct)");
}

std::string_view to_string(StopReason reason) {
  switch (reason) {
    case StopReason::RelativeGradient:
      return "relative tangential gradient below tolerance";
    case StopReason::AbsoluteGradient:
      return "tangential gradient below the absolute bound";
    case StopReason::NoFreeParticles:
      return "no interior particles";
    case StopReason::MaxIterations:
      return "iteration limit reached";
    case StopReason::LineSearchFailed:
      return "line search found no fold-free decrease";
    case StopReason::FoldConstrained:
      return "stopped against the no-fold constraint (the energy minimum folds faces)";
    case StopReason::Diverged:
      return "diverged (non-finite energy or positions)";
    case StopReason::Cancelled:
      return "cancelled";
  }
  return "unknown";
}

RelaxationResult relax(const RelaxationProblem& problem, const RelaxationOptions& options) {
  const auto run = [&] {
    return options.solver == SolverKind::Fast ? relax_lbfgs(problem, options)
                                              : relax_explicit(problem, options);
  };
  if (options.threads < 0) throw InvalidInputError("relaxation", "threads must be >= 0");
  if (options.threads == 0) return run();
  tbb::task_arena arena(options.threads);
  return arena.execute(run);
}

}  // namespace elastic
