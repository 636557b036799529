// _core bindings of program compensation: compensate_poses, compensate_program, stream_lines.
#include "common.hpp"

#include "kincal/compensation/backup.hpp"
#include "kincal/compensation/controller_program.hpp"
#include "kincal/compensation/program.hpp"
#include "kincal/compensation/stream.hpp"

#include <cmath>
#include <memory>
#include <optional>

using namespace kincal;

namespace {

ProgramOptions options(bool compensate, bool instrument, bool fd, double delta, double epsilon, int max_iter,
                       bool corrected_start, const std::string& residual, std::optional<double> temperature_c,
                       const std::vector<double>& initial_direction, bool keep_branch) {
  ProgramOptions o;
  o.compensate = compensate;
  o.instrument_frame = instrument;
  o.corrected_start = corrected_start;
  o.comp.finite_difference = fd;
  o.comp.delta = delta;
  o.comp.epsilon = epsilon;
  o.comp.max_iterations = max_iter;
  if (residual == "abc")
    o.comp.residual = Residual::Abc;
  else if (residual != "rotation_vector")
    throw InputError("residual must be 'rotation_vector' or 'abc', not '" + residual + "'");
  if (temperature_c) o.temperature_c = *temperature_c;
  o.initial_direction = initial_direction;
  o.keep_branch = keep_branch;
  return o;
}

py::dict result_dict(const ProgramResult& r) {
  RowMatrix q(static_cast<Eigen::Index>(r.q_deg.size()), 6);
  for (size_t i = 0; i < r.q_deg.size(); ++i) q.row(static_cast<Eigen::Index>(i)) = r.q_deg[i].transpose();
  py::dict d;
  d["q_deg"] = q;
  d["iterations"] = r.iterations;
  d["residual"] = r.residual;
  RowMatrix dir(static_cast<Eigen::Index>(r.dir.size()), 6);
  for (size_t i = 0; i < r.dir.size(); ++i) dir.row(static_cast<Eigen::Index>(i)) = r.dir[i].transpose();
  d["dir"] = dir;
  d["warnings"] = r.warnings;
  // the count and extremes, also when the per-pose arrays are not kept (keep_poses=False)
  d["poses"] = r.poses;
  d["iterations_min"] = r.min_iterations;
  d["iterations_max"] = r.max_iterations;
  d["iterations_total"] = r.total_iterations;
  d["residual_max"] = r.max_residual;
  return d;
}

NativeOptions native_options(const std::vector<double>& program_tool, const std::vector<double>& program_base,
                             bool skip_unresolved, std::optional<double> tolerance, const std::vector<std::string>& uframes,
                             const std::vector<std::string>& utools, bool allow_branch_change,
                             const std::vector<std::string>& tracks) {
  NativeOptions n;
  for (const auto& u : uframes) add_numbered_frame(n.user_frames, u, "--uframe");
  for (const auto& u : utools) add_numbered_frame(n.user_tools, u, "--utool");
  for (const auto& t : tracks) add_track_axis(n.track, t);
  if (tolerance) n.tolerance_mm = *tolerance;
  for (const auto* v : {&program_tool, &program_base})
    if (!v->empty() && v->size() != 6) throw InputError("--program-tool / --program-base: X,Y,Z,A,B,C (6 numbers)");
  if (!program_tool.empty())
    n.program_tool = Pose6{Vec3(program_tool[0], program_tool[1], program_tool[2]),
                           Vec3(program_tool[3], program_tool[4], program_tool[5])};
  if (!program_base.empty())
    n.program_base = Pose6{Vec3(program_base[0], program_base[1], program_base[2]),
                           Vec3(program_base[3], program_base[4], program_base[5])};
  n.skip_unresolved = skip_unresolved;
  n.allow_branch_change = allow_branch_change;
  return n;
}

}  // namespace


