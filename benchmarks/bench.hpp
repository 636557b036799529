// kincal: benchmarks of the hot paths against KDL's own solvers, timed in the same run.
#pragma once

#include <string>
#include <utility>
#include <vector>

namespace kincal {

/// Runs every C++ benchmark on `n` random poses of the built-in kr500 (seeded) and returns
/// name/value pairs: times in ns per call (median over batches), ratios, throughput.
std::vector<std::pair<std::string, double>> run_benchmarks(int n = 2000, unsigned seed = 1, int threads = 0);

}  // namespace kincal
