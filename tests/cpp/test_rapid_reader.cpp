// ABB RAPID programs read in: the constructs of the controller's manual (issue 30).
#include "kincal/io/native.hpp"

#include "test_files.hpp"

#include <gtest/gtest.h>
