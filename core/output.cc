#include "core/output.h"

#include "core/errors.h"

#include <boost/archive/binary_iarchive.hpp>
#include <boost/archive/binary_oarchive.hpp>
#include <boost/serialization/string.hpp>
#include <boost/serialization/vector.hpp>

#include <cmath>
#include <cstdio>
#include <iomanip>
#include <iostream>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace tribo
{
  TimeSeries::TimeSeries(std::vector<std::string> columns)
    : names(std::move(columns))
  {}

  void TimeSeries::add_row(const std::vector<double> &row)
  {
    if (row.size() != names.size())
      throw std::logic_error("TimeSeries: row of " + std::to_string(row.size()) +
                             " values for " + std::to_string(names.size()) + " columns");
    data.push_back(row);
  }

  std::vector<double> TimeSeries::column(const std::string &name) const
  {
    for (std::size_t c = 0; c < names.size(); ++c)
      if (names[c] == name)
        {
          std::vector<double> v;
          v.reserve(data.size());
          for (const auto &r : data)
            v.push_back(r[c]);
          return v;
        }
    throw std::out_of_range("no column " + name);
  }

  std::string TimeSeries::to_csv() const
  {
    std::ostringstream os;
    os << std::setprecision(std::numeric_limits<double>::max_digits10);
    for (std::size_t c = 0; c < names.size(); ++c)
      os << (c ? "," : "") << names[c];
    os << '\n';
    for (const auto &r : data)
      {
        for (std::size_t c = 0; c < r.size(); ++c)
          os << (c ? "," : "") << r[c];
        os << '\n';
      }
    return os.str();
  }

  namespace
  {
    std::string json_escape(const std::string &s)
    {
      std::string out = "\"";
      for (const char c : s)
        switch (c)
          {
            case '"': out += "\\\""; break;
            case '\\': out += "\\\\"; break;
            case '\n': out += "\\n"; break;
            case '\t': out += "\\t"; break;
            default:
              if (static_cast<unsigned char>(c) < 0x20)
                {
                  char buf[8];
                  std::snprintf(buf, sizeof buf, "\\u%04x", c);
                  out += buf;
                }
              else
                out += c;
          }
      return out + "\"";
    }
  } // namespace

  void JsonObject::put(const std::string &key, std::string json_text)
  {
    for (auto &item : items)
      if (item.first == key)
        {
          item.second = std::move(json_text);
          return;
        }
    items.emplace_back(key, std::move(json_text));
  }

  void JsonObject::set(const std::string &key, double value)
  {
    if (!std::isfinite(value))
      return put(key, "null"); // JSON has no NaN or infinity
    std::ostringstream os;
    os << std::setprecision(std::numeric_limits<double>::max_digits10) << value;
    put(key, os.str());
  }

  void JsonObject::set(const std::string &key, long value) { put(key, std::to_string(value)); }
  void JsonObject::set(const std::string &key, const std::string &value) { put(key, json_escape(value)); }
  void JsonObject::set(const std::string &key, bool value) { put(key, value ? "true" : "false"); }
  void JsonObject::set(const std::string &key, const JsonObject &value) { put(key, value.to_string(1)); }

  std::string JsonObject::to_string(unsigned int indent) const
  {
    const std::string pad(2 * indent, ' ');
    std::string       s = "{\n";
    for (std::size_t i = 0; i < items.size(); ++i)
      {
        const std::string &value = items[i].second;
        s += pad + "  " + json_escape(items[i].first) + ": " + value +
             (i + 1 < items.size() ? ",\n" : "\n");
      }
    return s + pad + "}" + (indent == 0 ? "\n" : "");
  }

  void Log::open(const std::string &path, bool echo_to_terminal)
  {
    echo = echo_to_terminal;
    if (path.empty())
      return;
    file.open(path, std::ios::app);
    if (!file)
      throw RunError("cannot write " + path);
  }

  void Log::operator()(const std::string &message)
  {
    if (file.is_open())
      file << message << '\n' << std::flush;
    if (echo)
      std::cout << message << std::endl;
  }
  void Log::error(const std::string &message)
  {
    if (file.is_open())
      file << "error: " << message << '\n' << std::flush;
    if (file.is_open() || echo)
      std::cerr << "error: " << message << std::endl;
  }

  void TimeSeries::save(CheckpointOut &ar) const
  {
    ar << names << data;
  }

  void TimeSeries::load(CheckpointIn &ar)
  {
    std::vector<std::string> saved;
    ar >> saved;
    if (!names.empty() && saved != names)
      throw InputError("checkpoint: its statistics columns differ from this case's "
                       "(another scene or another version of tribo)");
    names = saved;
    ar >> data;
  }
} // namespace tribo
