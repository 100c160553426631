// The command line (app/cli.h): every command's options, parsed as `tetrasand` parses them, nothing
// run. The input is the arguments after "tetrasand", one a line. A parse error is the expected
// outcome for most inputs; a crash, another exception or a sanitizer report is a finding, and so is a
// numeric option that takes a non-finite value.
//
// The app is built once and reused: building it (every command's options and validators) cost about
// 13 ms an input under ASan, nearly all of the target's time. CLI11's App::clear() resets what a
// parse leaves (each option's results, the parsed subcommands); the variables the options are bound
// to keep earlier values, but this target reads only the options' results, never those variables.
// That nothing else leaks from one input to the next is checked as the target runs: every
// kFreshEvery-th input is parsed again on a freshly built app, and a different outcome is a finding.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "app/cli.h"
#include "fuzz/fuzz_support.h"

namespace {

constexpr std::uint64_t kFreshEvery = 128;

std::vector<std::string> arguments(std::string_view text) {
  std::vector<std::string> args{"tetrasand"};
  std::size_t start = 0;
  while (start <= text.size() && args.size() < 64) {
    const std::size_t end = std::min(text.find('\n', start), text.size());
    args.emplace_back(text.substr(start, end - start));
    start = end + 1;
  }
  return args;
}

// Every numeric result of a parse that succeeded is finite: NaN and infinity never get through.
void check_parsed_numbers(const CLI::App& app) {
  for (const CLI::App* sub : app.get_subcommands({})) check_parsed_numbers(*sub);
  for (const CLI::Option* option : app.get_options()) {
    const std::string type = option->get_type_name();
    if (option->count() == 0 || type.find("FLOAT") == std::string::npos) continue;
    for (const std::string& value : option->results()) {
      for (std::size_t start = 0; start <= value.size();) {
        const std::size_t end = std::min(value.find(',', start), value.size());
        const std::string item = value.substr(start, end - start);
        start = end + 1;
        char* stop = nullptr;
        const double x = std::strtod(item.c_str(), &stop);
        if (stop != item.c_str() && !std::isfinite(x)) __builtin_trap();
      }
    }
  }
}

// What a parse left: the subcommands parsed and every option's results, in the app's order.
void describe(const CLI::App& app, std::string& out) {
  out += app.get_name() + (app.parsed() ? " parsed\n" : "\n");
  for (const CLI::Option* option : app.get_options()) {
    if (option->count() == 0) continue;
    out += option->get_name() + ":";
    for (const std::string& value : option->results()) out += " [" + value + "]";
    out += '\n';
  }
  for (const CLI::App* sub : app.get_subcommands({})) describe(*sub, out);
}

// Parses `argv` on `app` (cleared first); returns the outcome, checked for non-finite numbers.
std::string parse(CLI::App& app, const std::vector<const char*>& argv) {
  app.clear();
  try {
    app.parse(static_cast<int>(argv.size()), argv.data());
  } catch (const CLI::ParseError& e) {
    return "error " + std::to_string(e.get_exit_code()) + ": " + e.what();
  }
  check_parsed_numbers(app);
  std::string outcome;
  describe(app, outcome);
  return outcome;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::unique_ptr<ts::app::CommandLine> reused = ts::app::make_command_line();
  static std::uint64_t inputs = 0;
  const std::vector<std::string> args = arguments(ts::fuzz::as_text(data, size));
  std::vector<const char*> argv;
  for (const auto& a : args) argv.push_back(a.c_str());
  const std::string outcome = parse(reused->app, argv);
  if (++inputs % kFreshEvery == 0) {
    const auto fresh = ts::app::make_command_line();
    if (parse(fresh->app, argv) != outcome) __builtin_trap();  // state leaked from an earlier input
  }
  return 0;
}
