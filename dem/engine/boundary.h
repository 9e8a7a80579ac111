#pragma once
/// @file The coupling interface (../shared/DESIGN.md section 3) for first bodies that
/// are not rigid clumps, and the hybrid half-disc elements that let grains touch them.
///
/// The NSCD solver sees such a body only through a periodic chain of boundary nodes:
/// their positions and velocities at the start of a step, their free velocities
/// (no contact impulse), and the compliance that maps node impulses to node
/// velocity changes. A deal.II body (fem/), an SPH or an MLP body implements it; the
/// rigid clumps stay in ParticleSystem, where their compliance is closed form. Any number
/// of such bodies can be attached to one MoreauJean (an upper and a lower first body);
/// within a step each body's nodes couple only through its own compliance.
///
/// Hybrid half-disc elements (Cao et al. 2011, section 2.1 and Fig. 4): rigid
/// half-discs of diameter D with their flat side on the chain and their round side
/// towards the third body. Rule, the same for the three cases of the paper's Fig. 4
/// (D larger than, equal to or smaller than the edge length l):
/// - n_h = max(1, round(period / D)) half-discs, anchored at the reference abscissae
///   s_k = (k + 1/2) period / n_h: half-disc k is a rigid body carried by the edge A-B
///   that holds s_k (at the fraction xi_k of it), its centre c_k = (1 - xi_k) A + xi_k B,
///   its flat side along AB, turning with the edge at omega = (e x de/dt) / |e|^2,
///   e = B - A;
/// - a grain of radius R at x touches half-disc k when x is on the round side
///   ((x - c_k) . n_e > 0, n_e the edge's outward normal); the gap is
///   g = |x - c_k| - R - D/2, the normal n = (x - c_k)/|x - c_k| and the contact point
///   P = c_k + (D/2 + g/2) n, in the middle of the gap;
/// - the half-disc's velocity at P is that of its material point,
///   v_P = v_c + omega x a = J_A v_A + J_B v_B, a = P - c_k,
///       J_A = (1 - xi_k) I - a_perp e_perp^T / |e|^2,  J_B = xi_k I + a_perp e_perp^T / |e|^2
///   (v_perp = (-v_y, v_x)), and a contact force F on the half-disc goes to the nodes
///   by the transpose, F_A = (1 - xi_k) F - e_perp M / |e|^2, F_B = xi_k F + e_perp M / |e|^2
///   with M = a x F: the force splits as in Cao eq. (2) at the centre and its moment
///   about the centre passes as a couple across the edge (the established code's
///   disc-on-edge element does the same, docs/laws.md);
/// - since a is parallel to n, n . (omega x a) = 0: the solver's normal gap rate
///   n . (v_grain - v_c) is exactly the time derivative of the geometric gap, however
///   the face stretches or turns and whatever D / l.
/// With D = l each half-disc sits on one edge (the paper's choice); with D > l a
/// half-disc overhangs its edge and turns with it; with D < l several half-discs share
/// an edge and their forces add on its two nodes.
///
/// Detection uses the half-discs' displaced centres, binned along x in bins at least
/// one contact reach wide: every half-disc within reach of a grain is tested, however
/// far the face has moved from its reference position.

#include "dem/engine/particle_system.h"

#include <Eigen/Core>

#include <string>
#include <vector>

namespace tribo::dem
{
  struct Contact;

  /// A first body seen by the solver through its boundary nodes (units per unit depth).
  class BoundaryBody
  {
  public:
    virtual ~BoundaryBody() = default;