namespace {

void define_program_options(py::module_& m) {
  const ProgramOptions def;
  py::class_<ProgramOptions>(m, "ProgramOptions",
                             "How a program is compensated (read-only; make a new one to change it)")
      .def(py::init([](bool comp, bool instr, bool fd, double delta, double eps, int it, bool cs,
                       const std::string& residual, std::optional<double> temp, const std::vector<double>& initial,
                       bool keep, bool keep_poses, size_t chunk_bytes) {
             ProgramOptions o = options(comp, instr, fd, delta, eps, it, cs, residual, temp, initial, keep);
             o.keep_poses = keep_poses;
             o.chunk_bytes = chunk_bytes;
             return o;
           }),
           py::arg("compensate") = def.compensate, py::arg("instrument") = def.instrument_frame,
           py::arg("finite_difference") = def.comp.finite_difference, py::arg("delta") = def.comp.delta,
           py::arg("epsilon") = def.comp.epsilon, py::arg("max_iterations") = def.comp.max_iterations,
           py::arg("corrected_start") = def.corrected_start, py::arg("residual") = "rotation_vector",
           py::arg("temperature_c") = py::none(), py::arg("initial_direction") = std::vector<double>{},
           py::arg("keep_branch") = def.keep_branch, py::arg("keep_poses") = def.keep_poses,
           py::arg("chunk_bytes") = def.chunk_bytes,
           "compensate=False: the nominal IK only; instrument: the poses in the instrument's frame; Newton's\n"
           "finite_difference (step delta, deg), epsilon (|F|^2), max_iterations, corrected_start (False: from the\n"
           "nominal IK, as the paper), residual ('rotation_vector' or 'abc'); temperature_c for thermal expansion;\n"
           "initial_direction: backlash's directions into the first pose (+1/-1, one or one per joint; empty: the\n"
           "first motion's); keep_branch: a branch change is an error; keep_poses=False: no per-pose arrays in the\n"
           "result (bounded memory); chunk_bytes: a program file read and written so much at a time")
      .def_property_readonly("compensate", [](const ProgramOptions& o) { return o.compensate; })
      .def_property_readonly("instrument", [](const ProgramOptions& o) { return o.instrument_frame; })
      .def_property_readonly("finite_difference", [](const ProgramOptions& o) { return o.comp.finite_difference; })
      .def_property_readonly("delta", [](const ProgramOptions& o) { return o.comp.delta; })
      .def_property_readonly("epsilon", [](const ProgramOptions& o) { return o.comp.epsilon; })
      .def_property_readonly("max_iterations", [](const ProgramOptions& o) { return o.comp.max_iterations; })
      .def_property_readonly("corrected_start", [](const ProgramOptions& o) { return o.corrected_start; })
      .def_property_readonly("residual", [](const ProgramOptions& o) {
        return std::string(o.comp.residual == Residual::Abc ? "abc" : "rotation_vector");
      })
      .def_property_readonly("temperature_c", [](const ProgramOptions& o) {
        return std::isfinite(o.temperature_c) ? std::optional<double>(o.temperature_c) : std::nullopt;
      })
      .def_property_readonly("initial_direction", [](const ProgramOptions& o) { return o.initial_direction; })
      .def_property_readonly("keep_branch", [](const ProgramOptions& o) { return o.keep_branch; })
      .def_property_readonly("keep_poses", [](const ProgramOptions& o) { return o.keep_poses; })
      .def_property_readonly("chunk_bytes", [](const ProgramOptions& o) { return o.chunk_bytes; });
}

void define_compensation_poses(py::module_& m) {
  m.def("parse_initial_direction", &parse_initial_direction, py::arg("text"),
        "--initial-direction's text as signs (+1 or -1, one for all joints or one each; empty: none)");
  m.def(
      "compensate_poses",
      [](const Robot& r, const RowMatrix& poses, const ProgramOptions& o, const std::optional<Eigen::VectorXd>& temps) {
        if (poses.cols() != 6) throw InputError("poses need 6 columns x,y,z,a,b,c");
        std::vector<double> tv;
        if (temps) {
          if (temps->size() != poses.rows()) throw InputError("temperatures_c needs one value per pose");
          tv.assign(temps->data(), temps->data() + temps->size());
        }
        std::vector<Pose6> p;
        std::vector<std::string> where;
        for (Eigen::Index i = 0; i < poses.rows(); ++i) {
          if (!poses.row(i).allFinite()) throw InputError("pose " + std::to_string(i) + ": NaN or infinite value");
          p.push_back(Pose6{poses.row(i).head<3>().transpose(), poses.row(i).tail<3>().transpose()});
          where.push_back("pose " + std::to_string(i));
        }
        ProgramResult res;
        {
          py::gil_scoped_release release;
          res = compensate_poses(r, p, where, o, tv);
        }
        return result_dict(res);
      },
      py::arg("robot"), py::arg("poses"), py::arg("options") = ProgramOptions{}, py::arg("temperatures_c") = py::none(),
      "IK + Newton compensation of every pose (N x 6), branch kept continuous");
  m.def(
      "compensate_program",
      [](const Robot& r, const std::string& in, const std::string& out, const ProgramOptions& o) {
        ProgramResult res;
        {
          py::gil_scoped_release release;
          res = compensate_program_file(r, in, out, o);
        }
        return result_dict(res);
      },
      py::arg("robot"), py::arg("program"), py::arg("out"), py::arg("options") = ProgramOptions{},
      "Compensates a pose program file (CSV or G-code) into a joint program file, atomically, a chunk of "
      "options.chunk_bytes at a time; options.keep_poses=False: the result without per-pose arrays (bounded memory)");
}

void define_compensation_programs(py::module_& m) {
  m.def(
      "compensate_to_controller",
      [](const Robot& r, const std::vector<std::string>& in, const std::string& out, const ProgramOptions& o,
         std::optional<std::string> format, const std::string& targets, const std::string& name,
         std::optional<double> speed, std::optional<double> zone, int max_per_file,
         const std::vector<double>& program_tool, const std::vector<double>& program_base, bool skip_unresolved,
         std::optional<double> tolerance, const std::vector<std::string>& uframes,
         const std::vector<std::string>& utools, const std::vector<std::string>& declarations,
         bool allow_branch_change, const std::vector<std::string>& tracks, int threads, py::object progress) {
        NativeOptions n = native_options(program_tool, program_base, skip_unresolved, tolerance, uframes, utools,
                                         allow_branch_change, tracks);
        if (in.empty()) throw InputError("--program: no input");
        WriterOptions w;
        w.format = format ? controller_format_named(*format) : controller_format_of_path(out);
        w.targets = target_kind_named(targets);
        w.name = name;
        if (speed) w.speed = *speed;
        if (zone) w.zone = *zone;
        w.max_targets_per_file = max_per_file;
        if (in.size() > 1 || is_folder(in[0])) {  // a controller backup: the same tree under out
          if (format) throw InputError("--format: a backup's programs are written in their own languages");
          BackupOptions b;
          b.declarations = declarations;
          b.threads = threads;
          if (!progress.is_none())
            b.progress = [progress](size_t done, size_t all) {
              py::gil_scoped_acquire gil;
              progress(done, all);
            };
          BackupResult res;
          {
            py::gil_scoped_release release;
            res = compensate_backup(r, in, out, o, w, n, b);
          }
          py::list programs;
          for (const BackupProgram& p : res.programs) {
            py::dict d = result_dict(p.result.result);
            d["inputs"] = p.inputs;
            d["files"] = p.result.files;
            d["error"] = p.error;
            d["targets_note"] = p.result.targets_note;
            programs.append(d);
          }
          py::dict d;
          d["programs"] = programs;
          d["copied"] = res.copied;
          d["failed"] = res.failed;
          return d;
        }
        if (!declarations.empty()) {
          const ControllerFormat f = controller_format_of_path(in[0]);
          n.context = std::make_shared<const Declarations>(read_declarations(declarations, f));
        }
        ControllerProgramResult res;
        {
          py::gil_scoped_release release;
          res = compensate_to_controller(r, in[0], out, o, w, n);
        }
        py::dict d = result_dict(res.result);
        d["files"] = res.files;
        d["path_before_mm"] = res.path_before_mm;
        d["path_after_mm"] = res.path_after_mm;
        d["inserted"] = res.inserted;
        d["targets_note"] = res.targets_note;
        return d;
      },
      py::arg("robot"), py::arg("program"), py::arg("out"), py::arg("options") = ProgramOptions{},
      py::arg("format") = py::none(),
      py::arg("targets") = "joints", py::arg("name") = "", py::arg("speed") = py::none(), py::arg("zone") = py::none(),
      py::arg("max_targets_per_file") = 0, py::arg("program_tool") = std::vector<double>{},
      py::arg("program_base") = std::vector<double>{}, py::arg("skip_unresolved") = false,
      py::arg("tolerance") = py::none(), py::arg("uframes") = std::vector<std::string>{},
      py::arg("utools") = std::vector<std::string>{}, py::arg("declarations") = std::vector<std::string>{},
      py::arg("allow_branch_change") = false, py::arg("tracks") = std::vector<std::string>{}, py::arg("threads") = 0,
      py::arg("progress") = py::none(),
      "Compensates a program into a program in a controller's language (format: krl, rapid, fanuc-ls, urscript, gcode, "
      "csv; None: by the output's extension), every file written or none; tolerance (mm): targets inserted where the "
      "path between two targets leaves the desired segment by more (path_before_mm, path_after_mm, inserted); uframes, "
      "utools: FANUC LS user frames and tools, 'N=X,Y,Z,A,B,C' each; tracks: 'E1=X,Y,Z' linear tracks. program: one "
      "file, or several files and folders (a controller backup: out is a folder with the same tree; the result lists "
      "each program with its error or files, the files copied, and how many failed; progress(done, all)). A CSV or "
      "G-code program written as CSV or G-code joints is read and written a chunk of options.chunk_bytes at a time; "
      "with options.keep_poses=False its result has no per-pose arrays (poses, iterations_min/max/total and "
      "residual_max say "
      "what the summary needs), so that a program of any length is compensated in bounded memory");
}

void define_compensation_stream(py::module_& m) {
  m.def(
      "stream_lines",
      [](const Robot& r, const std::vector<std::string>& lines, bool instr, std::optional<double> temp,
         const std::vector<double>& initial, const std::string& residual) {
        StreamCompensator sc(r, options(true, instr, false, 1e-8, 1e-15, 20, true, residual, temp, initial, false));
        std::vector<std::string> out;
        char buf[8192];
        for (const auto& l : lines) out.emplace_back(buf, sc.process(l.data(), l.size(), buf, sizeof buf));
        return out;
      },
      py::arg("robot"), py::arg("lines"), py::arg("instrument") = false, py::arg("temperature_c") = py::none(),
      py::arg("initial_direction") = std::vector<double>{}, py::arg("residual") = "rotation_vector",
      "The streaming corrector on a list of lines (as kincal-compensate --stream)");
}

}  // namespace

void define_compensation(py::module_& m) {
  define_program_options(m);
  define_compensation_poses(m);
  define_compensation_programs(m);
  define_compensation_stream(m);
}
