#pragma once
/// @file Checkpoints: the state of a run in one binary file, so that a run killed at any
/// moment resumes from its last checkpoint (`tribo run CASE.prm --resume DIR`).
///
/// The file is a Boost.Serialization binary archive written atomically (NAME.tmp, then
/// renamed): a checkpoint that exists is complete. Each object that carries state between
/// steps saves and loads itself with the two archive types below, in the same order; the
/// archive holds doubles bit for bit, so a resumed run repeats the uninterrupted one
/// exactly (same binary, same machine).

#include <functional>
#include <string>

namespace boost::archive
{
  class binary_oarchive;
  class binary_iarchive;
} // namespace boost::archive

namespace tribo
{
  using CheckpointOut = boost::archive::binary_oarchive;
  using CheckpointIn  = boost::archive::binary_iarchive;

  /// Write a checkpoint to @p path: @p save fills the archive. Atomic.
  void write_checkpoint(const std::string &path, const std::function<void(CheckpointOut &)> &save);

  /// Read the checkpoint @p path with @p load. A missing, truncated or foreign file is an
  /// InputError naming the file. With @p whole false, @p load may read only the start
  /// of the state (e.g. to check the parameters before building anything).
  void read_checkpoint(const std::string &path, const std::function<void(CheckpointIn &)> &load,
                       bool whole = true);
} // namespace tribo
