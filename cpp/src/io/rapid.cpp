// kincal: ABB RAPID modules (IRC5 / OmniCore): MODULE NAME with the targets declared CONST
// (jointtarget for MoveAbsJ; robtarget with quaternion and confdata [cf1, cf4, cf6, cfx] for MoveJ
// then MoveL) and PROC main. Identifiers up to 32 characters. Speeds: VelSet (percent) for the joint
// motions, a declared speeddata (mm/s) for the linear ones; zones: fine, or a declared zonedata in the
// proportions of the predefined z10 ([FALSE, z, 1.5z, 1.5z, 0.15z, 1.5z, 0.15z]). The tool and work
// object are tool0 and wobj0 (filtered targets are the model's tool in the robot's base frame).
#include "controller_writers.hpp"

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
