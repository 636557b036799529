// kincal: probe campaigns on a truth (simulate.hpp): spheres, the faces of a block, ballbar pivots.
// Each row's commanded angles are found by inverse kinematics on the truth itself (its effects
// acting), so that its ball centre sits on the row's constraint exactly, then moved by the noise.
#include "kincal/identify/simulate.hpp"

#include "kincal/compensation/pose.hpp"
#include "kincal/identify/so3.hpp"
#include "kincal/kinematics/kinematics.hpp"

#include <cmath>
#include <random>

namespace kincal {

namespace {

/// The places a sphere or a pivot is given before the simulation gives up on a station.
constexpr int kStationAttempts = 20;

/// A random rotation taking the direction `axis` (unit) within `cone` rad of itself, turned about
/// the tool's own axis by up to +-60 deg.
Mat3 tilt(std::mt19937_64& rng, const Vec3& axis, double cone) {
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  const double theta = cone * std::sqrt(u01(rng)), phi = 2 * M_PI * u01(rng), psi = (u01(rng) - 0.5) * 2 * M_PI / 3;
  const Vec3 a = axis.unitOrthogonal(), b = axis.cross(a);
  return so3::exp((std::cos(phi) * a + std::sin(phi) * b) * theta) * so3::exp(axis * psi);
}

struct Placer {
  const Model& truth;
  const ProbeSimulationOptions& opt;
  std::mt19937_64& rng;
  /// Joint angles drawn in opt.limit_margin of every joint's range.
  VecQ random_q() const {
    std::uniform_real_distribution<double> ud(-0.5, 0.5);
    VecQ q(truth.dof());
    for (int j = 0; j < truth.dof(); ++j) {
      const JointSpec& js = truth.spec().joints[j];
      q[j] = 0.5 * (js.lower_deg + js.upper_deg) + ud(rng) * (js.upper_deg - js.lower_deg) * opt.limit_margin;
    }
    return q;
  }
  /// Directions of the last motion drawn for every joint.
  VecQ random_dir() const {
    std::uniform_real_distribution<double> u01(0.0, 1.0);
    VecQ d(truth.dof());
    for (int j = 0; j < truth.dof(); ++j) d[j] = u01(rng) < 0.5 ? -1.0 : 1.0;
    return d;
  }
  /// Commanded angles that put the truth's ball centre at c with the tool turned to r (base frame),
  /// near ref; false when out of reach.
  bool reach(const Vec3& c, const Mat3& r, const VecQ& ref, const VecQ& dir, Measurement& row, int starts = 8) const {
    Eigen::Isometry3d tool = Eigen::Isometry3d::Identity();
    tool.linear() = r;
    tool.translation() = c - r * opt.probe;
    EffectContext ctx;
    ctx.dir = dir;
    CompensationOptions co;
    co.max_iterations = 50;
    const auto q = numeric_ik(truth, iso_to_pose(tool), ref, co, starts, ctx);
    if (!q) return false;
    row.q_deg = *q;
    row.dir = dir;
    return true;
  }
};

/// The block whose faces a plane campaign probes: in front of the robot, its top face's centre at
/// `top`, the probe pointing down in `frame` (a pose of the truth with joint angles q0); faces in the
/// order top, the one towards the robot, the two sideways ones, and the surface plate it stands on
/// (parallel to the top, the block's edge below it: probed round the block).
struct Block {
  static constexpr int kPlate = 4;
  explicit Block(double edge) : edge_mm(edge) { frame.linear() << 1, 0, 0, 0, -1, 0, 0, 0, -1; }
  double edge_mm;
  VecQ q0;
  Eigen::Isometry3d frame = Eigen::Isometry3d::Identity();
  Vec3 top = Vec3::Zero();
  static Vec3 normal(int s) {
    const Vec3 n[] = {Vec3::UnitZ(), -Vec3::UnitX(), Vec3::UnitY(), -Vec3::UnitY(), Vec3::UnitZ()};
    return n[s];
  }
  /// A face's centre; the plate's: the block's foot on it, in front of the block (towards the robot)
  Vec3 centre(int s) const {
    if (s == kPlate) return top - Vec3::UnitZ() * edge_mm - Vec3::UnitX() * (0.85 * edge_mm);
    return top - Vec3::UnitZ() * (0.5 * edge_mm) + normal(s) * (0.5 * edge_mm);
  }
  /// A point of face s to touch (u, v uniform in -0.5..0.5): within 70% of a face; on the plate, in
  /// the ring 0.75-1.0 edges from the block's axis (clear of its foot), on the robot's side.
  Vec3 point(int s, double u, double v) const {
    if (s == kPlate) {
      const double rho = (0.875 + 0.25 * u) * edge_mm, phi = M_PI + v * M_PI;  // the half ring towards the robot
      return top - Vec3::UnitZ() * edge_mm + rho * Vec3(std::cos(phi), std::sin(phi), 0.0);
    }
    const Vec3 n = normal(s), a = n.unitOrthogonal(), b = n.cross(a);
    return centre(s) + 0.7 * edge_mm * (u * a + v * b);
  }
  /// The probe turned from `frame` to point into face s.
  Mat3 turn(int s) const {
    return Eigen::Quaterniond::FromTwoVectors(frame.linear().col(2), -normal(s)).toRotationMatrix() * frame.linear();
  }
};

/// Where every probed face's centre is in reach with the probe pointing into it: the first of a few
/// places at fractions of the reach and heights about the shoulder. InputError when none is.
Block place_block(const Placer& place) {
  const Model& truth = place.truth;
  const ProbeSimulationOptions& opt = place.opt;
  const int n = truth.dof();
  Block b(opt.block_mm);
  VecQ mid(n);
  for (int j = 0; j < n; ++j) mid[j] = 0.5 * (truth.spec().joints[j].lower_deg + truth.spec().joints[j].upper_deg);
  const double reach = (fk_compliant(truth, VecQ::Zero(n)) * opt.probe).head<2>().norm();
  const double shoulder = truth.point(1).z();
  for (double fr : {0.55, 0.45, 0.65, 0.35})
    for (double fz : {-0.3, 0.0, -0.5, 0.2})
      for (double az : {0.0, 30.0, -30.0}) {
        b.top = Vec3(fr * reach * std::cos(az * kDeg), fr * reach * std::sin(az * kDeg), shoulder + fz * reach);
        Measurement row;
        if (!place.reach(b.centre(0) + Block::normal(0) * opt.radius_mm, b.turn(0), mid, place.random_dir(), row, 48))
          continue;
        b.q0 = row.q_deg;
        bool all = true;
        for (int s = 1; s < opt.stations && all; ++s)
          all = place.reach(b.centre(s) + Block::normal(s) * opt.radius_mm, b.turn(s), b.q0, place.random_dir(), row, 48);
        if (all) return b;
      }
  throw InputError("simulate: no place for a block of " + std::to_string(opt.block_mm) + " mm with " +
                   std::to_string(opt.stations) + " faces in the robot's reach");
}

/// The artifact of a campaign: spheres and pivots, the distance of every station from the first
/// (points: their places, base frame); planes, the 90 deg angles between the top face and the
/// sideways faces and the one towards the robot, and the block's edge between the sideways faces and
/// between the top and the plate it stands on.
std::vector<ArtifactTerm> known_geometry(const ProbeSimulationOptions& opt, const std::vector<Vec3>& points) {
  std::vector<ArtifactTerm> out;
  for (int s = 1; s < opt.stations; ++s) {
    if (opt.kind == MeasureKind::plane && s == Block::kPlate) continue;  // parallel to the top: its distance below
    ArtifactTerm a;
    a.a = 0;
    a.b = s;
    if (opt.kind == MeasureKind::plane) a.angle_deg = 90;
    else a.distance_mm = (points[static_cast<size_t>(s)] - points[0]).norm();
    out.push_back(a);
  }
  if (opt.kind == MeasureKind::plane)
    for (const auto& [fa, fb] : {std::pair<int, int>{2, 3}, {0, Block::kPlate}}) {  // y+ with y-, top with the plate
      if (fb >= opt.stations) continue;
      ArtifactTerm a;
      a.a = fa;
      a.b = fb;
      a.distance_mm = opt.block_mm;
      out.push_back(a);
    }
  return out;
}

}  // namespace

MeasurementSet simulate_probe(const Model& truth, const ProbeSimulationOptions& opt) {
  if (!is_probe(opt.kind)) throw InputError("simulate: --kind must be sphere, plane or distance");
  if (opt.stations < 1 || opt.touches < 1) throw InputError("simulate: at least one station and one touch");
  if (opt.kind == MeasureKind::plane && opt.stations > 5) throw InputError("simulate: a block has 5 faces to probe");
  if (truth.dof() != 6) throw InputError("simulate: probe campaigns need a 6-joint robot");
  std::mt19937_64 rng(opt.seed);
  std::uniform_real_distribution<double> ud(-0.5, 0.5);
  std::normal_distribution<double> nd(0.0, 1.0);
  const Placer place{truth, opt, rng};
  const double cone = opt.cone_deg * kDeg;
  MeasurementSet m;
  m.source = "simulated";
  auto random_dir = [&] { return place.random_dir(); };
  // a seed pose with the probe's ball well in reach: its tool frame (base frame)
  auto seed_pose = [&](VecQ& q) {
    q = place.random_q();
    return fk_model(truth, q * kDeg, EffectContext{random_dir(), std::nan("")});
  };
  std::vector<Vec3> points;  // every sphere's centre or pivot (base frame)
  const char* faces[] = {"top", "x-", "y+", "y-", "plate"};  // Block's order
  const Block block = opt.kind == MeasureKind::plane ? place_block(place) : Block(opt.block_mm);
  for (int s = 0; s < opt.stations; ++s) {
    const std::string name = opt.kind == MeasureKind::plane ? faces[s] : "S" + std::to_string(s + 1);
    m.station_names.push_back(name);
    m.station_kinds.push_back(opt.kind);
    // a sphere's centre or a pivot placed where too few of its touches are in reach is placed again
    // (a seed pose at the edge of the workspace); a block's face stays where the block stands
    for (int attempt = 1;; ++attempt) {
      Vec3 axis;   // the probe's mean direction (the tool's z in the seed pose, or towards the face)
      Vec3 centre, normal = Vec3::UnitZ();
      VecQ ref;
      Eigen::Isometry3d seed;
      if (opt.kind == MeasureKind::plane) {
        ref = block.q0;
        seed = block.frame;
        normal = Block::normal(s);
        centre = block.centre(s);
        axis = -normal;  // the probe points into the face
      } else {
        seed = seed_pose(ref);
        centre = seed * opt.probe;
        axis = seed.linear().col(2);
        // the pivot on the probe's axis beyond the ball (the bar cannot pass through the tool)
        if (opt.kind == MeasureKind::distance) centre += axis * opt.length_mm;
        points.push_back(centre);
      }
      const size_t first_row = m.rows.size();
      int made = 0, tries = 0;
      while (made < opt.touches) {
        if (++tries > 40 * opt.touches) break;
        Measurement row;
        row.pose = static_cast<int>(m.rows.size());
        row.kind = opt.kind;
        row.station = s;
        Vec3 c;
        Mat3 r;
        if (opt.kind == MeasureKind::plane) {
          // a point of the face (70% of it; the plate's ring), the ball centre radius + noise off it,
          // the probe into it
          const double u = ud(rng), v = ud(rng);
          const Vec3 on = block.point(s, u, v);
          c = on + normal * (opt.radius_mm + opt.noise_mm * nd(rng));
          r = tilt(rng, axis, cone) * block.turn(s);
          row.radius_mm = opt.radius_mm;
        } else if (opt.kind == MeasureKind::sphere) {
          c = centre + Vec3(nd(rng), nd(rng), nd(rng)) * opt.noise_mm;
          r = tilt(rng, axis, cone) * seed.linear();
        } else {
          // the bar's direction (pivot to ball) within the cone about the probe's axis reversed, the
          // tool turned within half of it
          const Vec3 d = tilt(rng, -axis, cone) * -axis;
          c = centre + d * opt.length_mm;
          r = tilt(rng, axis, 0.5 * cone) * seed.linear();
          row.length_mm = opt.length_mm + opt.noise_mm * nd(rng);
        }
        if (!place.reach(c, r, ref, random_dir(), row)) continue;
        row.line = 0;
        m.rows.push_back(row);
        ++made;
      }
      if (made == opt.touches) break;
      m.rows.resize(first_row);
      if (opt.kind != MeasureKind::plane) points.pop_back();
      if (opt.kind == MeasureKind::plane || attempt == kStationAttempts)
        throw InputError("simulate: station " + name + " is out of the robot's reach (" + std::to_string(made) + " of " +
                         std::to_string(opt.touches) + " touches" +
                         (opt.kind == MeasureKind::plane ? "" : " at the last of " + std::to_string(attempt) + " places") + ")");
    }
  }
  // (the stations are in the base frame, the artifact's lengths and angles in any)
  if (opt.artifact) m.artifact = known_geometry(opt, points);
  return m;
}

}  // namespace kincal
