// Shared helpers of the C++ tests of program files and the stream: a calibrated kr500, files in the
// test's temporary directory.
#pragma once

#include "kincal/compensation/program.hpp"
#include "kincal/model/robots.hpp"

#include "test_util.hpp"

#include <gtest/gtest.h>

#include <fstream>
#include <memory>
#include <string>

namespace kincal::test {

/// The kr500 with 1 mm / 0.05 deg errors and compliance of seed 9 (KINCAL_TEST_SEED changes it: test_seed).
inline Robot kr500_calibrated() {
  auto nom = std::make_shared<Model>(kr500_spec());
  return Robot{nom, std::make_shared<Model>(perturbed_spec(kr500_spec(), test_seed(9), 1.0, 0.05, 0.003))};
}

/// Writes text to name in the test's temporary directory; returns the path.
inline std::string tmp(const std::string& name, const std::string& text) {
  const std::string p = ::testing::TempDir() + name;
  std::ofstream(p) << text;
  return p;
}

}  // namespace kincal::test
