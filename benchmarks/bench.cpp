#include "bench.hpp"

#include "kincal/compensation/pose.hpp"
#include "kincal/fivebar/fivebar.hpp"
#include "kincal/ik/ik.hpp"
#include "kincal/compensation/program.hpp"
#include "kincal/kinematics/kinematics.hpp"
#include "kincal/model/model.hpp"
#include "kincal/model/robots.hpp"

#include <kdl/chainfksolverpos_recursive.hpp>
#include <kdl/chainiksolverpos_nr.hpp>
#include <kdl/chainiksolvervel_pinv.hpp>
#include <kdl/chainjnttojacsolver.hpp>

#include <opw_kinematics/opw_kinematics.h>

#include <algorithm>
#include <chrono>
#include <random>
#include <thread>

#include <time.h>

namespace kincal {

namespace {

using Clock = std::chrono::steady_clock;

volatile double g_sink = 0;

// The calling thread's CPU time in ns: time spent waiting for a core (a loaded machine) is not counted.
double thread_cpu_ns() {
  timespec t;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return 1e9 * static_cast<double>(t.tv_sec) + static_cast<double>(t.tv_nsec);
}

// Median over batches of the time per call (the thread's CPU time), in ns.
template <class F>
double time_ns(int n, F&& f, int batches = 15) {
  std::vector<double> per;
  for (int b = 0; b < batches; ++b) {
    const double t0 = thread_cpu_ns();
    for (int i = 0; i < n; ++i) f(i);
    per.push_back((thread_cpu_ns() - t0) / n);
  }
  std::sort(per.begin(), per.end());
  return per[per.size() / 2];
}

KDL::JntArray to_kdl(const VecQ& q) {
  KDL::JntArray a(static_cast<unsigned>(q.size()));
  for (int i = 0; i < q.size(); ++i) a(i) = q[i];
  return a;
}

KDL::Frame to_kdl(const Eigen::Isometry3d& t) {
  const Mat3& r = t.linear();
  const Vec3& p = t.translation();
  return KDL::Frame(KDL::Rotation(r(0, 0), r(0, 1), r(0, 2), r(1, 0), r(1, 1), r(1, 2), r(2, 0), r(2, 1), r(2, 2)),
                    KDL::Vector(p[0], p[1], p[2]));
}

using Figures = std::vector<std::pair<std::string, double>>;

struct BenchPoses {  // random configurations inside the limits, more than 1 degree from the wrist singularity
  std::vector<VecQ> qs;                     // rad
  std::vector<Pose6> poses;                 // their poses on the nominal robot
  std::vector<Vec6> qref;                   // deg
  std::vector<Eigen::Isometry3d> targets;   // the poses as transforms
};

BenchPoses random_poses(const Model& nom, int n, unsigned seed) {
  BenchPoses b;
  auto& qs = b.qs;
  auto& poses = b.poses;
  auto& qref = b.qref;
  std::mt19937_64 rng(seed);
  while (static_cast<int>(qs.size()) < n) {
    VecQ q(6);
    for (int j = 0; j < 6; ++j) {
      const auto& js = nom.spec().joints[j];
      q[j] = std::uniform_real_distribution<double>(js.lower_deg, js.upper_deg)(rng);
    }
    if (std::abs(q[4]) < 1.0 || std::abs(q[2] - 3.07) < 1.0) continue;  // wrist, elbow singularities
    qref.push_back(q);
    const VecQ qr = q * kDeg;
    qs.push_back(qr);
    poses.push_back(iso_to_pose(fk(nom, qr)));
  }
  for (const auto& p : poses) b.targets.push_back(pose_to_iso(p));
  return b;
}

// FK, the Jacobian and the IK against KDL's FK and Jacobian
void bench_kinematics(Figures& out, const Model& nom, const BenchPoses& b) {
  const int n = static_cast<int>(b.qs.size());
  const auto& qs = b.qs;
  const auto& targets = b.targets;
  const auto& qref = b.qref;
  // FK
  out.emplace_back("fk_ns", time_ns(n, [&](int i) { g_sink = g_sink + fk(nom, qs[i]).translation()[0]; }));
  KDL::ChainFkSolverPos_recursive kfk(nom.kdl_chain());
  std::vector<KDL::JntArray> kq;
  for (const auto& q : qs) kq.push_back(to_kdl(q));
  KDL::Frame kf;
  out.emplace_back("kdl_fk_ns", time_ns(n, [&](int i) {
                     kfk.JntToCart(kq[i], kf);
                     g_sink = g_sink + kf.p.x();
                   }));
  // Jacobian
  Eigen::Isometry3d t;
  Jac jac;
  out.emplace_back("jacobian_ns", time_ns(n, [&](int i) {
                     fk_jacobian(nom, qs[i], t, jac);
                     g_sink = g_sink + jac(0, 0);
                   }));
  KDL::ChainJntToJacSolver kjac(nom.kdl_chain());
  KDL::Jacobian kj(6);
  out.emplace_back("kdl_jacobian_ns", time_ns(n, [&](int i) {
                     kjac.JntToJac(kq[i], kj);
                     g_sink = g_sink + kj(0, 0);
                   }));
  // IK, all solutions
  const IkSolver ik(nom);  // built once, as a Robot holds it
  out.emplace_back("ik_all_ns", time_ns(n, [&](int i) {
                     const IkSolutions s = ik.solve(targets[i], IkOptions(qref[i]));
                     g_sink = g_sink + s.count;
                   }));
}

// opw_kinematics (the peer a user of an ortho-parallel robot would pick) on the same targets: the
// kr500's parameters in its convention (zero with the arm upright; axes 1, 4, 6 reversed), the
// flange it solves for placed by the fixed transform from our tool frame, its 8 solutions mapped
// back to our angles. A pose counts as matched when one of them is our reference configuration.
void bench_opw(Figures& out, const Model& nom, const BenchPoses& b) {
  const int n = static_cast<int>(b.qs.size());
  const auto& qs = b.qs;
  const auto& targets = b.targets;
  const auto& qref = b.qref;
  opw_kinematics::Parameters<double> op;
  op.a1 = 500;
  op.a2 = -55;
  op.b = 0;
  op.c1 = 1045;
  op.c2 = 1300;
  op.c3 = 1025;
  op.c4 = 290;
  op.offsets = {0, -kPi / 2, 0, 0, 0, 0};
  op.sign_corrections = {-1, 1, 1, -1, 1, -1};
  // its flange at our zero: theta = q * sign - offset
  std::array<double, 6> z{};
  const Eigen::Isometry3d f0 = opw_kinematics::forward(op, z);
  const Eigen::Isometry3d x = fk(nom, VecQ::Zero(6)).inverse() * f0;
  std::vector<Eigen::Isometry3d> flange;
  for (const auto& t : targets) flange.push_back(t * x);
  int matched = 0;
  for (int i = 0; i < n; ++i) {
    const auto sols = opw_kinematics::inverse(op, flange[i]);
    for (const auto& s : sols) {
      double worst = 0;
      for (int j = 0; j < 6; ++j) {
        const double d = std::remainder(s[j] - qs[i][j], 2 * kPi);
        worst = std::max(worst, std::isfinite(d) ? std::abs(d) : 1e9);
      }
      if (worst < 1e-9) {
        ++matched;
        break;
      }
    }
  }
  out.emplace_back("opw_ik_ns", time_ns(n, [&](int i) {
                     const auto s = opw_kinematics::inverse(op, flange[i]);
                     g_sink = g_sink + s[0][0];
                   }));
  out.emplace_back("opw_matched_fraction", static_cast<double>(matched) / n);
  // the same with what our solve also delivers: degrees, each angle the whole turn nearest the
  // reference within the limits, flagged (a plain loop, as a user of opw_kinematics would write it)
  std::array<double, 6> lo, hi;
  for (int j = 0; j < 6; ++j) {
    lo[j] = nom.spec().joints[j].lower_deg;
    hi[j] = nom.spec().joints[j].upper_deg;
  }
  out.emplace_back("opw_ik_limits_ns", time_ns(n, [&](int i) {
                     const auto s = opw_kinematics::inverse(op, flange[i]);
                     int inside = 0;
                     double first = 0;
                     for (const auto& sol : s) {
                       bool ok = std::isfinite(sol[0]);
                       for (int j = 0; j < 6 && ok; ++j) {
                         const double q = std::remainder(sol[j] * (180 / kPi), 360.0);
                         double best = q;
                         bool found = false;
                         for (int k = -2; k <= 2; ++k) {
                           const double c = q + 360.0 * k;
                           if (c < lo[j] || c > hi[j]) continue;
                           if (!found || std::abs(c - qref[i][j]) < std::abs(best - qref[i][j])) best = c;
                           found = true;
                         }
                         ok = found;
                         if (j == 0) first = best;
                       }
                       inside += ok;
                     }
                     g_sink = g_sink + inside + first;
                   }));
}

struct NewtonFigures {  // what the compensation benchmarks share
  std::vector<Vec6> start;  // the nominal IK solution nearest each reference (deg)
  int not_converged = 0;
  long iterations = 0;
};

NewtonFigures bench_compensation(Figures& out, const Model& nom, const Model& cal, const Model& calc,
                                 const BenchPoses& b) {
  const int n = static_cast<int>(b.qs.size());
  const auto& poses = b.poses;
  const auto& qref = b.qref;
  const auto& targets = b.targets;
  const IkSolver ik(nom);
  NewtonFigures nf;
  auto& start = nf.start;
  auto& not_converged = nf.not_converged;
  auto& iterations = nf.iterations;
  // Compensation (the and the paper's): Newton on the calibrated model from the nominal IK
  // solution nearest the reference, the start KDL's NR gets below
  start.resize(n);
  for (int i = 0; i < n; ++i) {
    const IkSolutions s = ik.solve(targets[i], IkOptions(qref[i]));
    const int k = s.nearest(qref[i].data());
    start[i] = k >= 0 ? s.sol[k].q_deg : qref[i];
  }
  CompensationOptions an, fd;
  fd.finite_difference = true;
  out.emplace_back("compensate_ns", time_ns(n, [&](int i) {
                     const auto r = compensate(cal, poses[i], start[i], an);
                     not_converged += r.status != CompStatus::Converged;
                     iterations += r.iterations;
                     g_sink = g_sink + r.q_deg[0];
                   }));
  out.emplace_back("compensate_compliance_ns", time_ns(n, [&](int i) {
                     const auto r = compensate(calc, poses[i], start[i], an);
                     g_sink = g_sink + r.q_deg[0];
                   }));
  // the same compliant robot with transmission error (harmonics 1, 2) on joints 1-3 and backlash on
  // joints 1-3 (the directions of each pose alternate), and the paper's ABC residual for reference
  ModelSpec effects_spec = calc.spec();
  for (int j = 0; j < 3; ++j) {
    effects_spec.effects.push_back({Effect{"transmission_error", j, {1, 2}}, {2e-4, -1e-4, 5e-5, 8e-5}});
    effects_spec.effects.push_back({Effect{"backlash", j, {}}, {-2e-4}});
  }
  const Model cale(effects_spec);
  std::vector<EffectContext> ctx(n);
  for (int i = 0; i < n; ++i) ctx[i].dir = VecQ::Constant(6, i % 2 ? 1.0 : -1.0);
  out.emplace_back("compensate_effects_ns", time_ns(n, [&](int i) {
                     const auto r = compensate(cale, poses[i], start[i], an, ctx[i]);
                     g_sink = g_sink + r.q_deg[0];
                   }));
  CompensationOptions abc;
  abc.residual = Residual::Abc;
  out.emplace_back("compensate_abc_ns", time_ns(n, [&](int i) {
                     const auto r = compensate(cal, poses[i], start[i], abc);
                     g_sink = g_sink + r.q_deg[0];
                   }));
  out.emplace_back("compensate_fd_ns", time_ns(n, [&](int i) {
                     const auto r = compensate(cal, poses[i], start[i], fd);
                     g_sink = g_sink + r.q_deg[0];
                   }, 5));
  return nf;
}

// the program path, KDL's Newton-Raphson and the batch throughput on all cores
void bench_program(Figures& out, const Model& cal, const NewtonFigures& nf, const BenchPoses& b, int threads) {
  const int n = static_cast<int>(b.qs.size());
  const auto& poses = b.poses;
  const auto& qref = b.qref;
  const auto& targets = b.targets;
  const auto& start = nf.start;
  const CompensationOptions an;
  // The whole per-pose path of `kincal compensate` (compensation/program.hpp solve_pose): nominal IK of the branch
  // nearest the reference, the corrected start (a second IK), Newton, the joint-limit check
  auto nomp = std::make_shared<Model>(kr500_spec());
  const Robot rob{nomp, std::make_shared<Model>(cal.spec())};
  struct R {
    Vec6 q_deg;
    bool ok;
  };
  auto program_pose = [&](const Robot& rb, int i) {
    ProgramOptions po;
    const PoseSolution s = solve_pose(rb, po, poses[i], qref[i]);
    return R{s.q_deg, s.ok()};
  };
  int program_failed = 0;
  out.emplace_back("program_pose_ns", time_ns(n, [&](int i) {
                     const auto r = program_pose(rob, i);
                     program_failed += !r.ok;
                     g_sink = g_sink + r.q_deg[0];
                   }));
  // KDL's Newton-Raphson on the same calibrated chain, from the same start, |twist| < 3.2e-8 per
  // component (our stop |F|^2 < 1e-15)
  KDL::ChainFkSolverPos_recursive cfk(cal.kdl_chain());
  KDL::ChainIkSolverVel_pinv cvel(cal.kdl_chain());
  KDL::ChainIkSolverPos_NR cnr(cal.kdl_chain(), cfk, cvel, 100, std::sqrt(1e-15));
  std::vector<KDL::JntArray> kstart;
  for (const auto& s : start) kstart.push_back(to_kdl(VecQ(s * kDeg)));
  KDL::JntArray kout(6);
  const int nk = std::min(n, 500);
  int kdl_failed = 0;
  out.emplace_back("kdl_nr_ns", time_ns(nk, [&](int i) {
                     const Eigen::Isometry3d& tg = targets[i];
                     kdl_failed += cnr.CartToJnt(kstart[i], to_kdl(tg), kout) < 0;
                     g_sink = g_sink + kout(0);
                   }, 3));
  // all cores: the compensation of the poses split over the threads, and the whole program path
  const int nt = threads > 0 ? threads : std::max(1u, std::thread::hardware_concurrency());
  auto throughput = [&](auto&& one) {
    const int reps = 20;
    const auto t0 = Clock::now();
    std::vector<std::thread> pool;
    for (int w = 0; w < nt; ++w) {
      pool.emplace_back([&, w] {
        double sink = 0;
        for (int r = 0; r < reps; ++r)
          for (int i = w; i < n; i += nt) sink += one(i);
        g_sink = g_sink + sink;
      });
    }
    for (auto& th : pool) th.join();
    return n * reps / std::chrono::duration<double>(Clock::now() - t0).count();
  };
  out.emplace_back("batch_poses_per_s", throughput([&](int i) { return compensate(cal, poses[i], start[i], an).q_deg[0]; }));
  out.emplace_back("batch_program_poses_per_s", throughput([&](int i) { return program_pose(rob, i).q_deg[0]; }));
  out.emplace_back("batch_threads", nt);
  out.emplace_back("compensate_not_converged", nf.not_converged / 15.0);
  out.emplace_back("compensate_mean_iterations", nf.iterations / (15.0 * n));
  out.emplace_back("program_failures", program_failed / 15.0);
  out.emplace_back("kdl_nr_failures", kdl_failed / 3.0);
}

void add_ratios(Figures& out) {
  auto get = [&](const char* k) {
    for (auto& p : out)
      if (p.first == k) return p.second;
    return 0.0;
  };
  out.emplace_back("fk_speedup_vs_kdl", get("kdl_fk_ns") / get("fk_ns"));
  out.emplace_back("jacobian_speedup_vs_kdl", get("kdl_jacobian_ns") / get("jacobian_ns"));
  out.emplace_back("ik_ratio_to_opw", get("ik_all_ns") / get("opw_ik_ns"));
  out.emplace_back("ik_ratio_to_opw_limits", get("ik_all_ns") / get("opw_ik_limits_ns"));
  out.emplace_back("compensate_speedup_vs_kdl_nr", get("kdl_nr_ns") / get("compensate_ns"));
}

// five-bar corrector (hidden-robot IK, bilinear lookup, Jacobian correction): every sample timed
// alone (clock reads included), on a 5 mm error matrix over the paper's 100 x 150 mm workspace
void bench_fivebar(Figures& out, unsigned seed) {
  std::vector<FiveBarPoint> grid;
  std::mt19937_64 g(seed);
  std::normal_distribution<double> nd(0, 0.05);
  for (int iy = 0; iy <= 30; ++iy)
    for (int ix = 0; ix <= 20; ++ix) {
      FiveBarPoint p;
      p.desired = Vec2(162.132 + 5 * ix, -75 + 5 * iy);
      p.measured = p.desired + Vec2(nd(g), nd(g));
      grid.push_back(p);
    }
  const ErrorMatrix em = ErrorMatrix::from_points(grid, "bench");
  FiveBarCorrector corr(FiveBar{149.9, 150.05, 149.95, 150.1, +1, +1, -1}, &em);
  const int m = 200000;
  std::vector<double> lat(m);
  std::uniform_real_distribution<double> ux(162.132, 262.132), uy(-75, 75);
  std::vector<Vec2> pts(m);
  for (auto& p : pts) p = Vec2(ux(g), uy(g));
  double t1, t2;
  for (int i = 0; i < m; ++i) {
    const auto a = Clock::now();
    corr.command(pts[i], t1, t2);
    const auto b = Clock::now();
    g_sink = g_sink + t1;
    lat[i] = std::chrono::duration<double, std::nano>(b - a).count();
  }
  std::sort(lat.begin(), lat.end());
  out.emplace_back("fivebar_command_median_ns", lat[m / 2]);
  out.emplace_back("fivebar_command_p99_ns", lat[static_cast<size_t>(0.99 * m)]);
  out.emplace_back("fivebar_command_max_ns", lat.back());
}

}  // namespace

std::vector<std::pair<std::string, double>> run_benchmarks(int n, unsigned seed, int threads) {
  Figures out;
  const Model nom(kr500_spec());
  const Model cal(perturbed_spec(kr500_spec(), seed, 1.0, 0.05, 0.0));
  const Model calc(perturbed_spec(kr500_spec(), seed, 1.0, 0.05, 0.003));
  const BenchPoses b = random_poses(nom, n, seed);
  out.emplace_back("poses", n);
  bench_kinematics(out, nom, b);
  bench_opw(out, nom, b);
  const NewtonFigures nf = bench_compensation(out, nom, cal, calc, b);
  bench_program(out, cal, nf, b, threads);
  add_ratios(out);
  bench_fivebar(out, seed);
  return out;
}

}  // namespace kincal
