// Bounded-time fuzzing of the readers under AddressSanitizer and UndefinedBehaviorSanitizer (this
// program and the reader sources are built with -fsanitize=address,undefined). Valid seed documents
// are mutated (hard tokens inserted, ranges deleted, bytes overwritten, slices duplicated) by a
// seeded generator; a reader may reject an input only with InputError. Any other exception, a
// sanitizer report (the process aborts) or an input slower than 1 s is a failure.
//   KINCAL_FUZZ_SECONDS (default 10), KINCAL_FUZZ_SEED (default 1)
#include "kincal/fivebar/fivebar.hpp"
#include "kincal/identify/identify.hpp"
#include "kincal/io/programs.hpp"
#include "kincal/io/model_json.hpp"

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

using namespace kincal;

int main() {
  const double seconds = std::getenv("KINCAL_FUZZ_SECONDS") ? std::atof(std::getenv("KINCAL_FUZZ_SECONDS")) : 10.0;
  const unsigned seed = std::getenv("KINCAL_FUZZ_SEED") ? std::atoi(std::getenv("KINCAL_FUZZ_SEED")) : 1;
  const std::vector<std::string> tokens = {
      "nan", "inf", "-inf", "1e309", "1e-400", "-0", ",", "\n", ";", "(", ")", "A1=", "A7=", "X", "Y", "Z", "A",
      "B", "C", "G1", "N", "\"", "{", "}", "[", "]", ":", "1.2.3", "q7", "\"version\": 2", "0x1p3", "  ", "\t",
      "\r", "\xc3\xa9", std::string(1, '\0'), "e", "-", std::string(40, '9'), "A1=1e999", "dir1", "target",
      "null", "\xff\xfe"};
  struct Seed {
    std::string text;
    int kind;  // 0 csv poses, 1 gcode poses, 2 csv joints, 3 gcode joints, 4 measurements, 5 model, 6 fit, 7 matrix
  };
  const std::vector<Seed> seeds = {
      {"x,y,z,a,b,c\n2000,0,1000,180,0,180\n2000,10,1000,180,0,180\n", 0},
      {"N10 G1 X2000 Y0 Z1000 A180 B0 C180 F100 ; c\nN20 Y10\n(comment) G1 X2010\nM30\n", 1},
      {"q1,q2,q3,q4,q5,q6\n0,-90,90,0,45,0\n1,-90,90,0,45,0\n", 2},
      {"G1 A1=0 A2=-90 A3=90 A4=0 A5=45 A6=0\nG1 A1=1\n", 3},
      {"pose,q1,q2,q3,q4,q5,q6,x,y,z,target,payload_kg,temperature_c,dir1,dir2,dir3,dir4,dir5,dir6\n"
       "0,0,-90,90,0,5,0,1,2,3,0,300,21.5,1,-1,1,1,-1,1\n",
       4},
      {robot_to_json(load_robot("kr500")), 5},
      {"{\"a\": 150, \"b\": 150, \"c\": 150, \"d\": 150}", 6},
      {"{\"format\": \"kincal-error-matrix\", \"version\": 1, \"x0_mm\": 0, \"y0_mm\": 0, \"dx_mm\": 5, \"dy_mm\": 5, "
       "\"nx\": 2, \"ny\": 2, \"error_x_mm\": [0, 0.1, 0, 0.1], \"error_y_mm\": [0, 0, 0.1, 0.1]}",
       7}};
  std::mt19937_64 rng(seed);
  auto pick = [&](size_t n) { return static_cast<size_t>(rng() % n); };
  const auto t0 = std::chrono::steady_clock::now();
  long runs = 0, rejected = 0;
  while (std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() < seconds) {
    const Seed& sd = seeds[pick(seeds.size())];
    std::string s = sd.text;
    const int edits = static_cast<int>(pick(11));
    for (int k = 0; k < edits; ++k) {
      const size_t pos = pick(s.size() + 1);
      switch (pick(4)) {
        case 0: s.insert(pos, tokens[pick(tokens.size())]); break;
        case 1: s.erase(pos, 1 + pick(16)); break;
        case 2:
          if (!s.empty()) s[std::min(pos, s.size() - 1)] = static_cast<char>(pick(256));
          break;
        default: s.insert(pos, s.substr(pos, 1 + pick(64))); break;
      }
    }
    const auto a = std::chrono::steady_clock::now();
    try {
      switch (sd.kind) {
        case 0: parse_pose_program(s, "fuzz.csv", ProgramFormat::Csv); break;
        case 1: parse_pose_program(s, "fuzz.gcode", ProgramFormat::Gcode); break;
        case 2: parse_joint_program(s, "fuzz.csv", ProgramFormat::Csv, 6); break;
        case 3: parse_joint_program(s, "fuzz.gcode", ProgramFormat::Gcode, 6); break;
        case 4: parse_measurements(s, "fuzz.csv", 6); break;
        case 5: robot_from_json(s, "fuzz.json"); break;
        case 6: fivebar_from_json(s, "fuzz.json"); break;
        default: ErrorMatrix::from_json(s, "fuzz.json"); break;
      }
    } catch (const InputError&) {
      ++rejected;
    } catch (const std::exception& e) {
      std::fprintf(stderr, "reader kind %d threw %s on input:\n%s\n", sd.kind, e.what(), s.c_str());
      return 1;
    }
    if (std::chrono::duration<double>(std::chrono::steady_clock::now() - a).count() > 1.0) {
      std::fprintf(stderr, "reader kind %d took over 1 s on input:\n%s\n", sd.kind, s.c_str());
      return 1;
    }
    ++runs;
  }
  std::printf("%ld inputs in %.0f s, %ld rejected with a message, no crash, no sanitizer report\n", runs, seconds,
              rejected);
  return 0;
}
