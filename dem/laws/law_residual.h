#pragma once
/// @file A solver-independent accuracy measure of a contact solve: how far the impulses
/// and the velocities they produce are from the contact law (docs/laws.md, "Law residual").
///
/// For contact i with shifted normal impulse r~ = r_n + gamma h (N s/m), the law's normal
/// velocity u~ = u_n + b + c r~ (m/s; b the law's shift: IQS gap term max(0, g)/(theta h),
/// ELAS g/(theta h); c the ELAS compliance 1/(theta k h^2), 0 for IQS) and
/// rho = 1 / (W_nn + c) (N s/m per m/s), the natural map of the complementarity
/// 0 <= r~ _|_ u~ >= 0 is
///     phi_n = r~ - max(0, r~ - rho u~)                      (N s/m),
/// zero exactly when the law holds. With Coulomb friction mu, rho_t = 1 / W_tt and
///     phi_t = r_t - proj_[-mu r~', mu r~'](r_t - rho_t u_t),  r~' = max(0, r~ - rho u~),
/// the Alart-Curnier map of the sliding law. The relative residual is
///     max_i |phi_i| / mean over loaded contacts (r~ > 0) of r~,
/// so 1e-4 means the worst contact is one ten-thousandth of a mean impulse from its law.
/// When no contact is loaded, the scale is the mean over the contacts of rho |u~| (N s/m),
/// the impulse that would stop each one's normal velocity (with every impulse 0 it is the
/// scale APGS takes when its warm start has no loaded contact, the mean |b_n| / (W_nn + C),
/// dem/solvers/sweep_problem.h), so that a residual of
/// round-off size among separating contacts (1.9e-17 N s/m on an sph body's landing on two
/// ranks) does not read as 1; so does a mean loaded impulse below 1e-12 of that scale, the
/// round-off left on contacts that carry nothing (relative_law_residual()).
/// The gap violation is theta h max(0, -(u_n + b)) over the IQS contacts (m): how far the
/// end-of-step gap is left below what the law allows.

#include "dem/engine/contact.h"
#include "dem/laws/contact_law.h"

#include <vector>

namespace tribo::dem
{
  struct BodyState;

  /// The law residual of a set of contacts (see the file comment).
  struct LawResidual
  {
    double relative      = 0; ///< max |phi| / mean loaded r~, dimensionless
    double max_phi       = 0; ///< max |phi| = max sqrt(phi_n^2 + phi_t^2), N s/m
    double mean_impulse  = 0; ///< mean r~ over the contacts with r~ > 0, N s/m
    unsigned int loaded  = 0; ///< contacts with r~ > 0 (mean_impulse's count)
    /// Mean over the contacts of rho |u~| (N s/m): relative's scale when none is loaded.
    double velocity_scale = 0;
    double gap_violation = 0; ///< theta h max(0, -(u_n + b)) over IQS contacts, m
    unsigned int worst   = 0; ///< index of the contact with the largest |phi|
  };

  /// max |phi| over @p mean_impulse, or with nothing loaded over @p velocity_scale (the file
  /// comment); 1 when both are 0 and max |phi| is not. A mean loaded impulse below 1e-12 of
  /// the velocity scale is round-off left on contacts that carry nothing (2.6e-31 N s/m on two
  /// contacts of the 120-disc cell under the deal.II first body on two ranks), and counts as
  /// nothing loaded.
  inline double relative_law_residual(double max_phi, double mean_impulse, double velocity_scale)
  {
    const double scale = mean_impulse > 1e-12 * velocity_scale ? mean_impulse : velocity_scale;
    return scale > 0 ? max_phi / scale : max_phi > 0 ? 1.0 : 0.0;
  }
  /// The residual of @p contacts (impulses c.r, law terms) against the velocities of
  /// @p state; @p theta_h = theta h (s) turns velocity violations into gap violations.
  LawResidual law_residual(const std::vector<Contact> &contacts, const BodyState &state,
                           const ContactLaw &law, double theta_h);
} // namespace tribo::dem
