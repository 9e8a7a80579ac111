#pragma once
/// @file Errors reported to users and the exit codes of `tribo`.

#include <cstdio>
#include <stdexcept>
#include <string>

namespace tribo
{
  /// Wrong user input (parameter file, command line). The message names the
  /// file, the entry or line, and what was expected; `tribo` prints it alone
  /// (no stack) and exits with ExitCode::input_error.
  class InputError : public std::runtime_error
  {
  public:
    using std::runtime_error::runtime_error;
  };

  /// A run that cannot go on (solver blow-up, NaN, I/O failure).
  class RunError : public std::runtime_error
  {
  public:
    using std::runtime_error::runtime_error;
  };

  /// A number for a message, with 6 significant digits ("6e-06", not "0.000006").
  inline std::string to_text(double v)
  {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%g", v);
    return buf;
  }

  /// Exit codes of `tribo`; an interrupted run exits with 128 + signal number.
  enum ExitCode : int
  {
    exit_ok          = 0,
    exit_run_error   = 1,
    exit_input_error = 2
  };
} // namespace tribo
