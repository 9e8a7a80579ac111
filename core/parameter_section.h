#pragma once
/// @file The case subsection a module's parameters were read from, so that the module's
/// messages name its entries as the case file spells them without knowing the file's
/// layout (the application chooses where each module's subsection goes).

#include <string>

namespace dealii
{
  class ParameterHandler;
}

namespace tribo
{
  class ParameterFile;

  /// Where a module's entries live in the case: "Solver", "Shear cell", ...
  struct ParameterSection
  {
    /// The subsection path, nested subsections separated by '/'; empty when the
    /// parameters were not read from a case file (unit tests, benchmarks).
    std::string path;

    /// The full name of entry @p name, "path/name" ("Solver/Tolerance"), or @p name alone
    /// without a path.
    std::string entry(const std::string &name) const { return path.empty() ? name : path + "/" + name; }
  };
} // namespace tribo
