// kincal-compensate: offline and streaming compensation for controller PCs. Links no Python.
//
//   kincal-compensate --model M --program IN --out OUT [--frame base|instrument]
//   kincal-compensate --model M --stream [--frame base|instrument] < poses > joints
//   kincal-compensate --fivebar FIT.json [--matrix MATRIX.json] --program XY.csv --out J.csv
//   kincal-compensate --fivebar FIT.json [--matrix MATRIX.json] --stream < "x,y" lines > "theta1,theta2"
//
// M is a built-in robot name (kr500) or a model JSON written by kincal. Output equals
// `kincal compensate` (both run this library). Errors: one line "file:line: cause", exit 1, and no
// output file.
#include "kincal/fivebar/fivebar.hpp"
#include "kincal/compensation/backup.hpp"
#include "kincal/compensation/controller_program.hpp"
#include "kincal/compensation/program.hpp"
#include "kincal/compensation/stream.hpp"
#include "kincal/io/csv.hpp"
#include "kincal/io/file.hpp"
#include "kincal/io/model_json.hpp"
#include "kincal/model/joint_convention.hpp"

#include <CLI/CLI.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>
#include <iostream>
#include <optional>
#include <string>

namespace {

std::string slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw kincal::InputError(path + ": cannot open the file");
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

/// Five-bar corrector: hidden-robot IK, bilinear lookup, Jacobian correction (no allocation per line
/// in the streaming loop).
int run_fivebar(const std::string& fit_path, const std::string& matrix_path, const std::string& program,
                const std::string& out, bool stream) {
  const kincal::FiveBar fb = kincal::fivebar_from_json(slurp(fit_path), fit_path);
  kincal::ErrorMatrix m;
  if (!matrix_path.empty()) m = kincal::ErrorMatrix::from_json(slurp(matrix_path), matrix_path);
  kincal::FiveBarCorrector corr(fb, matrix_path.empty() ? nullptr : &m);
  char buf[128];
  if (stream) {
    std::string line;
    line.reserve(4096);
    long n = 0;
    while (std::getline(std::cin, line)) {
      ++n;
      const char* s = line.c_str();
      char* end;
      const double x = std::strtod(s, &end);
      const bool num_x = end != s;
      double y = 0;
      bool ok = num_x && *end == ',';
      if (ok) {
        const char* s2 = end + 1;
        y = std::strtod(s2, &end);
        ok = end != s2 && std::isfinite(x) && std::isfinite(y);
        while (ok && (*end == ' ' || *end == '\r' || *end == '\t')) ++end;
        ok = ok && *end == '\0';
      }
      int len;
      double t1, t2;
      if (!ok && n == 1 && !num_x) {
        len = std::snprintf(buf, sizeof buf, "theta1_deg,theta2_deg");  // the header line
      } else if (!ok) {
        len = std::snprintf(buf, sizeof buf, "error: stdin:%ld: expected x,y (two finite numbers)", n);
      } else if (!corr.command(kincal::Vec2(x, y), t1, t2)) {
        len = std::snprintf(buf, sizeof buf, "error: stdin:%ld: (%g, %g) is out of reach", n, x, y);
      } else {
        len = std::snprintf(buf, sizeof buf, "%.10f,%.10f", t1, t2);
      }
      len = std::min(std::max(len, 0), static_cast<int>(sizeof buf) - 2);  // snprintf may truncate
      buf[len] = '\n';
      std::fwrite(buf, 1, static_cast<size_t>(len) + 1, stdout);
      std::fflush(stdout);
    }
    return 0;
  }
  if (program.empty() || out.empty()) throw kincal::InputError("--program and --out are needed (or --stream)");
  const kincal::CsvTable t = kincal::read_csv(program);
  const int cx = t.require("x"), cy = t.require("y");
  std::string text = "theta1_deg,theta2_deg\n";
  for (size_t r = 0; r < t.cells.size(); ++r) {
    double t1, t2;
    const double x = t.number(r, cx), y = t.number(r, cy);
    if (!corr.command(kincal::Vec2(x, y), t1, t2))
      throw kincal::InputError(t.where(r) + ": (" + std::to_string(x) + ", " + std::to_string(y) +
                               ") is out of the hidden robot's reach");
    std::snprintf(buf, sizeof buf, "%.17g,%.17g\n", t1, t2);
    text += buf;
  }
  if (t.cells.empty()) throw kincal::InputError(program + ": no targets");
  kincal::write_file_atomic(out, text);
  return 0;
}

struct Args {  // the command line
  std::string model, out, frame = "base";
  std::vector<std::string> programs, declarations, tracks;
  bool allow_branch_change = false;
  int jobs = 0;
  bool stream = false, fd = false, nominal = false, keep_branch = false, paper_start = false;
  double eps = 1e-15, delta = 1e-8;
  std::optional<double> temperature;
  std::string initial_direction, residual = "rotation_vector";
  int max_iter = 20;
  std::string fivebar, matrix;
  std::string format, targets = "joints", prog_name;
  std::optional<double> speed, zone;
  int max_per_file = 0;
  std::vector<double> program_tool, program_base;
  std::vector<std::string> uframes, utools;
  bool skip_unresolved = false;
  std::optional<double> tolerance;
  std::string joint_convention;
};

// the program, the model and what is written
void add_program_options(CLI::App& app, Args& a) {
  app.add_option("--model", a.model, "built-in robot name or model JSON");
  app.add_option("--fivebar", a.fivebar, "five-bar hidden robot: FIT.json of kincal hidden-robot fit");
  app.add_option("--matrix", a.matrix, "five-bar: MATRIX.json of kincal hidden-robot matrix");
  app.add_option("--program", a.programs,
                 "pose program (CSV x,y,z,a,b,c or G-code X Y Z A B C) or a controller's program (.src with its .dat, "
                 ".mod, .ls, .script); several files or a folder: a controller backup (--out: a folder, the same tree)");
  app.add_option("--declarations", a.declarations, "more files whose declarations the programs may name (KRL .dat, "
                                                 "$config.dat; RAPID modules)");
  app.add_flag("--allow-branch-change", a.allow_branch_change, "a taught target the calibrated robot cannot reach on "
                                                             "its taught solution is written on another branch (a warning)");
  app.add_option("--track", a.tracks, "a linear track that carries the robot: AXIS=X,Y,Z (E1..E6; mm per unit of the "
                                    "axis, in the program's base frame)");
  app.add_option("--jobs", a.jobs, "a backup's programs filtered at once (default: every core)");
  app.add_option("--out", a.out,
                 "the program written: .csv (q1..q6), G-code (A1=..), KRL .src (+ .dat), RAPID .mod, FANUC .ls, "
                 "URScript .script");
  app.add_option("--format", a.format, "krl, rapid, fanuc-ls, urscript, gcode or csv (default: by --out's extension)")
      ->check(CLI::IsMember({"krl", "rapid", "fanuc-ls", "urscript", "gcode", "csv"}));
  app.add_option("--targets", a.targets, "joints (default) or filtered (Cartesian, with the controller's branch data)")
      ->check(CLI::IsMember({"joints", "filtered"}));
  app.add_option("--name", a.prog_name, "program name (default: the output file's name)");
  app.add_option("--speed", a.speed, "joint motions: percent of the axes' maximum speed (default 20); linear motions: "
                                   "mm/s (default 250)");
  app.add_option("--zone", a.zone, "approximation / blending in mm (FANUC: CNT 0..100); default 0: exact stop");
  app.add_option("--program-tool", a.program_tool, "a KRL/RAPID program's TCP in the model's tool frame: X,Y,Z,A,B,C")
      ->delimiter(',')->expected(6);
  app.add_option("--program-base", a.program_base, "a KRL/RAPID program's base in the robot's base frame: X,Y,Z,A,B,C")
      ->delimiter(',')->expected(6);
  app.add_option("--uframe", a.uframes, "a FANUC LS program's user frame N in the robot's base frame: N=X,Y,Z,A,B,C "
                                      "(repeat for each UF the positions use)");
  app.add_option("--utool", a.utools, "a FANUC LS program's tool N in the model's tool frame: N=X,Y,Z,A,B,C (repeat "
                                    "for each UT the positions use)");
  app.add_flag("--skip-unresolved", a.skip_unresolved, "pass targets computed at run time through with a warning");
  app.add_option("--tolerance", a.tolerance, "insert targets where the path between two targets leaves the desired "
                                           "segment by more than this (mm)");
  app.add_option("--max-targets-per-file", a.max_per_file, "split longer KRL / LS programs into parts (default: 2000)");
  app.add_option("--joint-convention", a.joint_convention,
                 "how the controller numbers a built-in robot's joints (a model JSON carries its own): fanuc, J3 is "
                 "the forearm's angle to the horizontal")
      ->check(CLI::IsMember({"fanuc"}));
}

// the frame, the stream and Newton's options
void add_newton_options(CLI::App& app, Args& a) {
  app.add_option("--frame", a.frame, "frame of the program poses")->check(CLI::IsMember({"base", "instrument"}));
  app.add_flag("--stream", a.stream, "read pose lines on stdin, write joint lines on stdout, flushed");
  app.add_flag("--finite-difference", a.fd, "the paper's finite-difference Jacobian (eq. 7)");
  app.add_flag("--nominal", a.nominal, "nominal IK only (the uncompensated program)");
  app.add_flag("--paper-start", a.paper_start, "start Newton from the nominal IK (no correction), as the paper");
  app.add_option("--epsilon", a.eps, "stop when |F|^2 < epsilon (eq. 9)");
  app.add_option("--delta", a.delta, "finite-difference step, degrees (eq. 7)");
  app.add_option("--max-iterations", a.max_iter, "Newton iteration limit");
  app.add_option("--residual", a.residual, "orientation residual of Newton: rotation_vector (default) or abc (eq. 6)")
      ->check(CLI::IsMember({"rotation_vector", "abc"}));
  app.add_option("--temperature", a.temperature, "thermal expansion: the temperature (deg C) unless a temperature_c column");
  app.add_option("--initial-direction", a.initial_direction,
                 "backlash: each joint's direction into the first pose, +1 or -1 (one for all, or q1..q6 comma "
                 "separated; default: the direction of the first motion; needed with --stream)");
  app.add_flag("--keep-branch", a.keep_branch, "a branch change inside the program is an error, not a warning");
}

kincal::ProgramOptions program_options(const Args& a) {
  kincal::ProgramOptions opt;
  opt.instrument_frame = a.frame == "instrument";
  opt.compensate = !a.nominal;
  opt.comp.finite_difference = a.fd;
  opt.corrected_start = !a.paper_start;
  opt.comp.epsilon = a.eps;
  opt.comp.delta = a.delta;
  opt.comp.max_iterations = a.max_iter;
  if (a.residual == "abc") opt.comp.residual = kincal::Residual::Abc;
  if (a.temperature) opt.temperature_c = *a.temperature;
  opt.keep_branch = a.keep_branch;
  opt.initial_direction = kincal::parse_initial_direction(a.initial_direction);
  opt.keep_poses = false;  // the summary needs the count and extremes only: any length in bounded memory
  return opt;
}

kincal::WriterOptions writer_options(const Args& a) {
  kincal::WriterOptions w;
  w.format = a.format.empty() ? kincal::controller_format_of_path(a.out) : kincal::controller_format_named(a.format);
  w.targets = kincal::target_kind_named(a.targets);
  w.name = a.prog_name;
  if (a.speed) w.speed = *a.speed;
  if (a.zone) w.zone = *a.zone;
  w.max_targets_per_file = a.max_per_file;
  return w;
}

kincal::NativeOptions native_options(const Args& a) {
  kincal::NativeOptions n;
  if (a.program_tool.size() == 6)
    n.program_tool = {kincal::Vec3(a.program_tool[0], a.program_tool[1], a.program_tool[2]),
                      kincal::Vec3(a.program_tool[3], a.program_tool[4], a.program_tool[5])};
  if (a.program_base.size() == 6)
    n.program_base = {kincal::Vec3(a.program_base[0], a.program_base[1], a.program_base[2]),
                      kincal::Vec3(a.program_base[3], a.program_base[4], a.program_base[5])};
  for (const auto& u : a.uframes) kincal::add_numbered_frame(n.user_frames, u, "--uframe");
  for (const auto& u : a.utools) kincal::add_numbered_frame(n.user_tools, u, "--utool");
  n.skip_unresolved = a.skip_unresolved;
  n.allow_branch_change = a.allow_branch_change;
  for (const auto& t : a.tracks) kincal::add_track_axis(n.track, t);
  if (a.tolerance) n.tolerance_mm = *a.tolerance;
  return n;
}

// --stream: pose lines on stdin, joint lines on stdout, flushed line by line
int run_stream(const kincal::Robot& robot, const kincal::ProgramOptions& opt) {
  kincal::StreamCompensator sc(robot, opt);
  std::string line;
  line.reserve(4096);
  char outbuf[8192];
  while (std::getline(std::cin, line)) {
    const size_t n = sc.process(line.data(), line.size(), outbuf, sizeof outbuf - 1);
    outbuf[n] = '\n';
    std::fwrite(outbuf, 1, n + 1, stdout);
    std::fflush(stdout);
    for (size_t a = 0, b = 0; a < sc.warning().size(); a = b + 1) {  // one warning per line
      b = std::min(sc.warning().find('\n', a), sc.warning().size());
      std::fprintf(stderr, "kincal-compensate: warning: %.*s\n", static_cast<int>(b - a), sc.warning().data() + a);
    }
  }
  return 0;
}

// a controller backup: several programs or a folder, written into the folder --out
int run_backup(const kincal::Robot& robot, const Args& a, const kincal::ProgramOptions& opt,
               const kincal::WriterOptions& w, const kincal::NativeOptions& n) {
  if (!a.format.empty()) throw kincal::InputError("--format: a backup's programs are written in their own languages");
  kincal::BackupOptions b;
  b.declarations = a.declarations;
  b.threads = a.jobs;
  const auto br = kincal::compensate_backup(robot, a.programs, a.out, opt, w, n, b);
  size_t filtered = 0;
  for (const auto& p : br.programs) {
    for (const auto& m : p.result.result.warnings) std::fprintf(stderr, "kincal-compensate: warning: %s\n", m.c_str());
    if (!p.error.empty() || p.result.files.empty()) continue;
    ++filtered;
    std::string files;
    for (const auto& f : p.result.files) files += (files.empty() ? "" : ", ") + f;
    std::fprintf(stderr, "%s: %zu target(s) compensated; %s\n", files.c_str(), p.result.result.poses,
                 p.result.targets_note.c_str());
  }
  std::fprintf(stderr, "%s: %zu program(s) filtered, %zu file(s) copied unchanged, %d program(s) failed\n",
               a.out.c_str(), filtered, br.copied.size(), br.failed);
  for (const auto& p : br.programs) {
    if (p.error.empty()) continue;
    std::string inputs;  // every program of a group that fails together (they share a written file)
    for (const auto& in : p.inputs) inputs += (inputs.empty() ? "" : ", ") + in;
    std::fprintf(stderr, "kincal-compensate: error: not written: %s:\n  %s\n", inputs.c_str(), p.error.c_str());
  }
  return br.failed ? 1 : 0;
}

// one program file
int run_program(const kincal::Robot& robot, const Args& a, const std::string& program,
                const kincal::ProgramOptions& opt, const kincal::WriterOptions& w, kincal::NativeOptions n) {
  if (!a.declarations.empty())
    n.context = std::make_shared<const kincal::Declarations>(
        kincal::read_declarations(a.declarations, kincal::controller_format_of_path(program)));
  const auto cr = kincal::compensate_to_controller(robot, program, a.out, opt, w, n);
  const auto& res = cr.result;
  for (const auto& w : res.warnings) std::fprintf(stderr, "kincal-compensate: warning: %s\n", w.c_str());
  std::fprintf(stderr, "%s: %zu poses, at most %d iterations, largest residual %.3g\n", a.out.c_str(),
               res.poses, res.max_iterations, res.max_residual);
  if (!cr.targets_note.empty()) std::fprintf(stderr, "%s: %s\n", a.out.c_str(), cr.targets_note.c_str());
  if (a.tolerance)
    std::fprintf(stderr, "%s: path between targets: largest deviation from the desired segments %.4f mm before, "
                 "%.4f mm after %d inserted target(s)\n", a.out.c_str(), cr.path_before_mm, cr.path_after_mm,
                 cr.inserted);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"kincal-compensate: Newton compensation of pose programs into joint programs"};
  Args a;
  add_program_options(app, a);
  add_newton_options(app, a);
  CLI11_PARSE(app, argc, argv);
  kincal::remove_unfinished_files_on_signals();  // a long program interrupted: no temporary file left

