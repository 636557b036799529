// A C++ program built against an installed kincal: the built-in KR 500's forward kinematics equals
// its KDL chain's, its closed-form IK returns the configuration it started from (kincal::core), and
// identification (kincal::identify, on Ceres) of a simulated noise-free campaign recovers its truth.
#include <kdl/chainfksolverpos_recursive.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "kincal/identify/identify.hpp"
#include "kincal/identify/simulate.hpp"
#include "kincal/ik/ik.hpp"
#include "kincal/kinematics/kinematics.hpp"
#include "kincal/model/model.hpp"
#include "kincal/model/robots.hpp"

// the standard comes from kincal::core (cxx_std_17); CMakeLists.txt sets none
static_assert(__cplusplus >= 201703L, "kincal's targets should compile their consumer as C++17");

int main() {
  const kincal::Model model(kincal::kr500_spec());
  kincal::VecQ q(6);
  q << 10, -80, 100, 20, 30, 40;
  q *= kincal::kDeg;
  const Eigen::Isometry3d t = kincal::fk(model, q);
  KDL::ChainFkSolverPos_recursive kdl(model.kdl_chain());
  KDL::JntArray qk(6);
  for (int i = 0; i < 6; ++i) qk(i) = q[i];
  KDL::Frame f;
  kdl.JntToCart(qk, f);
  double d = 0;
  for (int i = 0; i < 3; ++i) d = std::max(d, std::abs(f.p(i) - t.translation()[i]));
  const auto sols = kincal::IkSolver(model).solve(t);
  double best = 1e9;
  for (int s = 0; s < sols.count; ++s) best = std::min(best, (sols.sol[s].q_deg - q / kincal::kDeg).cwiseAbs().maxCoeff());
  std::printf("kincal consumer: fk vs KDL %.3g mm, IK round trip %.3g deg\n", d, best);
  // truth: 1 mm / 0.05 deg manufacturing errors (seed 4), 60 poses x 3 targets, no noise
  const kincal::Model truth(kincal::perturbed_spec(kincal::kr500_spec(), 4, 1.0, 0.05));
  kincal::SimulationOptions so;
  so.poses = 60;
  so.noise_mm = 0;
  so.targets = {kincal::Vec3(0, 0, 0), kincal::Vec3(120, 0, 30), kincal::Vec3(0, 150, -20)};
  const kincal::IdentifyResult r = kincal::identify(model, kincal::simulate(truth, so), kincal::IdentifyOptions());
  std::printf("kincal consumer: identification %.3g -> %.3g mm RMS\n", r.nominal_rms_mm, r.rms_mm);
  // two implementations in double precision on a 3 m arm agree to rounding (1e-6 mm, 1e-6 deg); the
  // identification of noise-free data fits to well under a micrometre
  const bool ok = d < 1e-6 && best < 1e-6 && r.nominal_rms_mm > 0.1 && r.rms_mm < 1e-3;
  if (ok) std::printf("kincal consumer: ok\n");
  return ok ? 0 : 1;
}
