#pragma once
// Reading servo.csv (scene/servo.h) back in the tests.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include "core/atomic_file.h"
#include "scene/servo.h"

namespace ts::test {

// servo.csv's rows in `dir` (time, target, measured, position, velocity), of every servo.
inline std::vector<scene::ServoSample> servo_samples(const std::filesystem::path& dir) {
  std::istringstream in(read_file(dir / "servo.csv"));
  std::string line;
  std::getline(in, line);
  std::vector<scene::ServoSample> rows;
  while (std::getline(in, line)) {
    scene::ServoSample s;
    int servo = 0;
    EXPECT_EQ(std::sscanf(line.c_str(), "%d,%lf,%lf,%lf,%lf,%lf", &servo, &s.time, &s.target, &s.measured,
                          &s.position, &s.speed),
              6)
        << line;
    rows.push_back(s);
  }
  return rows;
}

}  // namespace ts::test
