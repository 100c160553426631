#pragma once
// What the command line says about itself, made from the one CLI11 app so it cannot drift from it:
// --help wrapped to the terminal, a bash completion script and a man page (`tetrasand completion bash`,
// `tetrasand manpage`; `cmake --install` writes both).
#include <CLI/CLI.hpp>

#include <cstddef>
#include <string>

namespace ts::app {

// Wraps option and subcommand descriptions in --help to the terminal (COLUMNS, else the terminal's
// width, else 100 columns), continuation lines under the description column.
class WrappingFormatter : public CLI::Formatter {
 public:
  WrappingFormatter();
  std::string make_option_desc(const CLI::Option* option) const override;
  std::string make_subcommand(const CLI::App* sub) const override;
  std::string make_description(const CLI::App* app) const override;

 private:
  std::size_t text_width() const;  // columns left for a description
};

// `text` with its lines broken at spaces to at most `width` characters (a longer word stands alone).
std::string wrap_text(const std::string& text, std::size_t width);

// The bash completion script of `app` (subcommands, their options, the values of options that take
// one of a fixed set, files elsewhere), for /usr/share/bash-completion/completions/tetrasand.
std::string bash_completion(const CLI::App& app);

// A man page (roff, section 1) of `app`: every subcommand with its options and their descriptions.
std::string man_page(const CLI::App& app);

}  // namespace ts::app
