// kincal (private): what PointModel and PointState hold (point_model.hpp). PointStructure is what
// the layout fixes (built once); PointEval the model at one parameter vector (built by
// PointModel::at, never changed after). Their prediction is in point_model.cpp, the gravity's parts
// in point_model_gravity.cpp.
#pragma once

#include "kincal/identify/point_model.hpp"
#include "kincal/identify/stations.hpp"

#include <array>
#include <memory>
#include <utility>
#include <vector>

namespace kincal::detail {

/// What the layout fixes: the nominal model, the layout, the directions u, v normal to every nominal
/// axis, each setup's reference frame, the fitted gravity's zero-moment centres of mass and the
/// payloads that get a model of their own.
struct PointStructure {
  /// data: its payloads get their model variants, its planes their reference normals; reference:
  /// the placements the setups' corrections are relative to.
  PointStructure(const Model& nominal, const LayoutOptions& options, const MeasurementSet* data,
                 const Campaign& reference);
  const Model& nominal;
  ParamLayout layout;
  std::vector<Vec3> u, v;
  std::vector<Mat3> r0;  ///< every setup's reference frame: rotation
  std::vector<Vec3> t0;  ///< and translation
  std::vector<Vec3> com0;  ///< with the gravity fitted: each link's centre of mass at zero moments
  std::vector<double> payloads;  ///< payloads other than the model's named in the data (kg)
  /// every station's reference normal (planes: towards the flange; stations.cpp) and two unit
  /// directions normal to it, along which its tilt parameters turn it
  std::vector<Vec3> station_normal, station_u, station_v;
  std::vector<Vec3> target_start;  ///< the targets' start (LayoutOptions::target_start)
  /// The reference normals: the layout's when it has them, else from the data (the plane through
  /// each plane station's nominal ball centres, towards the flange), else z; stored in the layout.
  void init_stations(const MeasurementSet* data);
  void compute_normals(const MeasurementSet& data);
};

/// Every setup's instrument placement at the start: the best rigid fit (Horn) of the nominal tool
/// point to that setup's point and pose rows (three at least), else its reference frame.
std::vector<Eigen::Isometry3d> start_placements(const PointStructure& s, const MeasurementSet& data);
/// The stations' start values into x (their parameters): a sphere's centre the mean of its rows'
/// nominal tool points, a pivot the point at the rows' lengths from them (least squares), a plane at
/// its reference normal through them.
void start_stations(const PointStructure& s, const MeasurementSet& data, const std::vector<Eigen::Isometry3d>& place,
                    std::vector<double>& x);

/// mm of artifact residual per radian of an angle between planes (a 1 m lever)
constexpr double kArtifactLever = 1000.0;

/// With the gravity fitted: each link's centre of mass at zero moments (point_model.hpp), from the
/// nominal geometry.
std::vector<Vec3> zero_moment_centres(const Model& nominal, const ParamLayout& layout);

/// Every row's flange frame (and thermal scale) at one set of the robot's own parameters: what the
/// fit of the frames alone reuses while only the frames move.
struct FlangeCache {
  struct Flange {
    Mat3 r;
    Vec3 t;
    double scale;
  };
  std::vector<Flange> rows;
  const Measurement* first = nullptr;  ///< the rows they are of (their data's first row)
};

/// The model at one parameter vector.
class PointEval {
 public:
  /// flanges: the frames-only mode (PointModel::at_frames_only) with those rows' flange frames.
  PointEval(std::shared_ptr<const PointStructure> s, const std::vector<double>& x,
            std::shared_ptr<const FlangeCache> flanges = nullptr);
  /// Every row's flange frame at these parameters.
  std::shared_ptr<const FlangeCache> compute_flanges(const MeasurementSet& data) const;
  const std::shared_ptr<const PointStructure>& structure_ptr() const { return s_; }
  const std::shared_ptr<const FlangeCache>& flanges() const { return flanges_; }
  const PointStructure& structure() const { return *s_; }
  const std::vector<double>& x() const { return x_; }
  const ModelSpec& spec() const { return spec_; }
  const Campaign& campaign() const { return campaign_; }
  Vec3 predict(const Measurement& m, double* jac, Mat3* rot, double* jac_rot) const;
  int probe_residuals(const Measurement& m, int size, double* r, double* J) const;
  double artifact_residual(const ArtifactTerm& a, double* J) const;
  std::vector<StationValue> stations() const;

