// Closed-form local solves of the IQS and ELAS laws (dem/laws/contact_law.h).
#include "dem/laws/contact_law.h"

#include <gtest/gtest.h>

#include <Eigen/LU>

#include <random>
#include <sstream>

using tribo::dem::ContactLaw;

namespace
{
  const double h = 1e-8, theta = 0.5;

  Eigen::Matrix2d diagonal(double wn, double wt)
  {
    Eigen::Matrix2d W;
    W << wn, 0, 0, wt;
    return W;
  }
} // namespace

TEST(Laws, IqsStopsAClosingContactAtZeroGap)
{
  ContactLaw law;
  const Eigen::Matrix2d W = diagonal(2e8, 6e8);
  const double g = -1e-9; // overlap: frozen, target u_n >= 0
  const Eigen::Vector2d u_other(-3.0, 0.0);
  const auto r = law.solve(W, u_other, law.terms(g, h, theta));
  EXPECT_NEAR(r.x(), 3.0 / 2e8, 1e-20);
  EXPECT_EQ(r.y(), 0.0);
  EXPECT_NEAR(W(0, 0) * r.x() + u_other.x(), 0.0, 1e-12);
}

TEST(Laws, IqsAllowsTheOpenGapToCloseWithinTheStep)
{
  ContactLaw law;
  const Eigen::Matrix2d W = diagonal(2e8, 6e8);
  const double g = 1e-8; // open gap: u_n may reach -g/(theta h) = -2 m/s
  // Closing at 1 m/s would not close the gap within the step: no impulse.
  EXPECT_EQ(law.solve(W, {-1.0, 0}, law.terms(g, h, theta)).x(), 0.0);
  // Closing at 5 m/s: the impulse brings u_n to exactly -g/(theta h).
  const auto r = law.solve(W, {-5.0, 0}, law.terms(g, h, theta));
  EXPECT_NEAR(W(0, 0) * r.x() - 5.0, -g / (theta * h), 1e-9);
}

TEST(Laws, IqsSeparatingContactHasNoImpulse)
{
  ContactLaw law;
  EXPECT_EQ(law.solve(diagonal(1e8, 1e8), {0.5, 0.3}, law.terms(-1e-10, h, theta)).norm(), 0.0);
}

TEST(Laws, CohesionPullsWithGammaWithinRangeOnly)
{
  ContactLaw law;
  law.cohesion       = 2.0;  // N/m
  law.cohesion_range = 5e-9; // m
  const Eigen::Matrix2d W = diagonal(1e8, 1e8);
  // Separating inside the range: r_n = -gamma h exactly.
  EXPECT_DOUBLE_EQ(law.solve(W, {5.0, 0}, law.terms(1e-9, h, theta)).x(), -2.0 * h);
  // Separating slowly inside the range: the pull would close the gap within the
  // step, so the contact limits it: u_n = -g/(theta h) at the end.
  const auto rs = law.solve(W, {1.0, 0}, law.terms(1e-9, h, theta));
  EXPECT_NEAR(W(0, 0) * rs.x() + 1.0, -1e-9 / (theta * h), 1e-12);
  EXPECT_GT(rs.x(), -2.0 * h);
  // Beyond the range: nothing.
  EXPECT_EQ(law.solve(W, {1.0, 0}, law.terms(6e-9, h, theta)).x(), 0.0);
  // Closing at contact: shifted Signorini, r_n + gamma h = -u_other,n/W_nn + gamma h... exactly
  // u_n = 0 at the end: r_n = -u_other / W_nn.
  const auto r = law.solve(W, {-3.0, 0}, law.terms(0.0, h, theta));
  EXPECT_NEAR(r.x(), 3.0 / 1e8, 1e-20);
  EXPECT_GE(r.x() + 2.0 * h, 0.0);
}

