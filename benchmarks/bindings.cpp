// kincal._benchmarks._bench: the C++ benchmarks for `kincal bench` (a module of their own, outside
// kincal._core: the benchmarks are not part of the library).
#include <pybind11/pybind11.h>

#include "bench.hpp"

namespace py = pybind11;

PYBIND11_MODULE(_bench, m) {
  m.doc() = "kincal's C++ benchmarks (private: use kincal bench)";
  m.def(
      "run_benchmarks",
      [](int n, unsigned seed, int threads) {
        std::vector<std::pair<std::string, double>> r;
        {
          py::gil_scoped_release release;
          r = kincal::run_benchmarks(n, seed, threads);
        }
        py::dict d;
        for (auto& kv : r) d[py::str(kv.first)] = kv.second;
        return d;
      },
      py::arg("n") = 2000, py::arg("seed") = 1, py::arg("threads") = 0,
      "Every C++ benchmark on n seeded random kr500 poses: name -> value (ns per call, ratios)");
}
