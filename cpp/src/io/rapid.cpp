// kincal: ABB RAPID modules (IRC5 / OmniCore), and the values of a read module rewritten (rapid_robtarget,
// rapid_jointtarget: number by number, a value over several lines kept in its lines). New modules: MODULE NAME with the targets declared CONST
// (jointtarget for MoveAbsJ; robtarget with quaternion and confdata [cf1, cf4, cf6, cfx] for MoveJ
// then MoveL) and PROC main. Identifiers up to 32 characters. Speeds: VelSet (percent) for the joint
// motions, a declared speeddata (mm/s) for the linear ones; zones: fine, or a declared zonedata in the
// proportions of the predefined z10 ([FALSE, z, 1.5z, 1.5z, 0.15z, 1.5z, 0.15z]). The tool and work
// object are tool0 and wobj0 (filtered targets are the model's tool in the robot's base frame).
#include "controller_writers.hpp"

#include <algorithm>
#include <cctype>
#include <cstring>
#include <string>
#include <utility>
#include <vector>

namespace kincal::ctl {

namespace {

constexpr int kQuatDecimals = 9;
const char* const kNoExternal = "[9E9,9E9,9E9,9E9,9E9,9E9]";

}  // namespace

std::vector<OutputFile> write_rapid(const std::string& out, const std::vector<ControllerTarget>& t,
                                    const WriterOptions& o, const std::string& name) {
  const bool filtered = o.targets == TargetKind::Filtered;
  const double zone = zone_of(o);
  std::string s = "MODULE " + name + "\n";
  s += "  ! kincal compensate: " + std::to_string(t.size()) + (filtered ? " filtered Cartesian" : " joint") + " targets\n";
  if (zone > 0)
    s += "  CONST zonedata kc_zone:=[FALSE," + fixed(zone, 3) + "," + fixed(1.5 * zone, 3) + "," + fixed(1.5 * zone, 3) +
         "," + fixed(0.15 * zone, 4) + "," + fixed(1.5 * zone, 3) + "," + fixed(0.15 * zone, 4) + "];\n";
  if (filtered) s += "  CONST speeddata kc_speed:=[" + fixed(linear_speed_mm_s(o), 3) + ",500,5000,1000];\n";
  for (size_t i = 0; i < t.size(); ++i) {
    if (!filtered) {
      s += "  CONST jointtarget jt" + std::to_string(i + 1) + ":=[[";
      for (int j = 0; j < 6; ++j) s += (j ? "," : "") + fixed(t[i].q_deg[j], kJointDecimals);
      s += "]," + std::string(kNoExternal) + "];\n";
    } else {
      const auto q = quaternion_of(t[i].pose.abc);
      s += "  CONST robtarget p" + std::to_string(i + 1) + ":=[[";
      for (int k = 0; k < 3; ++k) s += (k ? "," : "") + fixed(t[i].pose.xyz[k], kMmDecimals);
      s += "],[";
      for (int k = 0; k < 4; ++k) s += (k ? "," : "") + fixed(q[static_cast<size_t>(k)], kQuatDecimals);
      s += "],[";
      for (int k = 0; k < 4; ++k) s += (k ? "," : "") + std::to_string(t[i].abb_conf[static_cast<size_t>(k)]);
      s += "]," + std::string(kNoExternal) + "];\n";
    }
  }
  s += "  PROC main()\n";
  s += "    ConfJ\\On;\n";
  if (filtered) s += "    ConfL\\On;\n";
  s += "    VelSet " + fixed(joint_speed_pct(o), 1) + ",7000;\n";
  for (size_t i = 0; i < t.size(); ++i) {
    const std::string z = zone > 0 && i + 1 < t.size() ? "kc_zone" : "fine";
    const std::string id = std::to_string(i + 1);
    if (!filtered) {
      s += "    MoveAbsJ jt" + id + "\\NoEOffs,v7000," + z + ",tool0;\n";
    } else if (i == 0) {
      s += "    MoveJ p1,v7000," + z + ",tool0\\WObj:=wobj0;\n";
      s += "    VelSet 100,7000;\n";
    } else {
      s += "    MoveL p" + id + ",kc_speed," + z + ",tool0\\WObj:=wobj0;\n";
    }
  }
  s += "  ENDPROC\nENDMODULE\n";
  return {{out, s}};
}

}  // namespace kincal::ctl

