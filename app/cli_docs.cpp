#include "app/cli_docs.h"

#include <fmt/format.h>
#include <sys/ioctl.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <sstream>
#include <vector>

namespace ts::app {
namespace {

// Columns of the terminal --help is printed on: COLUMNS, else the terminal's own, else 100; held
// to 60..200 so a tiny or absurd setting still gives readable help.
std::size_t terminal_columns() {
  std::size_t columns = 100;
  if (const char* env = std::getenv("COLUMNS"); env && std::atoi(env) > 0) {
    columns = static_cast<std::size_t>(std::atoi(env));
  } else if (winsize w{}; isatty(STDOUT_FILENO) && ioctl(STDOUT_FILENO, TIOCGWINSZ, &w) == 0 && w.ws_col > 0) {
    columns = w.ws_col;
  }
  return std::clamp<std::size_t>(columns, 60, 200);
}

// Every subcommand of `app`, depth first, with its path of names ("export lammps").
void walk(const CLI::App& app, const std::string& path,
          std::vector<std::pair<std::string, const CLI::App*>>& out) {
  out.emplace_back(path, &app);
  for (const CLI::App* sub : app.get_subcommands([](const CLI::App*) { return true; })) {
    walk(*sub, path.empty() ? sub->get_name() : path + " " + sub->get_name(), out);
  }
}

// The fixed set of values an option takes ("{auto,gpu,cpu}" in its type name, from CLI::IsMember).
std::vector<std::string> option_values(const CLI::Option& option) {
  const std::string type = option.get_type_name();
  const std::size_t open = type.find('{'), close = type.find('}', open);
  std::vector<std::string> values;
  if (open == std::string::npos || close == std::string::npos) return values;
  std::stringstream list(type.substr(open + 1, close - open - 1));
  for (std::string value; std::getline(list, value, ',');) values.push_back(value);
  return values;
}

// The option's spellings: "-o --output", or none for a positional.
std::vector<std::string> option_flags(const CLI::Option& option) {
  std::vector<std::string> flags;
  for (const std::string& s : option.get_snames()) flags.push_back("-" + s);
  for (const std::string& l : option.get_lnames()) flags.push_back("--" + l);
  return flags;
}

std::string join(const std::vector<std::string>& words) {
  std::string out;
  for (const std::string& w : words) out += (out.empty() ? "" : " ") + w;
  return out;
}

// roff text: backslashes and hyphens escaped, a line never starting with a control character.
std::string roff(const std::string& text) {
  std::string out;
  bool line_start = true;
  for (char c : text) {
    if (line_start && (c == '.' || c == '\'')) out += "\\&";
    if (c == '\\') out += "\\e";
    else if (c == '-') out += "\\-";
    else out += c;
    line_start = c == '\n';
  }
  return out;
}

std::string man_options(const CLI::App& app) {
  std::string out;
  for (const CLI::Option* option : app.get_options()) {
    std::vector<std::string> flags = option_flags(*option);
    std::string head = flags.empty() ? fmt::format("\\fI{}\\fR", roff(option->get_name()))
                                     : fmt::format("\\fB{}\\fR", roff(join(flags)));
    if (!flags.empty() && option->get_type_size() != 0) head += fmt::format(" \\fI{}\\fR", roff(option->get_type_name()));
    out += fmt::format(".TP\n{}\n{}\n", head, roff(option->get_description()));
  }
  return out;
}

}  // namespace

std::string wrap_text(const std::string& text, std::size_t width) {
  std::string out;
  std::stringstream paragraphs(text);
  bool first_paragraph = true;
  for (std::string paragraph; std::getline(paragraphs, paragraph, '\n');) {
    if (!first_paragraph) out += '\n';
    first_paragraph = false;
    std::stringstream words(paragraph);
    std::size_t line = 0;
    for (std::string word; words >> word;) {
      if (line > 0 && line + 1 + word.size() > width) {
        out += '\n';
        line = 0;
      } else if (line > 0) {
        out += ' ';
        ++line;
      }
      out += word;
      line += word.size();
    }
  }
  return out;
}

WrappingFormatter::WrappingFormatter() { column_width(30); }

std::size_t WrappingFormatter::text_width() const {
  const std::size_t columns = terminal_columns();
  return columns > get_column_width() + 30 ? columns - get_column_width() : 30;
}

std::string WrappingFormatter::make_option_desc(const CLI::Option* option) const {
  return wrap_text(CLI::Formatter::make_option_desc(option), text_width());
}

std::string WrappingFormatter::make_subcommand(const CLI::App* sub) const {
  std::stringstream out;
  CLI::detail::format_help(out, sub->get_display_name(), wrap_text(sub->get_description(), text_width()),
                           get_column_width());
  return out.str();
}

std::string WrappingFormatter::make_description(const CLI::App* app) const {
  return wrap_text(CLI::Formatter::make_description(app), terminal_columns()) + "\n";
}

std::string bash_completion(const CLI::App& app) {
  std::vector<std::pair<std::string, const CLI::App*>> commands;
  walk(app, "", commands);
  std::string descend, values, words, nested;
  for (const auto& [path, command] : commands) {
    if (!command->get_subcommands([](const CLI::App*) { return true; }).empty())
      nested += fmt::format("{}$path == \"{}\"", nested.empty() ? "" : " || ", path);
    std::vector<std::string> offered;
    for (const CLI::App* sub : command->get_subcommands([](const CLI::App*) { return true; })) {
      descend += fmt::format("      \"{}:{}\") path=\"{}\" ;;\n", path, sub->get_name(),
                             path.empty() ? sub->get_name() : path + " " + sub->get_name());
      offered.push_back(sub->get_name());
    }
    for (const CLI::Option* option : command->get_options()) {
      const std::vector<std::string> flags = option_flags(*option);
      offered.insert(offered.end(), flags.begin(), flags.end());
      const std::vector<std::string> set = option_values(*option);
      for (const std::string& flag : flags) {
        if (!set.empty()) values += fmt::format("    \"{}:{}\") COMPREPLY=($(compgen -W \"{}\" -- \"$cur\")); return ;;\n",
                                                path, flag, join(set));
      }
    }
    words += fmt::format("    \"{}\") words=\"{}\" ;;\n", path, join(offered));
  }
  return fmt::format(
      "# bash completion for tetrasand, made by `tetrasand completion bash` from its command line\n"
      "_tetrasand() {{\n"
      "  local cur=${{COMP_WORDS[COMP_CWORD]}} prev=${{COMP_WORDS[COMP_CWORD-1]}} path=\"\" w words=\"\"\n"
      "  for w in \"${{COMP_WORDS[@]:1:COMP_CWORD-1}}\"; do\n"
      "    case \"$path:$w\" in\n{}    esac\n"
      "  done\n"
      "  case \"$path:$prev\" in\n{}  esac\n"
      "  case \"$path\" in\n{}  esac\n"
      "  if [[ $cur == -* || {} ]]; then\n"
      "    COMPREPLY=($(compgen -W \"$words\" -- \"$cur\"))\n"
      "  else\n"
      "    COMPREPLY=($(compgen -f -- \"$cur\"))\n"
      "  fi\n"
      "}}\n"
      "complete -o filenames -F _tetrasand tetrasand\n",
      descend, values, words, nested);
}

std::string man_page(const CLI::App& app) {
  std::vector<std::pair<std::string, const CLI::App*>> commands;
  walk(app, "", commands);
  std::string page = fmt::format(
      ".TH TETRASAND 1 \"\" \"{}\" \"User Commands\"\n.SH NAME\ntetrasand \\- meshes to signed distance fields, "
      "particle rigid bodies and GPU sand simulation\n.SH SYNOPSIS\n.B tetrasand\n[\\fIglobal options\\fR] "
      "\\fIcommand\\fR [\\fIoptions\\fR]\n.SH DESCRIPTION\n{}\n.SH GLOBAL OPTIONS\n{}.SH COMMANDS\n",
      roff(app.get_name().empty() ? std::string("tetrasand") : app.get_name()), roff(app.get_description()),
      man_options(app));
  for (const auto& [path, command] : commands) {
    if (path.empty() || !command->get_subcommands([](const CLI::App*) { return true; }).empty()) continue;
    page += fmt::format(".SS \"tetrasand {}\"\n{}\n{}", roff(path), roff(command->get_description()),
                        man_options(*command));
  }
  page += ".SH SEE ALSO\nThe pages of docs/commands/ in the source tree, one per command.\n";
  return page;
}

}  // namespace ts::app
