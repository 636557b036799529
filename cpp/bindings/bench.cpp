// _core binding of the benchmarks (kincal bench): our code and its baselines in one run.
#include "common.hpp"

#include "bench.hpp"

void define_bench(py::module_& m) {
  m.def(
      "run_benchmarks",
      [](int n, unsigned seed, int threads) {
        py::gil_scoped_release release;
        auto r = kincal::run_benchmarks(n, seed, threads);
        py::gil_scoped_acquire acquire;
        py::dict d;
        for (auto& kv : r) d[py::str(kv.first)] = kv.second;
        return d;
      },
      py::arg("n") = 2000, py::arg("seed") = 1, py::arg("threads") = 0);
}
