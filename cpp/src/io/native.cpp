// kincal: native programs (KRL, RAPID) in and out: the readers are krl_reader.cpp and rapid_reader.cpp;
// the writer replaces each target's value span and keeps every other byte.
#include "kincal/io/native.hpp"

#include "controller_writers.hpp"
#include "kincal/io/file.hpp"

#include <algorithm>
#include <map>

namespace kincal {

NativeProgram read_krl_program(const std::string& src_path);
NativeProgram read_rapid_program(const std::string& path);
std::string krl_aggregate(const std::string& old, const Pose6& pose, const ControllerTarget& t, bool is_frame);
std::string rapid_robtarget(const std::string& old, const Pose6& pose, const ControllerTarget& t);

NativeProgram read_native_program(const std::string& path, ControllerFormat format) {
  if (format == ControllerFormat::Krl) return read_krl_program(path);
  if (format == ControllerFormat::Rapid) return read_rapid_program(path);
  throw InputError(path + ": kincal reads KRL (.src + .dat) and RAPID (.mod) programs, CSV and G-code; not " +
                   format_name(format) + " yet");
}

std::vector<OutputFile> write_native_program(const NativeProgram& p, const std::vector<Pose6>& pose,
                                             const std::vector<ControllerTarget>& t, const std::string& out_path) {
  std::vector<std::vector<std::string>> lines = p.lines;
  // per line, the replacements from the right so that earlier spans keep their places
  std::map<std::pair<int, int>, std::vector<size_t>> by_line;
  for (size_t k = 0; k < p.targets.size(); ++k) by_line[{p.targets[k].file, p.targets[k].line}].push_back(k);
  for (auto& [key, ks] : by_line) {
    std::sort(ks.begin(), ks.end(), [&](size_t a, size_t b) { return p.targets[a].begin > p.targets[b].begin; });
    std::string& l = lines[static_cast<size_t>(key.first)][static_cast<size_t>(key.second - 1)];
    for (size_t k : ks) {
      const NativeTarget& nt = p.targets[k];
      const std::string old = l.substr(nt.begin, nt.end - nt.begin);
      std::string now;
      if (p.format == ControllerFormat::Krl) {
        std::string head = l.substr(0, nt.begin);
        for (char& c : head) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
        now = krl_aggregate(old, pose[k], t[k], head.find("FRAME") != std::string::npos);
      } else {
        now = rapid_robtarget(old, pose[k], t[k]);
      }
      l.replace(nt.begin, nt.end - nt.begin, now);
    }
  }
  std::vector<OutputFile> out;
  for (size_t f = 0; f < lines.size(); ++f) {
    std::string text;
    for (size_t i = 0; i < lines[f].size(); ++i) {
      text += lines[f][i];
      if (i + 1 < lines[f].size() || p.final_newline[f]) text += '\n';
    }
    const std::string path = p.format == ControllerFormat::Krl ? ctl::with_ext(out_path, f == 0 ? ".src" : ".dat") : out_path;
    out.push_back({path, text});
  }
  return out;
}

}  // namespace kincal