TEST(Laws, ElasIsASpringOnTheEndOfStepGap)
{
  ContactLaw law;
  law.type      = ContactLaw::Type::elas;
  law.stiffness = 1e10;
  const Eigen::Matrix2d W = diagonal(2e8, 2e8);
  const double g = -2e-9;
  const Eigen::Vector2d u_other(-1.0, 0);
  const auto   r  = law.solve(W, u_other, law.terms(g, h, theta));
  const double un = W(0, 0) * r.x() + u_other.x();
  // r_n = h k max(0, -(g + theta h u_n)): the closed form holds at the solution.
  EXPECT_NEAR(r.x(), h * law.stiffness * -(g + theta * h * un), 1e-12 * std::abs(r.x()));
  EXPECT_GT(r.x(), 0.0);
  // An open gap that stays open: no force.
  EXPECT_EQ(law.solve(W, {-0.01, 0}, law.terms(1e-9, h, theta)).x(), 0.0);
}

TEST(Laws, ElasWithCohesionShiftsTheForceByGamma)
{
  ContactLaw law;
  law.type           = ContactLaw::Type::elas;
  law.stiffness      = 1e10;
  law.cohesion       = 1.0;
  law.cohesion_range = 1e-9;
  const Eigen::Matrix2d W = diagonal(2e8, 2e8);
  const double g = -1e-9;
  const Eigen::Vector2d u_other(0.2, 0);
  const auto   r  = law.solve(W, u_other, law.terms(g, h, theta));
  const double un = W(0, 0) * r.x() + u_other.x();
  // r_n + gamma h = h k max(0, -(g + theta h u_n)).
  const double spring = h * law.stiffness * std::max(0.0, -(g + theta * h * un));
  EXPECT_NEAR(r.x() + law.cohesion * h, spring, 1e-12 * spring);
}

TEST(Laws, CoulombSticksInsideTheConeAndSlidesOnIt)
{
  ContactLaw law;
  law.friction = 0.3;
  const Eigen::Matrix2d W = diagonal(1e8, 3e8);
  // Mostly normal approach: stick, both velocity components brought to zero.
  auto r = law.solve(W, {-2.0, 0.1}, law.terms(0.0, h, theta));
  EXPECT_NEAR((W * r + Eigen::Vector2d(-2.0, 0.1)).norm(), 0.0, 1e-12);
  EXPECT_LE(std::abs(r.y()), law.friction * r.x());
  // Strong tangential velocity: slide with |r_t| = mu r_n opposing the slip.
  r = law.solve(W, {-2.0, 10.0}, law.terms(0.0, h, theta));
  EXPECT_NEAR(std::abs(r.y()), law.friction * r.x(), 1e-20);
  EXPECT_LT(r.y(), 0.0);
  EXPECT_NEAR(W(0, 0) * r.x() - 2.0, 0.0, 1e-12); // normal velocity closed
  const double ut = W(1, 1) * r.y() + 10.0;
  EXPECT_GT(ut, 0.0); // still slipping forward, the friction opposes it
}

namespace
{
  /// The Coulomb law on the shifted impulse r~ for u = W~ r~ + q, checked case-free:
  /// 0 <= r~_n _|_ u_n >= 0, |r~_t| <= mu r~_n, and either stick (u_t = 0) or slide
  /// against the slip (r~_t = -mu r~_n sign(u_t)). Tolerances relative to the terms.
  ::testing::AssertionResult satisfies_coulomb(const Eigen::Matrix2d &Wt, const Eigen::Vector2d &q,
                                               double mu, const Eigen::Vector2d &r)
  {
    const Eigen::Vector2d u     = Wt * r + q;
    const double          scale = (Wt.cwiseAbs() * r.cwiseAbs()).maxCoeff() + q.cwiseAbs().maxCoeff();
    const double          tol   = 1e-9 * scale;
    const double          rtol  = 1e-9 * r.cwiseAbs().maxCoeff();
    std::ostringstream    os;
    os << "r = " << r.transpose() << ", u = " << u.transpose() << ", mu = " << mu << ", W~ = ["
       << Wt.row(0) << "; " << Wt.row(1) << "], q = " << q.transpose();
    if (r.x() < -rtol || u.x() < -tol || std::abs(r.x() * u.x()) > tol * r.cwiseAbs().maxCoeff())
      return ::testing::AssertionFailure() << "Signorini fails: " << os.str();
    if (std::abs(r.y()) > mu * r.x() + rtol)
      return ::testing::AssertionFailure() << "outside the cone: " << os.str();
    const bool stick = std::abs(u.y()) <= tol;
    const bool slide = std::abs(std::abs(r.y()) - mu * r.x()) <= rtol && r.y() * u.y() <= tol * std::abs(r.y());
    if (!stick && !slide)
      return ::testing::AssertionFailure() << "neither stick nor slide against the slip: " << os.str();
    return ::testing::AssertionSuccess();
  }
} // namespace

