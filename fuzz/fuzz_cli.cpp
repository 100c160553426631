// The command line (app/cli.h): every command's options, parsed as `tetrasand` parses them, nothing
// run. The input is the arguments after "tetrasand", one a line. A parse error is the expected
// outcome for most inputs; a crash, another exception or a sanitizer report is a finding, and so is a
// numeric option that takes a non-finite value.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "app/cli.h"
#include "fuzz/fuzz_support.h"

namespace {

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

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::vector<std::string> args = arguments(ts::fuzz::as_text(data, size));
  std::vector<const char*> argv;
  for (const auto& a : args) argv.push_back(a.c_str());
  const auto cli = ts::app::make_command_line();
  try {
    cli->app.parse(static_cast<int>(argv.size()), argv.data());
  } catch (const CLI::ParseError&) {
    return 0;
  }
  check_parsed_numbers(cli->app);
  return 0;
}