 private:
  std::shared_ptr<const PointStructure> s_;
  const Model& nominal_;
  const ParamLayout& layout_;
  const std::vector<Vec3>&u_, &v_;
  std::vector<double> x_;
  std::shared_ptr<const FlangeCache> flanges_;  ///< set: frames only
  const FlangeCache::Flange* cached_flange(const Measurement& m) const;
  ModelSpec spec_;
  Campaign campaign_;  ///< the placements at these parameters
  std::shared_ptr<const Model> current_;
  std::vector<std::pair<double, std::shared_ptr<const Model>>> payload_models_;
  /// One instrument placement at the current parameters: its frame (r, t) and the right Jacobian
  /// of its rotation vector.
  struct Placement {
    Mat3 r, jr;
    Vec3 t;
  };
  std::vector<Placement> place_;
  /// The row's placement (InputError for a setup code out of the layout); kept out of line with the
  /// drift's parts, so that predict()'s common path stays as compact as with one placement.
  [[gnu::noinline]] const Placement& placement(const Measurement& m) const;
  /// The placement at the row's time (rb, tb), tau in hours and the drift's rotation vector dw.
  [[gnu::noinline]] void drifted(const Measurement& m, const Placement& pl, Mat3& rb, Vec3& tb, double& tau,
                                 Vec3& dw) const;
  /// The drift's Jacobian columns at a row (rx: the rotated point R x).
  [[gnu::noinline]] void drift_columns(double tau, const Vec3& dw, const Vec3& rx, double* jac, double* jac_rot) const;
  Mat3 rm_, jrm_;
  Vec3 tm_;
  std::vector<Vec3> w_, p_;
  /// A station at the current parameters: its point c (sphere, pivot) or plane n . y = d with the
  /// normal's derivatives along its two tilt parameters.
  struct StationState {
    StationValue v;
    Vec3 dn[2] = {Vec3::Zero(), Vec3::Zero()};  ///< a plane's normal per unit of its tilt parameters
  };
  std::vector<StationState> station_;
  void init_stations();
  void fitted_masses(const std::vector<double>& x);  ///< the moments of x as spec_'s mass table
  const Model& model_for(double payload) const;
  void chain_frames(const VecQ& q, std::array<Mat3, kMaxJoints + 1>& gr, std::array<Vec3, kMaxJoints + 1>& gt) const;
  /// Gravity at the commanded angles: frames, centres of mass, moment arms and joint torques.
  struct GravityState {
    std::array<Mat3, kMaxJoints + 1> gr;
    std::array<Vec3, kMaxJoints + 1> gt, S;
    std::array<double, kMaxJoints + 1> M;
    std::array<Vec3, kMaxJoints> wc, oc, arm;
    std::array<double, kMaxJoints> tau{};
    Vec3 cp;
    double mp = 0;
  };
  void gravity_state(const Model& model, const Measurement& m, GravityState& gs) const;
  /// The joint frames G_0..G_n of row m with compliance and effects acting, and the thermal scale.
  void row_frames(const Model& model, const Measurement& m, GravityState& gs, std::array<Mat3, kMaxJoints + 1>& gr,
                  std::array<Vec3, kMaxJoints + 1>& gt, double& scale) const;
  /// The extra effects' columns of a row (jac_rot: their angular velocities, or null): a joint-angle
  /// effect's through its joint's rates jp, jw (scaled with the robot's point), thermal expansion's
  /// through the unscaled point xr; rb: the row's instrument placement (rotation).
  void effect_columns(const Measurement& m, const VecQ& q, const Mat3& rb, const Vec3& xr,
                      const std::array<Vec3, kMaxJoints>& jp, const std::array<Vec3, kMaxJoints>& jw, double scale,
                      double* jac, double* jac_rot) const;
  /// rb: the row's instrument placement (rotation).
  void add_torque_terms(const Model& model, const GravityState& gs, const std::array<Vec3, kMaxJoints>& jp,
                        const std::array<Vec3, kMaxJoints>& jw, const Mat3& rb, double* jac,
                        double* jac_rot) const;
};

}  // namespace kincal::detail
