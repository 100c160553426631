// Every numeric option of every command rejects NaN and infinity, and range errors print their
// bounds readably. The command line is parsed as the executable parses it (app/cli.h), nothing runs.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "app/cli.h"
#include "app/numeric_options.h"
#include "tests/test_support.h"

namespace ts {
namespace {

// An option whose value is a number (or several): CLI11 names its type FLOAT, INT or UINT.
bool is_numeric(const CLI::Option& option) {
  const std::string type = option.get_type_name();
  return type.find("FLOAT") != std::string::npos || type.find("INT") != std::string::npos;
}

// How the command line spells `option`: its long name, else its short one.
std::string flag(const CLI::Option& option) {
  return option.get_lnames().empty() ? "-" + option.get_snames().front() : "--" + option.get_lnames().front();
}

// `value` once per item the option takes (--eye takes three, comma-separated).
std::string values(const CLI::Option& option, const std::string& value) {
  std::string out = value;
  for (int i = 1; i < option.get_items_expected_min(); ++i) out += "," + value;
  return out;
}

// A command line of `command` that parses but for `option`: required positionals and options get an
// existing file, options `option` needs get "1".
std::vector<std::string> command_line(const std::string& command, const CLI::App& sub,
                                      const CLI::Option& option, const std::string& value) {
  const std::string file = test::asset("cube.obj").string();
  std::vector<std::string> args{"tetrasand", command};
  for (const CLI::Option* other : sub.get_options()) {
    if (other->get_positional() && other->get_required()) args.push_back(file);
    if (!other->get_positional() && other->get_required() && other != &option) {
      args.insert(args.end(), {flag(*other), file});
    }
  }
  for (const CLI::Option* needed : option.get_needs()) {
    args.insert(args.end(), {flag(*needed), values(*needed, "1")});
  }
  args.insert(args.end(), {flag(option), values(option, value)});
  return args;
}

// What parsing says: "" when it parses, else the error's message.
std::string parse_error(const std::vector<std::string>& args) {
  const auto cli = app::make_command_line();
  std::vector<const char*> argv;
  for (const auto& a : args) argv.push_back(a.c_str());
  try {
    cli->app.parse(static_cast<int>(argv.size()), argv.data());
  } catch (const CLI::ParseError& e) {
    return e.what();
  }
  return "";
}

std::string joined(const std::vector<std::string>& args) {
  std::string out;
  for (const auto& a : args) out += a + " ";
  return out;
}

TEST(CliOptions, EveryNumericOptionRejectsNanAndInfinity) {
  const auto cli = app::make_command_line();
  int checked = 0;
  for (const CLI::App* sub : cli->app.get_subcommands({})) {
    for (const CLI::Option* option : sub->get_options()) {
      if (option->get_positional() || !is_numeric(*option)) continue;
      const std::string command = sub->get_name();
      // A plain value is accepted (so the line is right but for the value under test): 1, or a tile
      // width of frames' contact sheet, which must be at least 16 pixels...
      const char* plain = option->check_lname("tile-width") ? "64" : "1";
      const auto fine = command_line(command, *sub, *option, plain);
      EXPECT_EQ(parse_error(fine), "") << joined(fine);
      // ... NaN and infinity are not.
      for (const char* bad : {"nan", "NaN", "inf", "-inf", "1e999"}) {
        const auto args = command_line(command, *sub, *option, bad);
        EXPECT_NE(parse_error(args), "") << joined(args);
      }
      ++checked;
    }
  }
  // The global --device, an index.
  EXPECT_EQ(parse_error({"tetrasand", "--device", "1", "devices"}), "");
  for (const char* bad : {"nan", "inf", "-1"}) {
    EXPECT_NE(parse_error({"tetrasand", "--device", bad, "devices"}), "") << bad;
  }
  // info 2, sdf 7, sample 13, preview 13 (and more), sim 1, export: the count only guards against
  // a loop that checks nothing.
  EXPECT_GE(checked, 30);
}

TEST(CliOptions, TheRadiusNanOfTheIssueIsRefusedWithAMessage) {
  const std::string mesh = test::asset("cube.obj").string();
  const std::string error = parse_error({"tetrasand", "sample", mesh, "--radius", "nan"});
  EXPECT_NE(error.find("--radius"), std::string::npos) << error;
  EXPECT_NE(error.find("'nan' is not a finite number"), std::string::npos) << error;
}

TEST(CliOptions, RangeErrorsPrintReadableBounds) {
  using app::detail::number_problem;
  constexpr double kMax = std::numeric_limits<double>::max();
  EXPECT_EQ(number_problem("-1", 0.0, kMax, true), "-1 must be > 0");
  EXPECT_EQ(number_problem("-2", 0.0, kMax, false), "-2 must be >= 0");
  EXPECT_EQ(number_problem("20000", 1, 10000, false), "20000 must be >= 1 and <= 10000");
  EXPECT_EQ(number_problem("nan", 0.0, kMax, true), "'nan' is not a finite number");
  EXPECT_EQ(number_problem("0.5", 0.0, kMax, true), "");
  EXPECT_EQ(number_problem("abc", 0.0, kMax, true), std::nullopt);  // CLI11's conversion says so
  const std::string mesh = test::asset("cube.obj").string();
  const std::string error = parse_error({"tetrasand", "sample", mesh, "--radius", "-1"});
  EXPECT_NE(error.find("-1 must be > 0"), std::string::npos) << error;
  EXPECT_EQ(error.find("1797693134862315708"), std::string::npos) << error;  // DBL_MAX in full
}

}  // namespace
}  // namespace ts
