#include "harmonic.hpp"

#include "kincal/core/fastmath.hpp"

namespace kincal::harmonic {

void basis(const std::vector<int>& orders, double q, double* b, double* db) {
  // sin(kq), cos(kq) of each order from sin q, cos q by the angle-addition rule
  double s1, c1;
  fastmath::sincos(q, s1, c1);
  int have = 1;
  double sk = s1, ck = c1;
  for (size_t i = 0; i < orders.size(); ++i) {
    const int k = orders[i];
    if (k < have) have = 1, sk = s1, ck = c1;  // orders out of ascending sequence: start again
    while (have < k) {
      const double s = sk * c1 + ck * s1;
      ck = ck * c1 - sk * s1;
      sk = s;
      ++have;
    }
    b[2 * i] = sk;
    b[2 * i + 1] = ck;
    if (db) db[2 * i] = k * ck, db[2 * i + 1] = -k * sk;
  }
}

std::vector<std::string> names(const std::string& prefix, const std::vector<int>& orders) {
  std::vector<std::string> n;
  for (int k : orders) n.push_back(prefix + "sin" + std::to_string(k)), n.push_back(prefix + "cos" + std::to_string(k));
  return n;
}

std::vector<std::string> units(const Effect& e) { return std::vector<std::string>(2 * e.harmonics.size(), "rad"); }

}  // namespace kincal::harmonic