namespace kincal {

namespace {

// the spans of a value's top-level parts (inside its outer brackets)
std::vector<std::pair<size_t, size_t>> part_spans(const std::string& v) {
  std::vector<std::pair<size_t, size_t>> out;
  const size_t open = v.find('[');
  int depth = 0;
  size_t b = open + 1;
  for (size_t c = open; open != std::string::npos && c < v.size(); ++c) {
    if (v[c] == '[') ++depth;
    if (v[c] == ']' && --depth == 0) {
      out.emplace_back(b, c);
      break;
    }
    if (v[c] == ',' && depth == 1) out.emplace_back(b, c), b = c + 1;
  }
  for (auto& [x, y] : out) {
    while (x < y && std::isspace(static_cast<unsigned char>(v[x]))) ++x;
    while (y > x && std::isspace(static_cast<unsigned char>(v[y - 1]))) --y;
  }
  return out;
}

}  // namespace

// a robtarget value with trans, rot and robconf replaced number by number: every other character, the
// blanks and line breaks of a value over several lines and the extax included, kept as written
std::string rapid_robtarget(const std::string& old, const Pose6& pose, const ControllerTarget& t) {
  const auto q = ctl::quaternion_of(pose.abc);
  std::vector<std::string> now;
  for (int k = 0; k < 3; ++k) now.push_back(ctl::fixed(pose.xyz[k], 4));
  for (int k = 0; k < 4; ++k) now.push_back(ctl::fixed(q[static_cast<size_t>(k)], 9));
  for (int k = 0; k < 4; ++k) now.push_back(std::to_string(t.abb_conf[static_cast<size_t>(k)]));
  const auto parts = part_spans(old);
  std::string s = old;
  size_t n = now.size();
  for (size_t k = std::min<size_t>(3, parts.size()); k-- > 0;) {  // from the right: spans stay valid
    const std::string part = old.substr(parts[k].first, parts[k].second - parts[k].first);
    std::vector<std::pair<size_t, size_t>> num;
    for (size_t c = 0; c < part.size();) {
      if (std::strchr("+-.0123456789", part[c])) {
        size_t e = c;
        while (e < part.size() && std::strchr("+-.0123456789eE", part[e])) ++e;
        num.emplace_back(c, e), c = e;
      } else {
        ++c;
      }
    }
    const size_t want = k == 0 ? 3 : 4;
    if (num.size() != want || n < want) return old;  // (read values always have them)
    for (size_t j = want; j-- > 0;) s.replace(parts[k].first + num[j].first, num[j].second - num[j].first, now[--n]);
  }
  return s;
}

// a robtarget value as a jointtarget [[q1..q6],[extax]], its external axes kept as written (and as many
// line breaks as the robtarget had, for a value over several lines)
std::string rapid_jointtarget(const std::string& old, const Vec6& q_deg) {
  const auto parts = part_spans(old);
  std::string qs = "[";
  for (int j = 0; j < 6; ++j) qs += (j ? "," : "") + ctl::fixed(q_deg[j], ctl::kJointDecimals);
  qs += "]";
  if (parts.size() != 4) return "[" + qs + "]";
  std::string s = old.substr(0, parts[0].first) + qs + old.substr(parts[0].second, parts[1].first - parts[0].second);
  const std::string gone = old.substr(parts[1].first, parts[3].first - parts[1].first);
  const size_t breaks = static_cast<size_t>(std::count(gone.begin(), gone.end(), '\n'));
  const std::string eol = old.find('\r') != std::string::npos ? "\r\n" : "\n";
  for (size_t k = 0; k < breaks; ++k) s += eol;
  if (breaks) s += gone.substr(gone.find_last_of('\n') + 1);  // the extax's indentation
  return s + old.substr(parts[3].first);
}

}  // namespace kincal
