// kincal: the immutable serial-robot model.
//
// A serial revolute chain in product-of-exponentials (screw theory) form: every joint is a line in
// the base frame at the zero configuration (a point and a direction), the tool is a frame at the zero
// configuration. That is 4 independent parameters per joint (a line) plus 6 for the tool: 30 for a
// 6R robot, the minimal complete set. Non-geometric: one joint compliance per gravity-loaded joint
// (deflection = compliance * gravity torque), from the link masses and the payload.
//
// The Model never changes after construction. It owns an equivalent KDL::Chain (the reference for
// every test) and a compiled evaluator (local frames along each joint axis) used by the hot paths.
// What is computed from a model lives beside it: the inverse kinematics in ik/ik.hpp (IkSolver),
// the built-in robots in model/robots.hpp, the model JSON in io/model_json.hpp.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "kincal/core/types.hpp"
#include "kincal/effects/effects.hpp"
#include "kincal/model/campaign.hpp"

namespace KDL {
class Chain;
}

namespace kincal {

struct JointSpec {
  std::string name;
  Vec3 point = Vec3::Zero();     ///< a point of the axis, base frame, zero configuration (mm)
  Vec3 axis = Vec3::UnitZ();     ///< axis direction (normalised by the Model)
  double lower_deg = -180, upper_deg = 180;
  double max_velocity_deg_s = 0, max_acceleration_deg_s2 = 0, max_jerk_deg_s3 = 0;  ///< 0: unknown
  double mass_kg = 0;            ///< mass of the link this joint moves (the link after the joint)
  Vec3 com = Vec3::Zero();       ///< its centre of mass, base frame, zero configuration (mm)
  double compliance_deg_per_knm = 0;  ///< joint deflection per gravity torque (deg per kN m)
};

/// Everything that defines one robot geometry; plain data, checked when a Model is built from it.
struct ModelSpec {
  std::string name = "robot";
  std::vector<JointSpec> joints;
  Pose6 tool;                      ///< tool (TCP) frame in the base frame at zero configuration
  double payload_kg = 0;
  Vec3 payload_com = Vec3::Zero(); ///< payload centre of mass in the tool frame (mm)
  Vec3 gravity = Vec3(0, 0, -9.81);///< gravity in the base frame (m/s^2)
  std::vector<double> home_deg;    ///< preferred configuration for the first pose of a program
  /// non-geometric effects besides the joints' compliance (effects.hpp): transmission error,
  /// backlash, thermal expansion, with their values in core units (a joint_compliance entry sets the
  /// joint's compliance_deg_per_knm); the instrument's drift is the campaign's (campaign.hpp)
  std::vector<EffectValue> effects;
  double t_ref_c = 20.0;           ///< reference temperature of thermal_expansion (deg C)
  /// How the controller numbers the joints (kincal/model/joint_convention.hpp): "" its own angles are
  /// the model's; "fanuc": the controller's J3 is the forearm's angle to the horizontal
  std::string joint_convention;
  /// Where the tool frame (TCP) comes from, as the identification knows it: "measured" (6-D rows
  /// measured the tool frame itself), "tool-targets" (placed from known target offsets), "nominal"
  /// (reflectors only: the tool frame stayed at its start value, its error in every pose); "" when
  /// not recorded (a nominal model, a model file written before the key). The model file's top-level
  /// "tcp", the calibrated model's.
  std::string tcp;
};

class Model {
 public:
  explicit Model(ModelSpec spec);
  ~Model();
  Model(const Model&) = delete;
  Model& operator=(const Model&) = delete;

  const ModelSpec& spec() const { return spec_; }
  int dof() const { return n_; }
  const KDL::Chain& kdl_chain() const { return *chain_; }
  /// true for a joint that carries a compliance parameter (its axis is not fixed along gravity)
  bool gravity_loaded(int j) const { return loaded_[j]; }
  int compliance_count() const;
  bool has_compliance() const { return has_compliance_; }
  /// effects on the joint angles besides compliance (transmission error, backlash)
  bool has_joint_effects() const { return !joint_effects_.empty(); }
  const std::vector<EffectValue>& joint_effects() const { return joint_effects_; }
  /// the harmonic joint effects (transmission error, joint map) term by term: the order k and the
  /// sine and cosine amplitudes (rad) on a joint, dq_j = s sin(k q_j) + c cos(k q_j)
  struct HarmonicTerm {
    int joint, k;
    double sin_amp, cos_amp;
  };
  const std::vector<HarmonicTerm>& harmonic_terms() const { return harmonic_terms_; }
  /// joint j's harmonic terms' bound of their sum's sixth derivative over 6!: sum k^6 (|s| + |c|) / 720
  double harmonic_bound(int j) const { return harmonic_bound_[j]; }
  bool needs_dir() const { return needs_dir_; }                  ///< backlash: dir1..dirN needed
  bool needs_temperature() const { return thermal_alpha_ != 0; }  ///< thermal expansion: T needed
  double thermal_alpha() const { return thermal_alpha_; }         ///< 1/degC (0: none)
  const Vec3& axis(int j) const { return w_[j]; }
  const Vec3& point(int j) const { return p_[j]; }
  const Eigen::Isometry3d& tool() const { return tool_; }
  bool within_limits_deg(const VecQ& q_deg, double tol_deg = 1e-9) const;

