#include "core/parameter_file.h"

#include "core/errors.h"

#include <deal.II/base/exceptions.h>

#include <boost/property_tree/json_parser.hpp>
#include <boost/property_tree/ptree.hpp>

#include <algorithm>
#include <cctype>

#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>

namespace tribo
{
  namespace
  {
    /// deal.II's own explanation of an exception, without its source location.
    std::string describe(const dealii::ExceptionBase &e)
    {
      std::ostringstream os;
      e.print_info(os);
      std::string s = os.str();
      // Collapse deal.II's line breaks and indentation into one line.
      s = std::regex_replace(s, std::regex("\\s+"), " ");
      while (!s.empty() && s.back() == ' ')
        s.pop_back();
      while (!s.empty() && s.front() == ' ')
        s.erase(s.begin());
      return s;
    }

    std::string trim(const std::string &s)
    {
      const auto b = s.find_first_not_of(" \t\r");
      const auto e = s.find_last_not_of(" \t\r");
      return b == std::string::npos ? "" : s.substr(b, e - b + 1);
    }

    /// Levenshtein distance of @p a and @p b, case ignored.
    std::size_t edit_distance(const std::string &a, const std::string &b)
    {
      std::vector<std::size_t> row(b.size() + 1);
      for (std::size_t j = 0; j <= b.size(); ++j)
        row[j] = j;
      for (std::size_t i = 1; i <= a.size(); ++i)
        {
          std::size_t diagonal = row[0];
          row[0]               = i;
          for (std::size_t j = 1; j <= b.size(); ++j)
            {
              const bool        same = std::tolower(static_cast<unsigned char>(a[i - 1])) ==
                                std::tolower(static_cast<unsigned char>(b[j - 1]));
              const std::size_t next = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (same ? 0 : 1)});
              diagonal               = row[j];
              row[j]                 = next;
            }
        }
      return row[b.size()];
    }
  } // namespace

  std::string ParameterFile::nearest_entry_hint(const std::string &path) const
  {
    std::string best;
    std::size_t best_distance = std::string::npos;
    for (const auto &[declared, value] : resolved())
      {
        const std::size_t d = edit_distance(path, declared);
        if (d < best_distance)
          {
            best          = declared;
            best_distance = d;
          }
      }
    return best_distance <= std::max<std::size_t>(2, path.size() / 3) ? " (did you mean '" + best + "'?)" : "";
  }

  ParameterFile::ParameterFile(dealii::ParameterHandler &prm)
    : prm(prm)
  {}

  std::vector<std::string> ParameterFile::split_path(const std::string &path)
  {
    std::vector<std::string> parts;
    std::string              item;
    std::istringstream       is(path);
    while (std::getline(is, item, '/'))
      parts.push_back(trim(item));
    return parts;
  }

  void ParameterFile::parse(const std::string &filename)
  {
    file = filename;
    std::error_code ec;
    if (std::filesystem::exists(filename, ec) && !std::filesystem::is_regular_file(filename, ec))
      throw InputError(filename + ": not a regular file (expected a .prm parameter file)");
    std::ifstream in(filename);
    if (!in)
      throw InputError(filename + ": cannot open the parameter file (missing or unreadable)");
    std::ostringstream buffer;
    buffer << in.rdbuf();
    text = buffer.str();

    // Record the line of every "set" so later checks can point at it.
    std::vector<std::string> sections;
    std::istringstream       is(text);
    std::string              line;
    unsigned int             number = 0;
    static const std::regex  sub_re("^\\s*subsection\\s+(.*?)\\s*$", std::regex::icase);
    static const std::regex  end_re("^\\s*end\\s*$", std::regex::icase);
    static const std::regex  set_re("^\\s*set\\s+(.*?)\\s*=.*$", std::regex::icase);
    while (std::getline(is, line))
      {
        ++number;
        const std::string code = line.substr(0, line.find('#'));
        std::smatch       m;
        if (std::regex_match(code, m, sub_re))
          sections.push_back(trim(m[1]));
        else if (std::regex_match(code, end_re) && !sections.empty())
          sections.pop_back();
        else if (std::regex_match(code, m, set_re))
          {
            std::string path;
            for (const auto &s : sections)
              path += s + "/";
            lines[path + trim(m[1])] = number;
          }
      }

    try
      {
        prm.parse_input(filename);
      }
    catch (const dealii::ParameterHandler::ExcInvalidEntryForPattern &e)
      {
        // deal.II: "Line <N> of file <F>: The entry value <V> for the entry named
        // <E> does not match the given pattern <P>." -> our FILE:LINE form with the path.
        static const std::regex re("Line <(\\d+)> of file <[^>]*>: The entry value <(.*)> for the entry "
                                   "named <(.*)> does not match the given pattern <(.*)>\\.?");
        const std::string info = describe(e);
        std::smatch       m;
        if (std::regex_match(info, m, re))
          {
            const unsigned int line = std::stoul(m[1]);
            std::string        path = m[3];
            for (const auto &[p, l] : lines)
              if (l == line)
                path = p;
            throw InputError(filename + ":" + std::to_string(line) + ": entry '" + path + "' = '" +
                             std::string(m[2]) + "': expected a value matching " + std::string(m[4]));
          }
        throw InputError(filename + ": " + info);
      }
    catch (const dealii::ExceptionBase &e)
      {
        const std::string      info = describe(e);
        static const std::regex undeclared("Line <(\\d+)> of file <[^>]*>: No entry with name <(.*)> was declared.*");
        static const std::regex subsection(".*There is no such subsection to be entered: (.*)");
        std::smatch             m;
        std::string             hint;
        if (std::regex_match(info, m, undeclared))
          {
            for (const auto &[p, l] : lines)
              if (l == std::stoul(m[1]))
                hint = nearest_entry_hint(p);
          }
        else if (std::regex_match(info, m, subsection) && trim(m[1]) == "Study")
          hint = " (a study file: run it with `tribo study` or `tribo tradeoff`)";
        throw InputError(filename + ": " + info + hint);
      }
  }

  void ParameterFile::set(const std::string &assignment)
  {
    const auto eq = assignment.find('=');
    if (eq == std::string::npos)
      throw InputError("--set '" + assignment + "': expected \"Subsection/Entry=value\"");
    const std::string path  = trim(assignment.substr(0, eq));
    const std::string value = trim(assignment.substr(eq + 1));
    auto parts = split_path(path);
    if (parts.empty() || parts.back().empty() || value.empty())
      throw InputError("--set '" + assignment + "': expected \"Subsection/Entry=value\"");
    const std::string entry = parts.back();
    parts.pop_back();
    unsigned int depth    = 0;
    bool         declared = true;
    try
      {
        for (const auto &s : parts)
          {
            if (!prm.subsection_path_exists({s}))
              throw InputError("--set '" + assignment + "': there is no subsection '" + s +
                               "' (see `tribo params`)");
            prm.enter_subsection(s);
            ++depth;
          }
        try
          {
            prm.set(entry, value);
          }
        catch (const dealii::ParameterHandler::ExcEntryUndeclared &)
          {
            declared = false;
          }
      }
    catch (const dealii::ExceptionBase &e)
      {
        for (; depth > 0; --depth)
          prm.leave_subsection();
        throw InputError("--set '" + assignment + "': " + describe(e));
      }
    catch (...)
      {
        for (; depth > 0; --depth)
          prm.leave_subsection();
        throw;
      }
    for (; depth > 0; --depth)
      prm.leave_subsection();
    if (!declared)
      {
        std::string full;
        for (const auto &s : parts)
          full += s + "/";
        full += entry;
        throw InputError("--set '" + assignment + "': there is no entry '" + full + "'" + nearest_entry_hint(full) +
                         " (see `tribo params`)");
      }
    overridden[path] = true;
  }

  std::string ParameterFile::get(const std::string &path) const
  {
    auto              parts = split_path(path);
    const std::string entry = parts.back();
    parts.pop_back();
    return prm.get(parts, entry);
  }

  double ParameterFile::get_double(const std::string &path) const
  {
    const std::string v = get(path);
    try
      {
        std::size_t n = 0;
        const double d = std::stod(v, &n);
        if (trim(v.substr(n)).empty())
          return d;
      }
    catch (const std::exception &)
      {}
    fail(path, "a number");
  }

  long ParameterFile::get_integer(const std::string &path) const
  {
    const std::string v = get(path);
    try
      {
        std::size_t n = 0;
        const long  i = std::stol(v, &n);
        if (trim(v.substr(n)).empty())
          return i;
      }
    catch (const std::exception &)
      {}
    fail(path, "an integer");
  }

  bool ParameterFile::get_bool(const std::string &path) const
  {
    const std::string v = get(path);
    if (v == "true" || v == "yes")
      return true;
    if (v == "false" || v == "no")
      return false;
    fail(path, "true or false");
  }

  std::string ParameterFile::where(const std::string &path) const
  {
    if (overridden.count(path))
      return "--set";
    const auto it = lines.find(path);
    if (it != lines.end())
      return file + ":" + std::to_string(it->second);
    return file + " (default)";
  }

  bool ParameterFile::is_default(const std::string &path) const
  {
    return !overridden.count(path) && !lines.count(path);
  }

  void ParameterFile::fail(const std::string &path, const std::string &expected) const
  {
    throw InputError(where(path) + ": entry '" + path + "' = '" + get(path) + "': expected " +
                     expected);
  }
  std::string demangle_parameter_name(const std::string &s)
  {
    std::string out;
    for (std::size_t i = 0; i < s.size(); ++i)
      if (s[i] == '_' && i + 2 < s.size() && std::isxdigit(s[i + 1]) && std::isxdigit(s[i + 2]))
        {
          out += static_cast<char>(std::stoi(s.substr(i + 1, 2), nullptr, 16));
          i += 2;
        }
      else
        out += s[i];
    return out;
  }

  namespace
  {
    void collect(const boost::property_tree::ptree &tree, const std::string &prefix,
                 std::map<std::string, std::string> &out)
    {
      for (const auto &[key, child] : tree)
        if (child.get_optional<std::string>("value"))
          out[prefix + demangle_parameter_name(key)] = child.get<std::string>("value");
        else if (!child.empty())
          collect(child, prefix + demangle_parameter_name(key) + "/", out);
    }
  } // namespace

  std::map<std::string, std::string> ParameterFile::resolved() const
  {
    std::ostringstream os;
    prm.print_parameters(os, dealii::ParameterHandler::JSON);
    boost::property_tree::ptree tree;
    std::istringstream          is(os.str());
    boost::property_tree::read_json(is, tree);
    std::map<std::string, std::string> out;
    collect(tree, "", out);
    return out;
  }
} // namespace tribo
