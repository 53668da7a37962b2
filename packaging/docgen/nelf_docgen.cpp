// nelf_docgen OUTDIR: writes the man page nelf.1 and the bash, zsh and fish completions of nelf
// (nelf.bash, _nelf, nelf.fish) into OUTDIR. It walks the very CLI::App that nelf parses with
// (app/cli.cpp), so a new subcommand or option appears in the page and the completions without
// anyone writing it twice. Run at build time; not installed.
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cctype>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <regex>
#include <stdexcept>
#include <string>
#include <vector>

#include "app/commands.hpp"
#include "optics/profile.hpp"

namespace {

// What a page or a completion needs to know about one option, read from CLI11's definitions.
struct OptionDoc {
  std::vector<std::string> shorts;  // without the dash: "y"
  std::vector<std::string> longs;   // without the dashes: "overwrite"
  std::string type;                 // CLI11's type name, e.g. "INT", "NAME|FILE", "TEXT:{left,right}"
  std::string description;
  std::string default_value;
  std::vector<std::string> choices;  // from an IsMember check: "{left,right}"
  bool flag = false;                 // takes no value
  bool required = false;
  bool positional = false;
  std::string positional_name;

  // What completing the value should offer.
  enum class Value { none, choices, profile, number, file } value = Value::none;
};

struct CommandDoc {
  std::string name;
  std::string description;
  std::string footer;
  std::vector<OptionDoc> options;      // named options, in the order they were added
  std::vector<OptionDoc> positionals;  // in order
};

std::vector<std::string> parse_choices(const std::string& type) {
  static const std::regex set{R"(\{([^}]*)\})"};
  std::smatch m;
  std::vector<std::string> out;
  if (!std::regex_search(type, m, set)) return out;
  std::string items = m[1].str();
  size_t start = 0;
  while (start <= items.size()) {
    size_t comma = items.find(',', start);
    if (comma == std::string::npos) comma = items.size();
    if (comma > start) out.push_back(items.substr(start, comma - start));
    start = comma + 1;
  }
  return out;
}

OptionDoc describe_option(const CLI::Option& opt) {
  OptionDoc d;
  d.shorts = opt.get_snames();
  d.longs = opt.get_lnames();
  d.type = opt.get_type_name();
  d.description = opt.get_description();
  d.default_value = opt.get_default_str();
  d.choices = parse_choices(d.type);
  d.flag = opt.get_type_size_max() == 0;
  d.required = opt.get_required();
  d.positional = d.shorts.empty() && d.longs.empty();
  if (d.positional) d.positional_name = opt.get_name(true, false);
  if (d.flag)
    d.value = OptionDoc::Value::none;
  else if (!d.choices.empty())
    d.value = OptionDoc::Value::choices;
  else if (std::find(d.longs.begin(), d.longs.end(), "profile") != d.longs.end())
    d.value = OptionDoc::Value::profile;
  else if (d.type.starts_with("INT") || d.type.starts_with("UINT") || d.type.starts_with("FLOAT") ||
           d.type.starts_with("NUMBER"))
    d.value = OptionDoc::Value::number;
  else
    d.value = OptionDoc::Value::file;  // text values are most often paths (as bash's default)
  return d;
}

CommandDoc describe_command(const CLI::App& app) {
  CommandDoc c;
  c.name = app.get_name();
  c.description = app.get_description();
  c.footer = app.get_footer();
  for (const CLI::Option* opt : app.get_options()) {
    if (opt->get_group().empty()) continue;  // hidden
    OptionDoc d = describe_option(*opt);
    (d.positional ? c.positionals : c.options).push_back(std::move(d));
  }
  return c;
}

std::vector<std::string> dashed(const OptionDoc& o) {
  std::vector<std::string> names;
  for (const auto& s : o.shorts) names.push_back("-" + s);
  for (const auto& l : o.longs) names.push_back("--" + l);
  return names;
}

std::string upper(std::string s) {
  for (char& c : s) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return s;
}

// ---- roff ----------------------------------------------------------------------------------------

// Escapes text for a roff line: backslashes, minus signs (so that options copy as typed), a
// leading control character, and every non-ASCII character as groff's \[uXXXX] (the page is then
// plain ASCII, as man-db's checks prefer).
std::string roff(const std::string& text) {
  std::string out;
  for (size_t i = 0; i < text.size();) {
    const auto c = static_cast<unsigned char>(text[i]);
    if (c < 0x80) {
      if (c == '\\')
        out += "\\e";
      else if (c == '-')
        out += "\\-";
      else
        out += static_cast<char>(c);
      ++i;
      continue;
    }
    // Decode one UTF-8 sequence.
    int len = c >= 0xF0 ? 4 : c >= 0xE0 ? 3 : 2;
    unsigned cp = c & (len == 4 ? 0x07u : len == 3 ? 0x0Fu : 0x1Fu);
    for (int k = 1; k < len && i + static_cast<size_t>(k) < text.size(); ++k)
      cp = (cp << 6) | (static_cast<unsigned char>(text[i + static_cast<size_t>(k)]) & 0x3Fu);
    out += fmt::format("\\[u{:04X}]", cp);
    i += static_cast<size_t>(len);
  }
  return out;
}

// Text as filled roff lines: each input line a source line (roff joins them), blank lines new
// paragraphs.
std::string roff_text(const std::string& text) {
  std::string out;
  size_t start = 0;
  while (start < text.size()) {
    size_t nl = text.find('\n', start);
    if (nl == std::string::npos) nl = text.size();
    std::string line = text.substr(start, nl - start);
    if (line.empty())
      out += ".PP\n";
    else {
      std::string escaped = roff(line);
      if (escaped[0] == '.' || escaped[0] == '\'') escaped = "\\&" + escaped;
      out += escaped + "\n";
    }
    start = nl + 1;
  }
  return out;
}

std::string roff_option(const OptionDoc& o) {
  std::vector<std::string> names;
  for (const auto& n : dashed(o)) names.push_back("\\fB" + roff(n) + "\\fR");
  std::string head = fmt::format("{}", fmt::join(names, ", "));
  if (!o.flag)
    head += " \\fI" + roff(o.choices.empty() ? o.type : fmt::format("{}", fmt::join(o.choices, "|"))) + "\\fR";
  std::string body = o.description;
  if (!o.default_value.empty()) body += fmt::format(" (default: {})", o.default_value);
  if (o.required) body += " Required.";
  return ".TP\n" + head + "\n" + roff_text(body);
}

std::string synopsis(const CommandDoc& c) {
  std::string s = fmt::format("\\fBnelf {}\\fR [\\fIoptions\\fR]", roff(c.name));
  for (const auto& p : c.positionals)
    s += p.required ? fmt::format(" \\fI{}\\fR", roff(upper(p.positional_name)))
                    : fmt::format(" [\\fI{}\\fR]", roff(upper(p.positional_name)));
  return s + "\n";
}

std::string man_page(const CommandDoc& root, const std::vector<CommandDoc>& commands) {
  std::string m;
  m += ".\\\" Generated by nelf_docgen from nelf's command-line definitions; do not edit.\n";
  m += fmt::format(".TH NELF 1 \"\" \"nelf {}\" \"User Commands\"\n", NELF_VERSION);
  m += ".SH NAME\nnelf \\- " + roff("show stereo 3D movies and photos on near-eye light field displays") + "\n";
  m += ".SH SYNOPSIS\n";
  for (const auto& c : commands) m += synopsis(c) + ".br\n";
  m += "\\fBnelf\\fR [\\fB\\-\\-help\\fR | \\fB\\-\\-version\\fR]\n";
  m += ".SH DESCRIPTION\n";
  // The help's first line reads "nelf: watch ...": in the page, "nelf" is already the subject.
  if (root.description.starts_with("nelf: "))
    m += "\\fBnelf\\fR " + roff_text(root.description.substr(6));
  else
    m += roff_text(root.description);
  m += ".PP\n" +
       roff_text(
           "nelf turns side-by-side, top-bottom, frame-packed, JPS and MPO stereo content into the "
           "elemental images a lens-array display shows, for each eye, packed into the display's signal "
           "(an HDMI 1.4a frame-packed mode, for example). It plays them on the display, writes them "
           "to video or image files, and simulates what an eye would see.") +
       ".PP\nEach command has its own options, listed below; \\fBnelf\\fR \\fIcommand\\fR \\fB\\-\\-help\\fR "
       "prints them too.\n";
  m += ".SH OPTIONS\n";
  for (const auto& o : root.options) m += roff_option(o);
  m += ".SH COMMANDS\n";
  for (const auto& c : commands) {
    m += fmt::format(".SS {}\n", roff(c.name));
    m += synopsis(c);
    m += ".PP\n" + roff_text(c.description);
    for (const auto& p : c.positionals) {
      m += fmt::format(".TP\n\\fI{}\\fR\n", roff(upper(p.positional_name)));
      m += roff_text(p.description);
    }
    for (const auto& o : c.options) m += roff_option(o);
    if (!c.footer.empty()) m += ".PP\n" + roff_text(c.footer);
  }
  m += ".SH EXIT STATUS\n"
       ".TP\n0\nSuccess.\n"
       ".TP\n1\nThe job failed (an input that cannot be read, an output that cannot be written); nothing "
       "half-written is left behind.\n"
       ".TP\n2\nBad arguments or a bad profile.\n"
       ".TP\n130\nInterrupted.\n"
       ".PP\nEvery error is one line on standard error starting with \\(lqnelf:\\(rq.\n";
  m += ".SH FILES\n"
       ".TP\n/usr/share/doc/nelf/README.md\nThe user guide; the optics, profile schema and performance notes "
       "are in /usr/share/doc/nelf/docs/.\n";
  m += ".SH SEE ALSO\n.BR ffmpeg (1),\n.BR ffprobe (1),\n.BR mpv (1)\n";
  return m;
}

// ---- shell completions --------------------------------------------------------------------------

std::string profile_names() {
  std::vector<std::string> names;
  for (const auto& p : nelf::builtin_profiles()) names.push_back(p.name);
  return fmt::format("{}", fmt::join(names, " "));
}

std::string all_names(const std::vector<OptionDoc>& options) {
  std::vector<std::string> names;
  for (const auto& o : options)
    for (const auto& n : dashed(o)) names.push_back(n);
  return fmt::format("{}", fmt::join(names, " "));
}

std::string bash_completion(const CommandDoc& root, const std::vector<CommandDoc>& commands) {
  std::vector<std::string> names;
  for (const auto& c : commands) names.push_back(c.name);
  const std::string command_list = fmt::format("{}", fmt::join(names, " "));
  std::string s;
  s += "# bash completion for nelf. Generated by nelf_docgen from nelf's command-line definitions; do not edit.\n";
  s += "_nelf_files()\n{\n    compopt -o filenames 2>/dev/null\n    local IFS=$'\\n'\n"
       "    COMPREPLY=($(compgen -f -- \"$1\"))\n}\n\n";
  s += "_nelf()\n{\n";
  s += "    local cur=${COMP_WORDS[COMP_CWORD]} prev=\"\" cmd=\"\" i\n";
  s += "    ((COMP_CWORD > 0)) && prev=${COMP_WORDS[COMP_CWORD - 1]}\n";
  s += "    for ((i = 1; i < COMP_CWORD; i++)); do\n        case ${COMP_WORDS[i]} in\n";
  s += fmt::format("            {}) cmd=${{COMP_WORDS[i]}}; break ;;\n", fmt::join(names, "|"));
  s += "        esac\n    done\n";
  s += "    local opts=\"\" positionals=0\n    case $cmd in\n";
  s += fmt::format(
      "        \"\")\n            if [[ $cur == -* ]]; then\n"
      "                COMPREPLY=($(compgen -W \"{}\" -- \"$cur\"))\n"
      "            else\n                COMPREPLY=($(compgen -W \"{}\" -- \"$cur\"))\n"
      "            fi\n            return ;;\n",
      all_names(root.options), command_list);
  for (const auto& c : commands) {
    s += fmt::format("        {})\n", c.name);
    std::string value_cases;
    for (const auto& o : c.options) {
      if (o.flag) continue;
      const std::string pattern = fmt::format("{}", fmt::join(dashed(o), "|"));
      switch (o.value) {
        case OptionDoc::Value::choices:
          value_cases += fmt::format("                {}) COMPREPLY=($(compgen -W \"{}\" -- \"$cur\")); return ;;\n",
                                     pattern, fmt::join(o.choices, " "));
          break;
        case OptionDoc::Value::profile:
          value_cases += fmt::format(
              "                {}) _nelf_files \"$cur\"; COMPREPLY+=($(compgen -W \"{}\" -- \"$cur\")); return ;;\n",
              pattern, profile_names());
          break;
        case OptionDoc::Value::number:
          value_cases += fmt::format("                {}) COMPREPLY=(); return ;;\n", pattern);
          break;
        case OptionDoc::Value::file:
        case OptionDoc::Value::none:
          value_cases += fmt::format("                {}) _nelf_files \"$cur\"; return ;;\n", pattern);
          break;
      }
    }
    if (!value_cases.empty()) s += "            case $prev in\n" + value_cases + "            esac\n";
    s += fmt::format("            opts=\"{}\"; positionals={} ;;\n", all_names(c.options), c.positionals.size());
  }
  s += "    esac\n";
  s += "    if [[ $cur == -* ]]; then\n        COMPREPLY=($(compgen -W \"$opts\" -- \"$cur\"))\n"
       "    elif ((positionals > 0)); then\n        _nelf_files \"$cur\"\n    fi\n}\n";
  s += "complete -F _nelf nelf\n";
  return s;
}

// For zsh's _arguments: brackets, colons and quotes in a description would end its fields.
std::string zsh_description(const std::string& text) {
  std::string out;
  for (char c : text) {
    if (c == '[' || c == ']' || c == ':' || c == '\\') out += '\\';
    if (c == '\'')
      out += "'\\''";
    else if (c == '\n')
      out += ' ';
    else
      out += c;
  }
  return out;
}

std::string zsh_action(const OptionDoc& o) {
  switch (o.value) {
    case OptionDoc::Value::choices:
      return fmt::format("({})", fmt::join(o.choices, " "));
    case OptionDoc::Value::profile:
      return "_nelf_profiles";
    case OptionDoc::Value::number:
      return " ";
    case OptionDoc::Value::file:
    case OptionDoc::Value::none:
      return "_files";
  }
  return "_files";
}

std::string zsh_option_spec(const OptionDoc& o) {
  const std::vector<std::string> names = dashed(o);
  std::string exclusion = names.size() > 1 ? fmt::format("'({})'", fmt::join(names, " ")) : "";
  std::string name_part =
      names.size() > 1 ? fmt::format("{{{}}}", fmt::join(names, ",")) : fmt::format("'{}'", names.front());
  std::string spec = exclusion + name_part + "'[" + zsh_description(o.description) + "]";
  if (!o.flag) {
    std::string label = o.choices.empty() ? o.type : "value";
    for (char& c : label)
      if (c == ':') c = ' ';
    spec += ":" + zsh_description(label) + ":" + zsh_action(o);
  }
  return spec + "'";
}

std::string zsh_completion(const CommandDoc& root, const std::vector<CommandDoc>& commands) {
  std::string s;
  s += "#compdef nelf\n";
  s += "# zsh completion for nelf. Generated by nelf_docgen from nelf's command-line definitions; do not edit.\n\n";
  s += fmt::format(
      "_nelf_profiles() {{\n    _alternative 'profiles:built-in profile:({})' "
      "'files:profile file:_files -g \"*.toml\"'\n}}\n\n",
      profile_names());
  s += "_nelf() {\n    local curcontext=$curcontext state line\n    local -a commands\n    commands=(\n";
  for (const auto& c : commands) s += fmt::format("        '{}:{}'\n", c.name, zsh_description(c.description));
  s += "    )\n    _arguments -C \\\n";
  for (const auto& o : root.options) s += "        " + zsh_option_spec(o) + " \\\n";
  s += "        '1: :->command' \\\n        '*:: :->arguments'\n";
  s += "    case $state in\n        command) _describe -t commands 'nelf command' commands ;;\n";
  s += "        arguments)\n            case $line[1] in\n";
  for (const auto& c : commands) {
    s += fmt::format("                {})\n                    _arguments \\\n", c.name);
    for (const auto& o : c.options) s += "                        " + zsh_option_spec(o) + " \\\n";
    for (const auto& p : c.positionals)
      s += fmt::format("                        '{}:{}:_files' \\\n", p.required ? "" : ":",
                       zsh_description(p.description));
    s.erase(s.size() - 3);  // the last spec's line continuation
    s += "\n                    ;;\n";
  }
  s += "            esac ;;\n    esac\n}\n\n";
  s += "if [[ $zsh_eval_context[-1] == loadautofunc ]]; then\n    _nelf \"$@\"\nelse\n    compdef _nelf nelf\nfi\n";
  return s;
}

std::string fish_quote(const std::string& text) {
  std::string out = "'";
  for (char c : text) {
    if (c == '\'' || c == '\\') out += '\\';
    out += c == '\n' ? ' ' : c;
  }
  return out + "'";
}

std::string fish_completion(const CommandDoc& root, const std::vector<CommandDoc>& commands) {
  std::vector<std::string> names;
  for (const auto& c : commands) names.push_back(c.name);
  std::string s;
  s += "# fish completion for nelf. Generated by nelf_docgen from nelf's command-line definitions; do not edit.\n";
  s += "complete -c nelf -f\n";
  const auto option_line = [](const std::string& condition, const OptionDoc& o) {
    std::string line = "complete -c nelf -n " + fish_quote(condition);
    for (const auto& sh : o.shorts) line += " -s " + sh;
    for (const auto& l : o.longs) line += " -l " + l;
    switch (o.value) {
      case OptionDoc::Value::none:
        break;
      case OptionDoc::Value::choices:
        line += fmt::format(" -x -a {}", fish_quote(fmt::format("{}", fmt::join(o.choices, " "))));
        break;
      case OptionDoc::Value::profile:
        line += fmt::format(" -r -F -a {}", fish_quote(profile_names()));
        break;
      case OptionDoc::Value::number:
        line += " -x";
        break;
      case OptionDoc::Value::file:
        line += " -r -F";
        break;
    }
    return line + " -d " + fish_quote(o.description) + "\n";
  };
  for (const auto& o : root.options) s += option_line("__fish_use_subcommand", o);
  for (const auto& c : commands)
    s += fmt::format("complete -c nelf -n __fish_use_subcommand -a {} -d {}\n", c.name, fish_quote(c.description));
  for (const auto& c : commands) {
    const std::string condition = "__fish_seen_subcommand_from " + c.name;
    for (const auto& o : c.options) s += option_line(condition, o);
    if (!c.positionals.empty()) s += "complete -c nelf -n " + fish_quote(condition) + " -F\n";
  }
  return s;
}

void write_file(const std::filesystem::path& path, const std::string& text) {
  // Written beside and renamed, so a failed run leaves no half-written page for the build to install.
  const std::filesystem::path partial = path.string() + ".partial";
  {
    std::ofstream out(partial, std::ios::binary);
    out << text;
    out.close();
    if (!out) throw std::runtime_error("cannot write " + partial.string());
  }
  std::filesystem::rename(partial, path);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: nelf_docgen OUTDIR\n");
    return 2;
  }
  try {
    CLI::App app;
    nelf::app::build_cli(app);
    const CommandDoc root = describe_command(app);
    std::vector<CommandDoc> commands;
    const CLI::App& const_app = app;
    for (const CLI::App* sub : const_app.get_subcommands([](const CLI::App* s) { return !s->get_group().empty(); }))
      commands.push_back(describe_command(*sub));

    const std::filesystem::path dir = argv[1];
    std::filesystem::create_directories(dir);
    write_file(dir / "nelf.1", man_page(root, commands));
    write_file(dir / "nelf.bash", bash_completion(root, commands));
    write_file(dir / "_nelf", zsh_completion(root, commands));
    write_file(dir / "nelf.fish", fish_completion(root, commands));
  } catch (const std::exception& e) {
    std::fprintf(stderr, "nelf_docgen: %s\n", e.what());
    return 1;
  }
  return 0;
}