  // --- compiled evaluator data (read by kinematics.cpp) ---
  /// T(q) = C0 * prod_j [Rz(q_j + offset_j) Trans(t_j) Rx(alpha_j)] with the last Rx replaced by the
  /// general tool rotation: every constant link rotation split as Rz Rx Rz, the Rz parts merged into
  /// the joint rotations (an exact rewriting of the chain, cheaper to evaluate than 3x3 products).
  struct Link {
    double offset;   ///< added to the joint angle (rad)
    double ca, sa;   ///< cos and sin of alpha, the rotation about x after the joint (not on the last)
    Vec3 t;          ///< translation after the joint, in the joint's local frame (mm)
    double m;        ///< mass carried by the joint's link (payload included on the last)
    Vec3 mc;         ///< first moment m * com in the joint's local frame (kg mm)
  };
  const Mat3& c0_r() const { return c0_r_; }
  const Vec3& c0_t() const { return c0_t_; }
  const Link& link(int j) const { return links_[j]; }
  /// rotation after the last joint (to the tool frame), local frame of the last joint
  const Mat3& last_r() const { return last_r_; }
  const Vec3& gravity() const { return g_; }
  /// compliance in rad per N mm (internal unit)
  double compliance(int j) const { return k_[j]; }
  /// cos and sin of link(j).offset: sin q, cos q of a joint angle from those of q + offset
  double offset_cos(int j) const { return offset_cs_[j][0]; }
  double offset_sin(int j) const { return offset_cs_[j][1]; }

 private:
  // the constructor's steps, in order
  void take_effects(const std::string& who);
  void check_values(const std::string& who);
  void find_loaded_joints(const std::string& who);
  void compile_links();
  void build_kdl_chain();

  ModelSpec spec_;
  int n_ = 0;
  std::unique_ptr<KDL::Chain> chain_;
  std::array<bool, kMaxJoints> loaded_{};
  bool has_compliance_ = false;
  std::vector<EffectValue> joint_effects_;
  std::vector<HarmonicTerm> harmonic_terms_;
  std::array<double, kMaxJoints> harmonic_bound_{};
  bool needs_dir_ = false;
  double thermal_alpha_ = 0;
  std::array<Vec3, kMaxJoints> w_, p_;
  std::array<double, kMaxJoints> k_{};
  Eigen::Isometry3d tool_;
  Mat3 c0_r_;
  Vec3 c0_t_;
  // the compiled chain on cache-line boundaries: FK, Jacobians and compensation walk it every call
  // (without this, removing the IK data from the Model cost the compliance compensation 5%)
  alignas(64) std::array<Link, kMaxJoints> links_;
  Mat3 last_r_;
  Vec3 g_;
  std::array<std::array<double, 2>, kMaxJoints> offset_cs_{};
};

using ModelPtr = std::shared_ptr<const Model>;

class IkSolver;  // kincal/ik/ik.hpp

/// A robot as users name it: the nominal geometry (for the closed-form IK start), the calibrated one
/// (for FK and compensation) and the campaign that calibrated it (campaign.hpp: the instrument's
/// placements and drift, the fitted joint ranges; empty for a nominal robot unless its file gives a
/// placement). For a nominal robot both models are the same object. The nominal model's IK solver is
/// built once with the Robot (src/model/robot.cpp), so that programs do not rebuild it per pose.
class Robot {
 public:
  Robot() = default;  ///< no models (to be assigned a whole Robot)
  /// InputError when the campaign does not fit the models (campaign.hpp's check)
  Robot(ModelPtr nominal_model, ModelPtr calibrated_model, Campaign campaign = {});
  /// Everything is fixed at construction (a new Robot for new models): the IK below always follows
  /// the nominal model it was built from
  const ModelPtr& nominal() const { return nominal_; }
  const ModelPtr& calibrated() const { return calibrated_; }
  const Campaign& campaign() const { return *campaign_; }
  bool identified() const { return nominal_ != calibrated_; }
  /// the nominal model's closed-form IK (ik/ik.hpp); only on a Robot built with its models
  const IkSolver& ik() const { return *ik_; }

 private:
  ModelPtr nominal_;
  ModelPtr calibrated_;
  std::shared_ptr<const Campaign> campaign_ = std::make_shared<const Campaign>();
  std::shared_ptr<const IkSolver> ik_;
};

}  // namespace kincal
