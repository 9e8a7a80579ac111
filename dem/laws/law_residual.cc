#include "dem/laws/law_residual.h"

#include "dem/engine/body_state.h"

#include <algorithm>
#include <cmath>

namespace tribo::dem
{
  LawResidual law_residual(const std::vector<Contact> &contacts, const BodyState &state,
                           const ContactLaw &law, double theta_h)
  {
    LawResidual  result;
    double       loaded_sum = 0, max_phi2 = 0, min_rate = 0, velocity_sum = 0;
    unsigned int &loaded    = result.loaded;
    const bool   iqs        = law.type == ContactLaw::Type::iqs;
    for (std::size_t i = 0; i < contacts.size(); ++i)
      {
        const Contact        &c  = contacts[i];
        const Eigen::Vector2d u  = state.local_velocity(c);
        const double          rs = c.r.x() + c.cohesion_impulse; // r~
        const double          us = u.x() + c.shift + c.compliance * rs;
        const double          rn_law = std::max(0.0, rs - us / (c.W(0, 0) + c.compliance));
        const double          phi_n  = rs - rn_law;
        double                phi_t  = 0;
        if (law.friction > 0)
          {
            const double bound = law.friction * rn_law;
            phi_t = c.r.y() - std::clamp(c.r.y() - u.y() / c.W(1, 1), -bound, bound);
          }
        const double phi2 = phi_n * phi_n + phi_t * phi_t;
        if (phi2 > max_phi2)
          {
            max_phi2     = phi2;
            result.worst = static_cast<unsigned int>(i);
          }
        if (rs > 0)
          {
            loaded_sum += rs;
            ++loaded;
          }
        velocity_sum += std::abs(us) / (c.W(0, 0) + c.compliance);
        if (iqs)
          min_rate = std::min(min_rate, u.x() + c.shift);
      }
    result.max_phi       = std::sqrt(max_phi2);
    result.mean_impulse   = loaded ? loaded_sum / loaded : 0;
    result.velocity_scale = contacts.empty() ? 0 : velocity_sum / double(contacts.size());
    result.relative       = relative_law_residual(result.max_phi, result.mean_impulse, result.velocity_scale);
    result.gap_violation = theta_h * std::max(0.0, -min_rate);
    return result;
  }
} // namespace tribo::dem
