/// @file The case entries of the contact law, declared and read in the subsection the
/// application names (ContactLaw::declare(), parse()).

#include "core/parameter_file.h"
#include "dem/laws/contact_law.h"

#include <deal.II/base/parameter_handler.h>

#include <cmath>

namespace tribo::dem
{
  using dealii::Patterns::Double;
  using dealii::Patterns::Selection;

  void ContactLaw::declare(dealii::ParameterHandler &prm)
  {
    prm.declare_entry("Law", "IQS", Selection("IQS|ELAS"),
                      "IQS: cohesive unilateral (inelastic quasi-shock), r_N + gamma >= 0, g >= 0, "
                      "(r_N + gamma) g = 0. ELAS: cohesive elastic, r_N + gamma = max(0, -k g). "
                      "r_N > 0 is compressive; see docs/laws.md.");
    prm.declare_entry("Cohesion", "0", Double(), "Cohesion gamma, N/m (force per unit depth), >= 0.");
    prm.declare_entry("Cohesion range", "0", Double(),
                      "Distance d_w over which the cohesion acts, m, >= 0 (needed if Cohesion > 0).");
    prm.declare_entry("Stiffness", "1e10", Double(),
                      "ELAS normal stiffness k, N/m^2 (force per unit depth per metre of overlap), > 0.");
    prm.declare_entry("Friction coefficient", "0", Double(),
                      "Coulomb friction coefficient between discs, >= 0 (0: frictionless, as in the paper).");
    prm.declare_entry("Overlap recovery", "0", Double(0, 1),
                      "IQS only: fraction in [0, 1] of an existing overlap pushed out per step. 0 freezes "
                      "overlaps as the paper's law does; under high pressure the NLGS's small velocity "
                      "errors then accumulate into overlaps step after step (docs/laws.md); 0.1 keeps "
                      "them at the size of one step's error.");
    prm.declare_entry("Detection distance", "0", Double(),
                      "Pairs closer than this gap (m) enter the contact list; 0 picks a tenth of the "
                      "smallest radius. Always at least the cohesion range.");
  }

  ContactLaw ContactLaw::parse(const ParameterFile &f, const std::string &section)
  {
    ContactLaw law;
    law.section       = {section};
    const auto entry  = [&](const std::string &name) { return law.section.entry(name); };
    law.type          = f.get(entry("Law")) == "IQS" ? Type::iqs : Type::elas;
    law.cohesion      = f.get_checked(entry("Cohesion"), is_non_negative, "a cohesion >= 0 in N/m");
    law.cohesion_range = f.get_checked(entry("Cohesion range"), is_non_negative, "a distance >= 0 in m");
    if (law.cohesion > 0 && law.cohesion_range == 0)
      f.fail(entry("Cohesion range"), "a positive range in m, since " + entry("Cohesion") + " > 0");
    law.stiffness        = f.get_checked(entry("Stiffness"), is_positive, "a positive stiffness in N/m^2");
    law.overlap_recovery = f.get_double(entry("Overlap recovery"));
    law.friction         = f.get_checked(entry("Friction coefficient"), is_non_negative, "a coefficient >= 0");
    law.detection_distance =
      f.get_checked(entry("Detection distance"), is_non_negative, "a distance >= 0 in m");
    return law;
  }
} // namespace tribo::dem
