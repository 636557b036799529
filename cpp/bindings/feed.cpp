// _core bindings of the time-optimal feed along a path.
#include "common.hpp"

#include "kincal/feed/feed.hpp"

using namespace kincal;

void define_feed(py::module_& m) {
  m.def(
      "time_optimal_feed",
      [](const Eigen::VectorXd& s, const RowMatrix& d1, const RowMatrix& d2, const Eigen::VectorXd& v, const Eigen::VectorXd& a,
         const Eigen::VectorXd& cap) {
        double t = 0;
        Eigen::VectorXd sd = time_optimal_feed(s, d1, d2, v, a, cap, t);
        return py::make_tuple(sd, t);
      },
      py::arg("s"), py::arg("d1"), py::arg("d2"), py::arg("v"), py::arg("a"), py::arg("cap"),
      "time-optimal s-dot along the path and the traversal time (see kincal/feed.hpp)");
}
