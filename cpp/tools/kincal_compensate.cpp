// kincal-compensate: offline and streaming compensation for controller PCs. Links no Python.
//
//   kincal-compensate --model M --program IN --out OUT [--frame base|instrument]
//   kincal-compensate --model M --stream [--frame base|instrument] < poses > joints
//
// M is a built-in robot name (kr500) or a model JSON written by kincal. Output equals
// `kincal compensate` (both run this library). Errors: one line "file:line: cause", exit 1, and no
// output file.
#include "kincal/io.hpp"

#include <CLI/CLI.hpp>

#include <cstdio>
#include <cstring>
#include <iostream>
#include <string>

int main(int argc, char** argv) {
  CLI::App app{"kincal-compensate: Newton compensation of pose programs into joint programs"};
  std::string model, program, out, frame = "base";
  bool stream = false, fd = false, nominal = false;
  double eps = 1e-15, delta = 1e-8;
  int max_iter = 20;
  app.add_option("--model", model, "built-in robot name or model JSON")->required();
  app.add_option("--program", program, "pose program: CSV (x,y,z,a,b,c) or G-code (X Y Z A B C)");
  app.add_option("--out", out, "joint program: .csv (q1..q6) or G-code (A1=..)");
  app.add_option("--frame", frame, "frame of the program poses")->check(CLI::IsMember({"base", "instrument"}));
  app.add_flag("--stream", stream, "read pose lines on stdin, write joint lines on stdout, flushed");
  app.add_flag("--finite-difference", fd, "the paper's finite-difference Jacobian (eq. 7)");
  app.add_flag("--nominal", nominal, "nominal IK only (the uncompensated program)");
  app.add_option("--epsilon", eps, "stop when |F|^2 < epsilon (eq. 9)");
  app.add_option("--delta", delta, "finite-difference step, degrees (eq. 7)");
  app.add_option("--max-iterations", max_iter, "Newton iteration limit");
  CLI11_PARSE(app, argc, argv);

  try {
    kincal::ProgramOptions opt;
    opt.instrument_frame = frame == "instrument";
    opt.compensate = !nominal;
    opt.comp.finite_difference = fd;
    opt.comp.epsilon = eps;
    opt.comp.delta = delta;
    opt.comp.max_iterations = max_iter;
    const kincal::Robot robot = kincal::load_robot(model);
    if (opt.instrument_frame && !robot.identified())
      throw kincal::InputError(model + ": --frame instrument needs an identified model (kincal identify)");
    if (stream) {
      kincal::StreamCompensator sc(robot, opt);
      std::string line;
      line.reserve(4096);
      char outbuf[8192];
      while (std::getline(std::cin, line)) {
        const size_t n = sc.process(line.data(), line.size(), outbuf, sizeof outbuf - 1);
        outbuf[n] = '\n';
        std::fwrite(outbuf, 1, n + 1, stdout);
        std::fflush(stdout);
      }
      return 0;
    }
    if (program.empty() || out.empty()) throw kincal::InputError("--program and --out are needed (or --stream)");
    const auto res = kincal::compensate_program_file(robot, program, out, opt);
    std::fprintf(stderr, "%s: %zu poses, at most %d iterations, largest residual %.3g\n", out.c_str(),
                 res.q_deg.size(), res.max_iterations, res.max_residual);
    return 0;
  } catch (const kincal::InputError& e) {
    std::fprintf(stderr, "kincal-compensate: error: %s\n", e.what());
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "kincal-compensate: internal error: %s\n", e.what());
    return 2;
  }
}
