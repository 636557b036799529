// kincal-bench: the C++ benchmarks as one JSON object (kincal bench adds the Python baselines).
#include "bench.hpp"

#include <cstdio>
#include <cstdlib>

int main(int argc, char** argv) {
  const int n = argc > 1 ? std::atoi(argv[1]) : 2000;
  const auto r = kincal::run_benchmarks(n > 0 ? n : 2000, 1, 0);
  std::printf("{");
  for (size_t i = 0; i < r.size(); ++i) std::printf("%s\"%s\": %.6g", i ? ", " : "", r[i].first.c_str(), r[i].second);
  std::printf("}\n");
  return 0;
}