    /// Number of boundary nodes; node i and node (i + 1) % n end edge i. Nodes are
    /// ordered by increasing reference x in [0, period).
    virtual unsigned int n_nodes() const = 0;
    /// Position of node @p i at the start of the step, m.
    virtual Vec2 node_position(unsigned int i) const = 0;
    /// Velocity of node @p i at the start of the step, m/s.
    virtual Vec2 node_velocity(unsigned int i) const = 0;
    /// Compute the free state of a step @p h (s): the velocities without contact impulses.
    virtual void predict(double h) = 0;
    /// Free velocity of node @p i (after predict()), m/s.
    virtual Vec2 node_free_velocity(unsigned int i) const = 0;
    /// Compliance G (2n x 2n, m/s per N s/m): node velocities change by G R for node
    /// impulses R, index 2i for x and 2i + 1 for y of node i. Constant while the step is.
    virtual const Eigen::MatrixXd &compliance() const = 0;
    /// Complete the step with the node impulses @p impulses (N s/m, one per node).
    virtual void finalize(const std::vector<Vec2> &impulses) = 0;
    /// Kinetic plus stored (elastic) energy at the end of the last step, J/m.
    virtual double energy() const = 0;
    /// Power of the body's external loads over the last step, W/m.
    virtual double external_power() const = 0;
    /// Power dissipated inside the body (damping) over the last step, W/m (>= 0).
    virtual double internal_dissipation() const = 0;
    /// Work the impulses did on the body over the last step beyond R . (v_begin + v_end)/2
    /// with v_begin = node_velocity() read after predict(), / h, W/m: 0 for a body that
    /// takes the impulses into its own implicit step (fem); the stored-energy change of
    /// the position correction of an explicit particle body
    /// (coupling/particle_first_body.h). Booked with the contact power.
    virtual double impulse_extra_power() const { return 0; }
    /// What the overlap guard adds to its message when a grain has passed more than its
    /// radius into something while this body is attached and the contact step was @p h
    /// (s): a body-specific cause and remedy, or nothing.
    virtual std::string overlap_hint(double /*h*/) const { return {}; }
  };

  /// Placement and contacts of the half-disc elements on a BoundaryBody's chain.
  class HalfDiscs
  {
  public:
    /// Half-discs of diameter @p diameter (m) on the chain of @p body, whose round
    /// side faces @p outward (unit vector, e.g. (0, -1) for the bottom face of an
    /// upper body), periodic with @p period (m). Reads the reference abscissae.
    HalfDiscs(const BoundaryBody &body, double diameter, const Vec2 &outward, double period);

    unsigned int count() const { return centre_abscissa.size(); }
    double       radius() const { return 0.5 * diameter; }

    /// Centres of the half-discs for node positions @p nodes (m, not wrapped).
    std::vector<Vec2> centres(const std::vector<Vec2> &nodes) const;

    /// Contacts of the discs of @p system (centres @p disc_centres, wrapped into
    /// [0, period)) with the half-discs at node positions @p nodes, for gaps up to
    /// @p distance. Fills geometry, node indices and node maps; side 0 is the
    /// half-disc, side 1 the grain's body (its arms are set).
    /// With @p disc_motion (one per disc) and @p node_motion (one per node), how far each
    /// may move before the next detection (m), a pair further apart is a contact too when
    /// their motions close it, gap <= -(m_disc - m_centre).n with n from the half-disc to
    /// the grain and m_centre the nodes' motions interpolated as the centre is, as
    /// ContactDetector::detect does for two discs and with its cap: relative motions of at
    /// most ContactDetector::max_motion_reach largest radii are looked for.
    std::vector<Contact> detect(const ParticleSystem &system, const std::vector<Vec2> &disc_centres,
                                const std::vector<double> &disc_angles_of_bodies,
                                const std::vector<Vec2> &nodes, double distance,
                                const std::vector<Vec2> &disc_motion = {},
                                const std::vector<Vec2> &node_motion = {}) const;

  private:
    /// Where half-disc @p k is for node positions @p nodes: its centre (m, near its
    /// reference abscissa) and the vector e = B - A of its edge (m).
    struct Placement
    {
      Vec2 centre, edge;
    };
    Placement placement(unsigned int k, const std::vector<Vec2> &nodes) const;
    /// Edge holding abscissa @p s (wrapped) and the weight xi of its second node.
    std::pair<unsigned int, double> locate(double s) const;

    double              diameter;
    /// +1 if the round side faces +e_perp (e along +x in the reference: outward +y),
    /// -1 if it faces -e_perp (the bottom face of an upper body).
    double              side;
    double              period;
    std::vector<double> node_abscissa;   ///< reference x of the nodes, increasing
    std::vector<double> centre_abscissa; ///< s_k
    std::vector<unsigned int> anchor_edge; ///< edge holding s_k
    std::vector<double>       anchor_xi;   ///< xi_k, the fraction of that edge at s_k
  };
} // namespace tribo::dem