TEST(Laws, CoulombOnCoupledBlocksSatisfiesTheLawEverywhere)
{
  // Random symmetric positive definite blocks, coupling W_nt up to 0.999 sqrt(W_nn W_tt)
  // (clumps and half-discs: a large lever arm), mu in [0, 3], closing and opening q, with
  // and without cohesion and ELAS compliance: every returned impulse satisfies the law,
  // checked case by case above rather than by the solver's own enumeration.
  std::mt19937                           gen(11);
  std::uniform_real_distribution<double> U(0, 1);
  unsigned int                           cases[4] = {0, 0, 0, 0};
  for (int trial = 0; trial < 20000; ++trial)
    {
      ContactLaw law;
      law.friction       = 3 * U(gen);
      law.cohesion       = trial % 3 == 0 ? 2.0 : 0.0;
      law.cohesion_range = 1e-8;
      if (trial % 4 == 1)
        {
          law.type      = ContactLaw::Type::elas;
          law.stiffness = 1e9;
        }
      const double wn = 1e8 * (0.1 + 2 * U(gen)), wt = 1e8 * (0.1 + 2 * U(gen));
      const double coupling = (2 * U(gen) - 1) * (trial % 2 ? 0.999 : 0.5);
      Eigen::Matrix2d W;
      W << wn, coupling * std::sqrt(wn * wt), coupling * std::sqrt(wn * wt), wt;
      const Eigen::Vector2d u_other(6 * U(gen) - 4, 6 * U(gen) - 3);
      const auto            terms = law.terms(1e-9 * (2 * U(gen) - 1), h, theta);
      const Eigen::Vector2d r     = law.solve(W, u_other, terms);
      // The shifted problem the law is written on.
      Eigen::Matrix2d Wt = W;
      Wt(0, 0) += terms.compliance;
      const Eigen::Vector2d q(u_other.x() - W(0, 0) * terms.cohesion_impulse + terms.shift,
                              u_other.y() - W(1, 0) * terms.cohesion_impulse);
      const Eigen::Vector2d rs(r.x() + terms.cohesion_impulse, r.y());
      ASSERT_TRUE(satisfies_coulomb(Wt, q, law.friction, rs)) << "trial " << trial;
      // Which case it was, so that the test is seen to cover all of them.
      const Eigen::Vector2d u = Wt * rs + q;
      if (rs.x() == 0)
        ++cases[0];
      else if (std::abs(u.y()) <= 1e-9 * q.cwiseAbs().maxCoeff())
        ++cases[1];
      else
        ++cases[rs.y() > 0 ? 2 : 3];
    }
  // No contact, stick, slide + and slide -, each many times.
  for (int k = 0; k < 4; ++k)
    EXPECT_GT(cases[k], 1000u) << "case " << k;
}

TEST(Laws, CoulombWithoutASolutionFailsLoudly)
{
  // A block that is not positive definite (det < 0) with a closing contact: stick is
  // undefined, sliding one way has a negative denominator, the other way slides with
  // the slip: no case satisfies the law, and the solve says so instead of returning 0.
  ContactLaw law;
  law.friction = 1;
  Eigen::Matrix2d W;
  W << 1, 2, 2, 1;
  try
    {
      law.solve(W, {-1.0, 0.0}, law.terms(1e-9, h, theta));
      FAIL() << "expected a RunError";
    }
  catch (const tribo::RunError &e)
    {
      EXPECT_NE(std::string(e.what()).find("the frictional local problem has no solution (mu = 1"),
                std::string::npos)
        << e.what();
    }
}
