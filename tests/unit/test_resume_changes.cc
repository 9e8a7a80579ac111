// What a resumed run may change (app/run.h, resume_changes): exact messages and log
// texts, including a checkpoint written before an entry was declared.
#include "app/run.h"
#include "core/errors.h"
#include "core/parameter_file.h"

#include <deal.II/base/parameter_handler.h>

#include <gtest/gtest.h>

#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <map>
#include <string>

namespace
{
  using namespace tribo;

  /// A case file with "Simulation/End time", "Solver/Tolerance" and two loading entries,
  /// one of them ("Shear cell/New entry") as if declared after the checkpoint was written.
  struct Case
  {
    dealii::ParameterHandler prm;
    ParameterFile            file{prm};

    /// @p prediction_depth: also declare "Shear cell/Upper body prediction depth".
    explicit Case(const std::string &body, bool prediction_depth = false)
    {
      prm.enter_subsection("Simulation");
      prm.declare_entry("End time", "1e-6", dealii::Patterns::Double(0));
      prm.leave_subsection();
      prm.enter_subsection("Solver");
      prm.declare_entry("Tolerance", "1e-4", dealii::Patterns::Double(0));
      prm.leave_subsection();
      prm.enter_subsection("Shear cell");
      prm.declare_entry("Pressure", "1e8", dealii::Patterns::Double(0));
      prm.declare_entry("New entry", "0.5", dealii::Patterns::Double(0));
      if (prediction_depth)
        prm.declare_entry("Upper body prediction depth", "0", dealii::Patterns::Double(0));
      prm.leave_subsection();
      // One file per test and process: ctest runs these tests concurrently.
      const std::string name = ::testing::TempDir() + "resume_case_" +
                               ::testing::UnitTest::GetInstance()->current_test_info()->name() + "_" +
                               std::to_string(::getpid()) + ".prm";
      std::ofstream(name) << body;
      file.parse(name);
      std::remove(name.c_str());
    }
  };

  /// The checkpoint of the older program: no "Shear cell/New entry".
  const std::map<std::string, std::string> saved = {{"Simulation/End time", "1e-6"},
                                                    {"Solver/Tolerance", "1e-4"},
                                                    {"Shear cell/Pressure", "1e8"}};

  std::string message(const std::map<std::string, std::string> &before, Case &c)
  {
    try
      {
        app::resume_changes(before, c.file, "out");
      }
    catch (const InputError &e)
      {
        return e.what();
      }
    return "(accepted)";
  }
} // namespace

TEST(ResumeChanges, NothingChangedGivesAnEmptyLogText)
{
  Case c("");
  auto same = saved;
  same["Shear cell/New entry"] = "0.5";
  EXPECT_EQ(app::resume_changes(same, c.file, "out"), "");
}

TEST(ResumeChanges, SolverAndEndTimeMayChangeAndAreLogged)
{
  Case c("subsection Solver\n  set Tolerance = 5e-4\nend\nsubsection Simulation\n  set End time = 2e-6\nend\n");
  auto same = saved;
  same["Shear cell/New entry"] = "0.5";
  EXPECT_EQ(app::resume_changes(same, c.file, "out"),
            "; changed: Simulation/End time 1e-6 -> 2e-6, Solver/Tolerance 1e-4 -> 5e-4");
}

TEST(ResumeChanges, TheParticleBodysPredictionDepthMayChange)
{
  auto with_depth = saved;
  with_depth["Shear cell/New entry"] = "0.5";
  with_depth["Shear cell/Upper body prediction depth"] = "0";
  Case c("subsection Shear cell\n  set Upper body prediction depth = 3\nend\n", true);
  EXPECT_EQ(app::resume_changes(with_depth, c.file, "out"), "; changed: Shear cell/Upper body prediction depth 0 -> 3");
}

TEST(ResumeChanges, TheLoadingMayNotChange)
{
  Case c("subsection Shear cell\n  set Pressure = 2e8\nend\n");
  EXPECT_EQ(message(saved, c),
            "--resume out: entry 'Shear cell/Pressure' is '2e8' in the case but '1e8' in the "
            "checkpoint; a resumed run may change only Solver/*, Output/*, Simulation/End time, "
            "Simulation/Most substeps, Simulation/Most substeps on retake and "
            "Shear cell/Upper body prediction depth");
}

TEST(ResumeChanges, AnEntryNewerThanTheCheckpointIsAcceptedAtItsDefault)
{
  Case c("subsection Solver\n  set Tolerance = 5e-4\nend\n");
  EXPECT_EQ(app::resume_changes(saved, c.file, "out"),
            "; changed: Solver/Tolerance 1e-4 -> 5e-4; not in the checkpoint, at their defaults: "
            "Shear cell/New entry = 0.5");
}

TEST(ResumeChanges, AnEntryNewerThanTheCheckpointIsRefusedWhenTheCaseSetsIt)
{
  Case c("subsection Shear cell\n  set New entry = 0.7\nend\n");
  EXPECT_EQ(message(saved, c),
            "--resume out: entry 'Shear cell/New entry' is '0.7' in the case but '(absent)' in the "
            "checkpoint; a resumed run may change only Solver/*, Output/*, Simulation/End time, "
            "Simulation/Most substeps, Simulation/Most substeps on retake and "
            "Shear cell/Upper body prediction depth");
}
