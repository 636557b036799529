// kincal: hidden-robot kinematics, synthesis, the error matrix and the over-constrained truth.
#include "kincal/fivebar/fivebar.hpp"

#include "kincal/io/csv.hpp"
#include "kincal/model/model.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

namespace kincal {

using json = nlohmann::json;

namespace {

Vec2 unit(double t) { return Vec2(std::cos(t), std::sin(t)); }

/// Intersection of circle (p, r) and circle (q, s) on the side `mode` of the line p->q.
bool circles(const Vec2& p, double r, const Vec2& q, double s, int mode, Vec2& out) {
  const Vec2 pq = q - p;
  const double l2 = pq.squaredNorm();
  if (l2 <= 0) return false;
  const double l = std::sqrt(l2);
  const double x = (r * r - s * s + l2) / (2 * l);  // along pq from p
  const double h2 = r * r - x * x;
  if (h2 < 0) return false;
  const Vec2 ex = pq / l, ey(-ex.y(), ex.x());
  // (B - A) x (C - A) > 0 means C on the left of A->B: +ey
  out = p + x * ex + (mode >= 0 ? 1.0 : -1.0) * std::sqrt(h2) * ey;
  return true;
}

double wrap_near(double t, double ref) { return t + 2 * kPi * std::round((ref - t) / (2 * kPi)); }

}  // namespace

bool fivebar_fk(const FiveBar& m, double t1, double t2, Vec2& c) {
  const Vec2 A = m.a * unit(t1), B = m.d * unit(t2);
  return circles(A, m.b, B, m.c, m.assembly, c);
}

bool fivebar_ik(const FiveBar& m, const Vec2& c, double& t1, double& t2, const double* ref) {
  const double r2 = c.squaredNorm();
  const double r = std::sqrt(r2);
  if (r <= 0) return false;
  const double phi = std::atan2(c.y(), c.x());
  // x cos t + y sin t = k  (|C - a u(t)| = b)  =>  cos(t - phi) = k / r
  const double k1 = (r2 + m.a * m.a - m.b * m.b) / (2 * m.a * r);
  const double k2 = (r2 + m.d * m.d - m.c * m.c) / (2 * m.d * r);
  if (std::abs(k1) > 1 || std::abs(k2) > 1) return false;
  t1 = phi + (m.working1 >= 0 ? 1.0 : -1.0) * std::acos(k1);
  t2 = phi + (m.working2 >= 0 ? 1.0 : -1.0) * std::acos(k2);
  if (ref) {
    t1 = wrap_near(t1, ref[0]);
    t2 = wrap_near(t2, ref[1]);
  }
  return true;
}

bool fivebar_jacobian(const FiveBar& m, double t1, double t2, Mat2& j) {
  Vec2 c;
  if (!fivebar_fk(m, t1, t2, c)) return false;
  const Vec2 A = m.a * unit(t1), B = m.d * unit(t2);
  // C - A = b u3, C - B = c u4; dC = a u1' dt1 + b u3' dt3 = d u2' dt2 + c u4' dt4.
  // Dotting with u3 removes dt3: u3 . dC = a (u3 . u1') dt1, likewise for the right dyad.
  const Vec2 u3 = (c - A) / m.b, u4 = (c - B) / m.c;
  const Vec2 u1p(-std::sin(t1), std::cos(t1)), u2p(-std::sin(t2), std::cos(t2));
  Mat2 n;  // n * dC = diag(g) * dtheta
  n.row(0) = u3.transpose();
  n.row(1) = u4.transpose();
  const double g1 = m.a * u3.dot(u1p), g2 = m.d * u4.dot(u2p);
  const double det = n.determinant();
  if (std::abs(det) < 1e-12 || std::abs(g1) < 1e-12 * m.a || std::abs(g2) < 1e-12 * m.d) return false;
  j = n.inverse() * Eigen::Vector2d(g1, g2).asDiagonal();
  return true;
}

bool fivebar_length_jacobian(const FiveBar& m, double t1, double t2, Eigen::Matrix<double, 2, 4>& j) {
  Vec2 c;
  if (!fivebar_fk(m, t1, t2, c)) return false;
  const Vec2 u1 = unit(t1), u2 = unit(t2);
  const Vec2 u3 = (c - m.a * u1) / m.b, u4 = (c - m.d * u2) / m.c;
  Mat2 n;
  n.row(0) = u3.transpose();
  n.row(1) = u4.transpose();
  if (std::abs(n.determinant()) < 1e-12) return false;
  const Mat2 ni = n.inverse();
  // |C - A|^2 = b^2, |C - B|^2 = c^2: u3 . dC = db + (u3 . u1) da ; u4 . dC = dc + (u4 . u2) dd
  j.col(0) = ni * Vec2(u3.dot(u1), 0);
  j.col(1) = ni * Vec2(1, 0);
  j.col(2) = ni * Vec2(0, 1);
  j.col(3) = ni * Vec2(0, u4.dot(u2));
  return true;
}

// ---------------------------------------------------------------------------------------------
// Table files
// ---------------------------------------------------------------------------------------------
std::vector<FiveBarPoint> read_fivebar_table(const std::string& path) {
  const CsvTable t = read_csv(path);
  const int cp = t.find("point");
  const int c1 = t.require("theta1_deg"), c2 = t.require("theta2_deg");
  const int cxd = t.require("x_desired_mm"), cyd = t.require("y_desired_mm");
  const int cxm = t.require("x_measured_mm"), cym = t.require("y_measured_mm");
  std::vector<FiveBarPoint> out;
  for (size_t r = 0; r < t.cells.size(); ++r) {
    FiveBarPoint p;
    p.id = cp >= 0 ? static_cast<int>(t.number(r, cp)) : static_cast<int>(r + 1);
    p.t1_deg = t.number(r, c1);
    p.t2_deg = t.number(r, c2);
    p.desired = Vec2(t.number(r, cxd), t.number(r, cyd));
    p.measured = Vec2(t.number(r, cxm), t.number(r, cym));
    p.line = t.line[r];
    out.push_back(p);
  }
  if (out.empty()) throw InputError(path + ": no points");
  return out;
}

// ---------------------------------------------------------------------------------------------
// Synthesis (eqs. 1-6), each dyad separately
// ---------------------------------------------------------------------------------------------
namespace {

// P1 + P2 f2 = F with f2 = 2 (x cos t + y sin t), F = x^2 + y^2; crank = P2, coupler = sqrt(P2^2 + P1)
bool dyad(const std::vector<FiveBarPoint>& pts, const std::vector<int>& use, bool left, bool lsq, double& crank,
          double& coupler) {
  Eigen::Matrix2d ata = Eigen::Matrix2d::Zero();
  Eigen::Vector2d atb = Eigen::Vector2d::Zero();
  if (!lsq && use.size() != 2) return false;
  for (int i : use) {
    const FiveBarPoint& p = pts[i];
    const double t = (left ? p.t1_deg : p.t2_deg) * kDeg;
    const Eigen::Vector2d row(1.0, 2 * (p.measured.x() * std::cos(t) + p.measured.y() * std::sin(t)));
    const double F = p.measured.squaredNorm();
    ata += row * row.transpose();
    atb += row * F;
  }
  if (std::abs(ata.determinant()) < 1e-9 * ata.squaredNorm()) return false;
  const Eigen::Vector2d P = ata.ldlt().solve(atb);  // two points: the exact solution of eq. 2
  crank = P[1];
  const double b2 = P[1] * P[1] + P[0];  // b = sqrt(a^2 + P1) (the paper prints P1^2: a slip)
  if (!(crank > 0) || !(b2 > 0)) return false;
  coupler = std::sqrt(b2);
  return std::isfinite(crank) && std::isfinite(coupler);
}

}  // namespace

bool fivebar_synthesis(const std::vector<FiveBarPoint>& pts, const std::vector<int>& use, bool least_squares,
                       FiveBar& out) {
  return dyad(pts, use, true, least_squares, out.a, out.b) && dyad(pts, use, false, least_squares, out.d, out.c);
}

double fivebar_max_error(const FiveBar& m, const std::vector<FiveBarPoint>& pts, bool desired) {
  double worst = 0;
  for (const auto& p : pts) {
    Vec2 c;
    if (!fivebar_fk(m, p.t1_deg * kDeg, p.t2_deg * kDeg, c)) return std::numeric_limits<double>::infinity();
    worst = std::max(worst, (c - (desired ? p.desired : p.measured)).norm());
  }
  return worst;
}

SubsetResult fivebar_best_subset(const std::vector<FiveBarPoint>& pts, bool least_squares, bool desired_score,
                                 int n_min, int n_max) {
  const int N = static_cast<int>(pts.size());
  if (N > 30) throw InputError("subset search: " + std::to_string(N) + " points give too many subsets; use minimax");
  SubsetResult best;
  best.max_error = std::numeric_limits<double>::infinity();
  for (int n = std::max(2, n_min); n <= std::min(N, n_max); ++n) {
    std::vector<int> idx(n);
    for (int i = 0; i < n; ++i) idx[i] = i;
    while (true) {
      FiveBar m;
      ++best.subsets_tried;
      if (fivebar_synthesis(pts, idx, least_squares, m)) {
        const double e = fivebar_max_error(m, pts, desired_score);
        if (e < best.max_error) {
          best.max_error = e;
          best.model = m;
          best.points = idx;
        }
      }
      int k = n - 1;
      while (k >= 0 && idx[k] == N - n + k) --k;
      if (k < 0) break;
      ++idx[k];
      for (int i = k + 1; i < n; ++i) idx[i] = idx[i - 1] + 1;
    }
  }
  if (!std::isfinite(best.max_error)) throw InputError("subset search: no subset gives a mechanism that closes");
  return best;
}

// ---------------------------------------------------------------------------------------------
// Error matrix (eq. 7)
// ---------------------------------------------------------------------------------------------
Vec2 ErrorMatrix::at(const Vec2& p) const {
  const double fx = std::clamp((p.x() - x0) / dx, 0.0, static_cast<double>(nx - 1));
  const double fy = std::clamp((p.y() - y0) / dy, 0.0, static_cast<double>(ny - 1));
  const int ix = std::min(static_cast<int>(fx), nx - 2), iy = std::min(static_cast<int>(fy), ny - 2);
  const double u = fx - ix, v = fy - iy;
  const int k = iy * nx + ix;
  const double w11 = (1 - u) * (1 - v), w21 = u * (1 - v), w12 = (1 - u) * v, w22 = u * v;
  return Vec2(w11 * ex[k] + w21 * ex[k + 1] + w12 * ex[k + nx] + w22 * ex[k + nx + 1],
              w11 * ey[k] + w21 * ey[k + 1] + w12 * ey[k + nx] + w22 * ey[k + nx + 1]);
}

std::string ErrorMatrix::to_json() const {
  json j = {{"format", "kincal-error-matrix"}, {"version", 1}, {"x0_mm", x0}, {"y0_mm", y0},
            {"dx_mm", dx},  {"dy_mm", dy},  {"nx", nx},     {"ny", ny},
            {"error_x_mm", ex}, {"error_y_mm", ey},
            {"note", "errors are desired - measured at the grid nodes, row-major (iy * nx + ix)"}};
  return j.dump(1) + "\n";
}

ErrorMatrix ErrorMatrix::from_json(const std::string& text, const std::string& source) {
  json j;
  try {
    j = json::parse(text);
  } catch (const json::exception& e) {  // parse errors, and numbers out of range (1e999)
    throw InputError(source + ": not valid JSON (" + e.what() + ")");
  }
  try {
    if (j.value("format", "") != "kincal-error-matrix")
      throw InputError(source + ": not a kincal error matrix (\"format\": \"kincal-error-matrix\")");
    if (j.value("version", 0) != 1) throw InputError(source + ": error matrix version " + j["version"].dump() + " (expected 1)");
    ErrorMatrix m;
    m.x0 = j.at("x0_mm");
    m.y0 = j.at("y0_mm");
    m.dx = j.at("dx_mm");
    m.dy = j.at("dy_mm");
    m.nx = j.at("nx");
    m.ny = j.at("ny");
    m.ex = j.at("error_x_mm").get<std::vector<double>>();
    m.ey = j.at("error_y_mm").get<std::vector<double>>();
    if (m.nx < 2 || m.ny < 2 || !(m.dx > 0) || !(m.dy > 0) || m.ex.size() != static_cast<size_t>(m.nx * m.ny) ||
        m.ey.size() != m.ex.size())
      throw InputError(source + ": inconsistent error matrix (nx, ny, spacing and value counts)");
    for (size_t i = 0; i < m.ex.size(); ++i)
      if (!std::isfinite(m.ex[i]) || !std::isfinite(m.ey[i])) throw InputError(source + ": a value is not finite");
    return m;
  } catch (const json::exception& e) {
    throw InputError(source + ": " + e.what());
  }
}

ErrorMatrix ErrorMatrix::from_points(const std::vector<FiveBarPoint>& grid, const std::string& source) {
  if (grid.size() < 4) throw InputError(source + ": a grid needs at least 2 x 2 points");
  std::vector<double> xs, ys;
  for (const auto& p : grid) xs.push_back(p.desired.x()), ys.push_back(p.desired.y());
  auto uniq = [](std::vector<double> v) {
    std::sort(v.begin(), v.end());
    std::vector<double> u;
    for (double x : v)
      if (u.empty() || x - u.back() > 1e-6) u.push_back(x);
    return u;
  };
  const std::vector<double> ux = uniq(xs), uy = uniq(ys);
  ErrorMatrix m;
  m.nx = static_cast<int>(ux.size());
  m.ny = static_cast<int>(uy.size());
  if (m.nx < 2 || m.ny < 2) throw InputError(source + ": the desired points do not span a 2-D grid");
  m.x0 = ux.front();
  m.y0 = uy.front();
  m.dx = (ux.back() - ux.front()) / (m.nx - 1);
  m.dy = (uy.back() - uy.front()) / (m.ny - 1);
  m.ex.assign(m.nx * m.ny, std::nan(""));
  m.ey = m.ex;
  for (const auto& p : grid) {
    const double fx = (p.desired.x() - m.x0) / m.dx, fy = (p.desired.y() - m.y0) / m.dy;
    const int ix = static_cast<int>(std::lround(fx)), iy = static_cast<int>(std::lround(fy));
    if (std::abs(fx - ix) > 1e-3 || std::abs(fy - iy) > 1e-3)
      throw InputError(source + ":" + std::to_string(p.line) + ": the desired point is not on a regular grid");
    const int k = iy * m.nx + ix;
    if (!std::isnan(m.ex[k])) throw InputError(source + ":" + std::to_string(p.line) + ": a grid node measured twice");
    const Vec2 e = p.desired - p.measured;
    m.ex[k] = e.x();
    m.ey[k] = e.y();
  }
  if (grid.size() != static_cast<size_t>(m.nx * m.ny))
    throw InputError(source + ": " + std::to_string(grid.size()) + " points but a " + std::to_string(m.nx) + " x " +
                     std::to_string(m.ny) + " grid needs " + std::to_string(m.nx * m.ny));
  return m;
}

// ---------------------------------------------------------------------------------------------
// The corrector
// ---------------------------------------------------------------------------------------------
FiveBarCorrector::FiveBarCorrector(const FiveBar& m, const ErrorMatrix* matrix)
    : m_(m), has_matrix_(matrix != nullptr) {
  if (matrix) e_ = *matrix;
}

bool FiveBarCorrector::command(const Vec2& p, double& t1_deg, double& t2_deg) {
  double t1, t2;
  if (!fivebar_ik(m_, p, t1, t2, have_ref_ ? ref_ : nullptr)) return false;
  if (has_matrix_) {
    Mat2 j;
    if (!fivebar_jacobian(m_, t1, t2, j)) return false;
    // the machine lands short of the target by e = desired - measured: aim e further (eq. 8)
    const Vec2 dt = j.inverse() * e_.at(p);
    t1 += dt[0];
    t2 += dt[1];
  }
  ref_[0] = t1;
  ref_[1] = t2;
  have_ref_ = true;
  t1_deg = t1 / kDeg;
  t2_deg = t2 / kDeg;
  return true;
}

std::vector<Vec2> fivebar_commands(const FiveBar& m, const ErrorMatrix* matrix, const std::vector<Vec2>& xy,
                                   const std::function<std::string(size_t)>& where) {
  FiveBarCorrector corr(m, matrix);
  std::vector<Vec2> out(xy.size());
  for (size_t i = 0; i < xy.size(); ++i)
    if (!corr.command(xy[i], out[i][0], out[i][1]))
      throw InputError(where(i) + ": (" + std::to_string(xy[i][0]) + ", " + std::to_string(xy[i][1]) +
                       ") is out of the hidden robot's reach");
  return out;
}

std::vector<Vec2> fivebar_command_file(const FiveBar& m, const ErrorMatrix* matrix, const std::string& path) {
  const CsvTable t = read_csv(path);
  if (t.cells.empty()) throw InputError(path + ": no rows");
  const int cx = t.require("x"), cy = t.require("y");
  std::vector<Vec2> xy(t.cells.size());
  for (size_t r = 0; r < t.cells.size(); ++r) xy[r] = Vec2(t.number(r, cx), t.number(r, cy));
  return fivebar_commands(m, matrix, xy, [&t](size_t i) { return t.where(i); });
}

std::string fivebar_to_json(const FiveBar& m) {
  return json{{"a", m.a}, {"b", m.b}, {"c", m.c}, {"d", m.d}}.dump();
}

FiveBar fivebar_from_json(const std::string& text, const std::string& source) {
  json j;
  try {
    j = json::parse(text);
  } catch (const json::exception& e) {  // parse errors, and numbers out of range (1e999)
    throw InputError(source + ": not valid JSON (" + e.what() + ")");
  }
  FiveBar m;
  for (const char* k : {"a", "b", "c", "d"}) {
    if (!j.contains(k) || !j[k].is_number())
      throw InputError(source + ": missing link length \"" + std::string(k) + "\" (a hidden-robot FIT.json)");
    const double v = j[k];
    if (!(v > 0) || !std::isfinite(v)) throw InputError(source + ": link length \"" + std::string(k) + "\" must be positive");
  }
  m.a = j["a"];
  m.b = j["b"];
  m.c = j["c"];
  m.d = j["d"];
  return m;
}

// ---------------------------------------------------------------------------------------------
// The over-constrained 6-bar (truth)
// ---------------------------------------------------------------------------------------------
bool SixBar::position(double t1_deg, double t2_deg, Vec2& cpos, double* mismatch) const {
  const double t1 = (t1_deg + offset1_deg) * kDeg, t2 = (t2_deg + offset2_deg) * kDeg;
  const Vec2 A0(-e / 2, 0), B0(e / 2, 0);
  const Vec2 A = A0 + a * unit(t1), B = B0 + d * unit(t2);
  double phi = 0, mu = 0;
  Vec2 D = Vec2::Zero();
  for (int it = 0; it < 8; ++it) {
    const double be = b + strain_b * mu, ce = c + strain_c * mu;
    const Vec2 plat = e * unit(phi);
    // D on circle (A, be); E = D + plat on circle (B, ce)
    if (!circles(A, be, B - plat, ce, +1, D)) return false;
    const Vec2 E = D + plat;
    const double t3 = std::atan2(D.y() - A.y(), D.x() - A.x()), t4 = std::atan2(E.y() - B.y(), E.x() - B.x());
    // platform angle each side's parallelograms want (first order in the companions' errors)
    const double phil = (companion_error[0] * std::cos(t1) + companion_error[1] * std::cos(t3)) / h;
    const double phir = (companion_error[2] * std::cos(t2) + companion_error[3] * std::cos(t4)) / h;
    phi = 0.5 * (phil + phir);
    mu = phil - phir;
  }
  cpos = D + 0.5 * e * unit(phi);
  if (mismatch) *mismatch = mu;
  return true;
}

void SixBar::coupler_lengths(double t1_deg, double t2_deg, double& b_eff, double& c_eff) const {
  Vec2 cpos;
  double mu = 0;
  position(t1_deg, t2_deg, cpos, &mu);
  b_eff = b + strain_b * mu;
  c_eff = c + strain_c * mu;
}

std::vector<FiveBarPoint> sixbar_campaign(const SixBar& truth, const FiveBar& model, const ErrorMatrix* matrix,
                                          const std::vector<Vec2>& targets, double noise_mm, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> nd(0.0, 1.0);
  std::uniform_real_distribution<double> ud(0.0, 1.0);
  FiveBarCorrector corr(model, matrix);
  std::vector<FiveBarPoint> out;
  int id = 0;
  for (const Vec2& t : targets) {
    ++id;
    FiveBarPoint p;
    if (!corr.command(t, p.t1_deg, p.t2_deg)) continue;
    Vec2 c;
    if (!truth.position(p.t1_deg, p.t2_deg, c)) continue;
    const double r = truth.clearance * std::sqrt(ud(rng)), ang = 2 * kPi * ud(rng);
    c += r * unit(ang);
    c += noise_mm * Vec2(nd(rng), nd(rng));
    p.id = id;
    p.desired = t;
    p.measured = c;
    out.push_back(p);
  }
  return out;
}

SixBar paper_sixbar(unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  SixBar s;
  s.e = 40;
  s.a = 150 + 0.1 * u(rng);
  s.b = 150 + 0.1 * u(rng);
  s.c = 150 + 0.1 * u(rng);
  s.d = 150 + 0.1 * u(rng);
  s.offset1_deg = 0.3 * u(rng);
  s.offset2_deg = 0.3 * u(rng);
  for (double& v : s.companion_error) v = 0.08 * u(rng);
  s.strain_b = 150;
  s.strain_c = -150;
  s.clearance = 0.002;
  return s;
}

}  // namespace kincal
