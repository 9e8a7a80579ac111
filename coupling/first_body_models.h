#pragma once
/// @file What the scene asks of the upper first-body models without naming one: the
/// table behind the Upper body model entry (coupling/models.cc) seen from outside.

#include <string>
#include <vector>

namespace tribo::coupling
{
  /// Whether model @p model is a wall of discs, a clump in the scene's particle system
  /// (rigid) rather than a FirstBody: the discs then carry its whole state, so a sample
  /// file or a shared compaction carries it too. InputError for an unknown model.
  bool is_wall_of_discs(const std::string &model);

  /// The first-body entries (of the subsection that declares them, without its name) that a
  /// resumed run may change, for any model: entries that say only how the contact solve
  /// predicts a body, not how the body moves.
  const std::vector<std::string> &entries_that_may_change_on_resume();
} // namespace tribo::coupling