  try {
    if (a.programs.size() > 1 && !a.fivebar.empty()) throw kincal::InputError("--fivebar: one --program");
    const std::string program = a.programs.empty() ? std::string() : a.programs[0];
    if (!a.fivebar.empty()) return run_fivebar(a.fivebar, a.matrix, program, a.out, a.stream);
    if (a.model.empty()) throw kincal::InputError("--model (a serial robot) or --fivebar (a hidden robot) is needed");
    const kincal::ProgramOptions opt = program_options(a);
    const kincal::Robot robot = kincal::with_joint_convention(kincal::load_robot(a.model), a.model, a.joint_convention);
    if (opt.instrument_frame && !robot.identified())
      throw kincal::InputError(a.model + ": --frame instrument needs an identified model (kincal identify)");
    const std::string tcp = kincal::tcp_warning(robot, a.model);  // a model whose TCP was not measured
    if (!tcp.empty()) std::fprintf(stderr, "kincal-compensate: warning: %s\n", tcp.c_str());
    if (a.stream) return run_stream(robot, opt);
    if (program.empty() || a.out.empty()) throw kincal::InputError("--program and --out are needed (or --stream)");
    const kincal::WriterOptions w = writer_options(a);
    const kincal::NativeOptions n = native_options(a);
    if (a.programs.size() > 1 || kincal::is_folder(program))  // a controller backup
      return run_backup(robot, a, opt, w, n);
    return run_program(robot, a, program, opt, w, n);
  } catch (const kincal::InputError& e) {
    std::fprintf(stderr, "kincal-compensate: error: %s\n", e.what());
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "kincal-compensate: internal error: %s\n", e.what());
    return 2;
  }
}
