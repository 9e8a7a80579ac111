#pragma once
/// @file Reading a deal.II ParameterHandler file with messages that name the
/// file, the line and the entry, command-line overrides, and validated reads.

#include <deal.II/base/parameter_handler.h>

#include <cmath>
#include <map>
#include <string>
#include <vector>

namespace tribo
{
  /// Checks for ParameterFile::get_checked(): finite and > 0, finite and >= 0.
  inline bool is_positive(double v) { return v > 0 && std::isfinite(v); }
  inline bool is_non_negative(double v) { return v >= 0 && std::isfinite(v); }

  /// Undo ParameterHandler's name mangling in its JSON and XML output ("_20" for a blank, ...).
  std::string demangle_parameter_name(const std::string &s);

  /// A parsed case file on top of a ParameterHandler whose entries are already
  /// declared. Entries are addressed by path, "Subsection/Entry" (nested
  /// subsections separated by '/').
  class ParameterFile
  {
  public:
    explicit ParameterFile(dealii::ParameterHandler &prm);

    /// Parse @p filename. Throws InputError "FILE:LINE: ..." for an unreadable
    /// file, an unknown subsection or entry, or a value that breaks its pattern.
    void parse(const std::string &filename);

    /// Apply an override "Subsection/Entry=value" (as given to --set).
    /// Throws InputError for an unknown entry or a value that breaks its pattern.
    void set(const std::string &assignment);

    /// The value of @p path as a string / number (pattern already checked).
    std::string get(const std::string &path) const;
    double get_double(const std::string &path) const;
    long get_integer(const std::string &path) const;
    bool get_bool(const std::string &path) const;

    /// A double that must satisfy @p ok; otherwise InputError naming the entry
    /// and @p expected, e.g. "a positive density in kg/m^3".
    template <typename Check>
    double get_checked(const std::string &path, Check ok, const std::string &expected) const
    {
      const double v = get_double(path);
      if (!ok(v))
        fail(path, expected);
      return v;
    }

    /// Throw InputError "FILE:LINE: entry 'path' = 'value': expected ...".
    [[noreturn]] void fail(const std::string &path, const std::string &expected) const;

    /// Where @p path was set: "FILE:LINE", "--set" or "FILE (default)".
    std::string where(const std::string &path) const;
    /// True when @p path was set neither in the file nor by set(): it has its default.
    bool is_default(const std::string &path) const;

    const std::string &filename() const { return file; }
    /// The file exactly as read.
    const std::string &original_text() const { return text; }
    dealii::ParameterHandler       &handler() { return prm; }
    const dealii::ParameterHandler &handler() const { return prm; }
    /// Every entry as used (file, then set(), then defaults): "Subsection/Entry" -> value.
    std::map<std::string, std::string> resolved() const;

  private:
    static std::vector<std::string> split_path(const std::string &path);
    /// " (did you mean 'Subsection/Entry'?)" for the declared entry nearest to @p path in
    /// edit distance (case ignored), when it is within a third of the name; else "".
    std::string nearest_entry_hint(const std::string &path) const;

    dealii::ParameterHandler &prm;
    std::string file = "(no file)";
    std::string text;
    /// Line of each "set" statement in the file, by entry path.
    std::map<std::string, unsigned int> lines;
    std::map<std::string, bool> overridden;
  };
} // namespace tribo
