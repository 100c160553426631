#pragma once
// For tests of user-data errors: the message a ts::InputError carries.
#include <gtest/gtest.h>

#include <string>

#include "core/error.h"

namespace ts::test {

// The message of the ts::InputError `f` throws ("" and a test failure when it throws none).
template <typename F>
std::string input_error(F&& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  ADD_FAILURE() << "no InputError";
  return "";
}

}  // namespace ts::test
