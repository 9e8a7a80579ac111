/// @file Any deformable model as the scene's FirstBody: the DeformableBody touched by the
/// grains through half-disc elements on its bottom face (dem/engine/boundary.h), their bottom on
/// the placement's surface.

#include "coupling/models.h"

#include "dem/engine/moreau_jean.h"

#include <cmath>

namespace tribo::coupling
{
  namespace
  {
    class HalfDiscBody : public FirstBody
    {
    public:
      /// @p half_disc: the elements' diameter, m; @p length: the period, m.
      HalfDiscBody(std::unique_ptr<DeformableBody> body, double half_disc, double length)
        : body(std::move(body)), half_disc(half_disc), length(length)
      {
        for (unsigned int i = 0; i < this->body->n_nodes(); ++i)
          face_start.push_back(this->body->node_position(i).x());
      }

      unsigned int system_body() const override { return no_system_body; }
      double       y_to_surface() const override { return 0.5 * half_disc; }
      double       half_disc_diameter() const override { return half_disc; }
      double       load_time(double t, double start) const override { return t - start; }
      void attach(dem::MoreauJean &mj) override { mj.attach(*body, half_disc, {0, -1}, length); }

      /// The body ramps its own load, with the same law; the compaction damping goes when
      /// shearing starts.
      void before_step(dem::ParticleSystem &, double, bool sliding) override
      {
        if (sliding)
          body->start_shearing();
      }

      FirstBodyState state(const dem::ParticleSystem &, const std::vector<double> &) const override
      {
        const double y = body->mean_bottom_y();
        return {y, body->mean_bottom_vy(), y - 0.5 * half_disc, body->external_power(), body->kinetic_energy(),
                body->stored_energy()};
      }

      /// sum_i (x_i - x_i(0)) / n over the chain nodes, each minimum image over L.
      double face_shift() const override
      {
        double sum = 0;
        for (unsigned int i = 0; i < face_start.size(); ++i)
          {
            const double dx = body->node_position(i).x() - face_start[i];
            sum += dx - length * std::round(dx / length);
          }
        return sum / face_start.size();
      }
      bool in_energy_balance() const override { return true; }
      std::vector<std::string> write_fields(const std::string &dir, unsigned int index) const override
      {
        return {body->write_fields(dir, index)};
      }
      std::string describe() const override { return body->describe(); }
      void        summarize(JsonObject &j) const override { body->summarize(j); }
      void        save(CheckpointOut &ar) const override { body->save(ar); }
      void        load(CheckpointIn &ar) override { body->load(ar); }

    private:
      std::unique_ptr<DeformableBody> body;
      double                          half_disc, length;
      std::vector<double>             face_start; ///< x of its chain nodes at the start, m
    };
  } // namespace

  std::unique_ptr<FirstBody> place_on_half_discs(const FirstBodyParameters &p, const FirstBodyPlacement &where)
  {
    const double        half_disc = p.half_disc_diameter > 0 ? p.half_disc_diameter : p.length / chain_nodes(p);
    FirstBodyParameters placed    = p;
    placed.bottom                 = where.surface + 0.5 * half_disc;
    return std::make_unique<HalfDiscBody>(make_deformable_body(placed), half_disc, p.length);
  }
} // namespace tribo::coupling
