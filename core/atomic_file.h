#pragma once
/// @file Files written whole or not at all.

#include <string>

namespace tribo
{
  /// Write @p content to @p path atomically (temporary file, then rename); RunError if
  /// it cannot be written.
  void atomic_write(const std::string &path, const std::string &content);
} // namespace tribo
