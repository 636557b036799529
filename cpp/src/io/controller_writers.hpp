// kincal: what the controller writers share (private to cpp/src/io): number formatting, the speed
// and zone defaults, names, splitting into parts, and the writers of each language.
#pragma once

#include "kincal/io/controllers.hpp"

#include <cstddef>
#include <string>
#include <utility>
#include <vector>

namespace kincal::ctl {

/// The printed precision of joint targets: KRL and RAPID 1e-6 deg (KRL REAL is single precision: about
/// 1e-5 deg kept), FANUC LS 1e-4 deg and mm (the controller keeps single precision), URScript 1e-10 rad
/// (6e-9 deg); positions in mm.
constexpr int kJointDecimals = 6;
constexpr int kMmDecimals = 4;
constexpr int kLsDecimals = 4;
constexpr int kRadDecimals = 10;

/// v with the given decimals, never "-0.000"; InputError when v is not finite.
std::string fixed(double v, int decimals);
/// The joint speed in percent (1..100) and the linear speed in mm/s of the options (defaults 20, 250).
double joint_speed_pct(const WriterOptions& o);
double linear_speed_mm_s(const WriterOptions& o);
/// The zone (0: exact stop).
double zone_of(const WriterOptions& o);

/// The folder part of a path with its slash ("" for none), the file's stem, a path with another
/// extension.
std::string dir_of(const std::string& path);
std::string stem_of(const std::string& path);
std::string with_ext(const std::string& path, const std::string& ext);

/// InputError unless name starts with a letter, has only letters, digits and '_' and at most
/// max_len characters ("<language> program name '<name>': cause").
void check_name(const std::string& name, size_t max_len, const char* language);

/// The target ranges [begin, end) of the parts: one range when n <= max (or max <= 0).
std::vector<std::pair<size_t, size_t>> parts(size_t n, int max);

/// The unit quaternion (w, x, y, z) of KUKA ABC angles (deg), w >= 0.
std::array<double, 4> quaternion_of(const Vec3& abc_deg);
/// The rotation vector (rad) of KUKA ABC angles (deg), as URScript poses take it.
Vec3 rotation_vector_of(const Vec3& abc_deg);

std::vector<OutputFile> write_krl(const std::string& out, const std::vector<ControllerTarget>& t,
                                  const WriterOptions& o, const std::string& name);
std::vector<OutputFile> write_rapid(const std::string& out, const std::vector<ControllerTarget>& t,
                                    const WriterOptions& o, const std::string& name);
std::vector<OutputFile> write_fanuc_ls(const std::string& out, const std::vector<ControllerTarget>& t,
                                       const WriterOptions& o, const std::string& name);
std::vector<OutputFile> write_urscript(const std::string& out, const std::vector<ControllerTarget>& t,
                                       const WriterOptions& o, const std::string& name);

}  // namespace kincal::ctl
