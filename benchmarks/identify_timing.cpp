// kincal-identify-timing: identify() on simulated tracker campaigns of three sizes (2 targets, 300,
// 1000 and 4000 poses of the kr500 with 0.7/-0.4/0.5 mm joint offsets and compliance 0.003 deg/kNm),
// the median wall time of 9 fits each, covariance off. Its source compiles unchanged against an
// earlier commit's headers and libraries, so that two builds can be run alternately (BENCHMARKS.md).
#include "kincal/identify/identify.hpp"
#include "kincal/identify/simulate.hpp"
#include "kincal/model/robots.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <vector>

using namespace kincal;

int main() {
  const Model nominal(kr500_spec());
  ModelSpec ts = kr500_spec();
  for (size_t k = 0; k < ts.joints.size(); ++k) {
    ts.joints[k].point += Vec3(0.7, -0.4, 0.5);
    if (k > 0) ts.joints[k].compliance_deg_per_knm = 0.003;  // joint 1 carries no gravity torque
  }
  const Model truth(ts);
  for (int poses : {300, 1000, 4000}) {
    SimulationOptions so;
    so.poses = poses;
    so.targets = {Vec3::Zero(), Vec3(100, 0, 30)};
    const MeasurementSet d = simulate(truth, so);
    IdentifyOptions opt;
    opt.covariance = false;
    std::vector<double> t;
    for (int k = 0; k < 9; ++k) {
      const auto a = std::chrono::steady_clock::now();
      const IdentifyResult r = identify(nominal, d, opt);
      t.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - a).count());
      if (k == 0) std::fprintf(stderr, "%d poses: rms %.4f mm, %d iterations\n", poses, r.rms_mm, r.iterations);
    }
    std::sort(t.begin(), t.end());
    std::printf("identify_%d_rows_ms %.2f\n", 2 * poses, t[4]);
  }
}
