#pragma once
/// \file
/// The library's exception hierarchy. Every error names the input it is about (a file path, a flag,
/// a mesh name) and says what is wrong with it, so that a tool can print `what()` as one line for
/// the user.
///
// clang-format off
///   Error                    base of everything the library throws on purpose
///   ├── IoError              a file cannot be opened, read or written (missing, permission,
///   │                        disk full)
///   ├── InvalidInputError    the input is readable but wrong: malformed file, non-manifold
///   │                        mesh, NaN coordinates, a curve off the surface, an absurd count, ...
///   └── NumericalError       a computation failed on valid input (no convergence, singular
///                            system)
// clang-format on
///
/// `what()` is "<input>: <problem>"; `input()` and `problem()` give the two parts.

#include <stdexcept>
#include <string>

namespace elastic {

class Error : public std::runtime_error {
 public:
  Error(std::string input, std::string problem)
      : std::runtime_error(input.empty() ? problem : input + ": " + problem),
        input_(std::move(input)),
        problem_(std::move(problem)) {}

  /// The input the error is about: a file path, a flag, a mesh name. May be empty.
  const std::string& input() const noexcept { return input_; }
  /// What is wrong, without the input's name.
  const std::string& problem() const noexcept { return problem_; }

 private:
  std::string input_;
  std::string problem_;
};

/// A file could not be opened, read or written. `direction()` tells which, so a tool can tell a
/// missing input from an output it cannot create.
class IoError : public Error {
 public:
  enum class Direction { Read, Write };
  IoError(std::string input, std::string problem, Direction direction = Direction::Read)
      : Error(std::move(input), std::move(problem)), direction_(direction) {}
  Direction direction() const noexcept { return direction_; }

 private:
  Direction direction_;
};

/// The input is readable but not acceptable (malformed, non-manifold, out of range, ...).
class InvalidInputError : public Error {
 public:
  using Error::Error;
};

/// A numerical computation failed on valid input.
class NumericalError : public Error {
 public:
  using Error::Error;
};

}  // namespace elastic
