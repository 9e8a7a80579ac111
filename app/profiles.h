#pragma once
/// @file Profiles across the gap of a shear cell: layers parallel to the walls,
/// accumulated at every step of the shearing phase in consecutive blocks of steps (the
/// profile samples), and averaged over the blocks of the steady state.
///
/// The gap between the first bodies' surfaces, from y_L + a (y_L the lower wall's
/// centre line, a the mean wall-disc radius) to the upper surface given by the scene
/// (a rigid wall: its centre line - a; a deformable body: its bottom face minus the
/// half-disc radius), is cut into n layers of equal
/// thickness, n fixed at the first step accumulated (about one mean diameter each).
/// Per layer and step (a sample is the mean over the steps of its block):
/// - vx: mean x-velocity of the free discs whose centre lies in the layer
///   (Cao et al. 2011 eq. 14; grains whose centre is beyond a wall surface,
///   nestled between wall discs, count in the layer next to that wall), m/s;
/// - solid_fraction: area of all discs inside the layer / layer area (exact
///   circle-strip areas, walls included);
/// - stress: Love-Weber average over the layer, sigma = -(1/A) sum_P sum_c f_c (x) l_c,
///   with f_c the contact force on free disc P and l_c from P's centre to the
///   contact point (Cao et al. eq. 15 with vol(P) replaced by the layer area A),
///   each term shared among the layers that its lever arm l_c crosses, in
///   proportion to the height of l_c in each. A layer in static equilibrium then
///   carries exactly the mean force transmitted across its horizontal planes:
///   sigma_yy = P. Compression positive, Pa. sigma_xy: x-force per unit length
///   transmitted across a horizontal plane;
/// - power_dissipated: sum of -P_c (MoreauJean::contact_power()) over the contacts whose
///   contact point lies in the layer, W/m (per metre of depth; the layers sum to the
///   step's contact dissipation, statistics.csv power_dissipated);
/// - granular_temperature: (1/2) mean over the layer's free discs of |v - v_k|^2, v_k
///   their mean velocity in that layer at that step, m^2/s^2 (0 for fewer than 2 discs).

#include "core/checkpoint.h"
#include "dem/engine/moreau_jean.h"
#include "dem/engine/particle_system.h"

#include <string>
#include <utility>
#include <vector>

namespace tribo::app
{
  class LayerProfiles
  {
  public:
    /// Quantities per layer, in this order in every sample.
    static const std::vector<std::string> &quantity_names();

    /// @p lower, @p upper: the wall bodies (@p upper = no_body when the upper first
    /// body is not a rigid body of the system); @p wall_inset: a, m (the lower wall's
    /// surface is its centre line + a); @p layer_target: wanted layer thickness, m.
    LayerProfiles(unsigned int lower, unsigned int upper, double wall_inset, double layer_target);
    static constexpr unsigned int no_body = ~0u;

    /// Add the state after a step of @p mj to the current block (its contacts' forces are
    /// their impulses over MoreauJean::step_length()), with the upper first body's surface at
    /// height @p upper_surface (m).
    void accumulate(const dem::ParticleSystem &system, const dem::MoreauJean &mj, double upper_surface);
    /// Close the current block as one sample, at time @p t_begin (s: the beginning of its
    /// first step); nothing without accumulated steps.
    void end_block(double t_begin);

    /// Mean over the samples with time >= @p t_start: one row per layer,
    /// columns: layer, y (layer centre above the lower wall surface, m), y_over_h
    /// (y over the gap between the wall surfaces), then quantity_names(), n_samples,
    /// then the standard error of each quantity's mean, `<name>_stderr`, by batch means
    /// over the samples in time order (batch_standard_error(), steady_state.h).
    std::vector<std::vector<double>> average(double t_start) const;
    static std::vector<std::string> average_columns();

    /// Mean over the samples with time >= @p t_start of @p quantity averaged over the
    /// layers 2 .. n - 3 (at least two layers from each wall), and its batch-means
    /// standard error (steady_state.h) over the per-sample layer averages; NaN with fewer
    /// than 5 layers or no sample.
    std::pair<double, double> interior_mean(const std::string &quantity, double t_start) const;

    unsigned int n_layers() const { return layers; }
    unsigned int n_samples() const { return times.size(); }
    /// Steps accumulated in the current, open block.
    unsigned int n_open_steps() const { return block_steps; }
    unsigned int n_samples_after(double t_start) const;
    /// Checkpoint: the samples taken so far.
    void save(CheckpointOut &ar) const;
    void load(CheckpointIn &ar);

  private:
    unsigned int lower, upper;
    double       inset, target;
    unsigned int layers = 0;
    std::vector<double> times;
    std::vector<double> gap;       ///< mean gap between the wall surfaces per sample, m
    /// data[sample][layer * n_quantities + q]
    std::vector<std::vector<double>> data;
    /// The open block: sums over its steps of the rows and of the gap.
    std::vector<double> block_sum;
    double              block_gap   = 0;
    unsigned int        block_steps = 0;
  };

  /// Area (m^2) of the disc of radius @p r centred at height @p yc between the
  /// horizontal lines y = @p a and y = @p b (a < b).
  double disc_area_between(double yc, double r, double a, double b);
} // namespace tribo::app
