// Man page and bash completion from the CLI11 definitions (see manual.h).
#include "cli/manual.h"

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <sstream>

namespace pathex::cli {
namespace {

// The subcommands in registration order (CLI11 keeps them so).
std::vector<const CLI::App*> subcommands(const CLI::App& app) {
  return app.get_subcommands([](const CLI::App*) { return true; });
}

// The options a user sees in --help: hidden ones (empty group) and --help itself left out.
std::vector<const CLI::Option*> visible_options(const CLI::App& app) {
  std::vector<const CLI::Option*> out;
  for (const CLI::Option* o : app.get_options())
    if (!o->get_group().empty() && o != app.get_help_ptr() && o != app.get_help_all_ptr()) out.push_back(o);
  return out;
}

bool takes_value(const CLI::Option& o) { return o.get_expected_max() > 0; }  // flags expect 0

// The choices an option's validator lists, e.g. TEXT:{full,heckbert} -> full heckbert.
std::vector<std::string> choices(const CLI::Option& o) {
  const std::string t = o.get_type_name();
  const std::size_t open = t.find('{'), close = t.find('}', open);
  std::vector<std::string> out;
  if (open == std::string::npos || close == std::string::npos) return out;
  std::stringstream items(t.substr(open + 1, close - open - 1));
  for (std::string item; std::getline(items, item, ',');) out.push_back(item);
  return out;
}

// The long name (or the positional's name) of an option.
std::string option_name(const CLI::Option& o) {
  if (o.get_positional()) return o.get_name(/*positional=*/true);
  return o.get_lnames().empty() ? "-" + o.get_snames().front() : "--" + o.get_lnames().front();
}

// Escapes text for roff: backslashes, hyphens (so they stay ASCII minus signs), a leading period
// or quote that would start a request, and every non-ASCII character as its \[uXXXX] glyph (groff
// reads its input as Latin-1 unless told otherwise).
std::string roff(const std::string& text) {
  std::string out;
  bool line_start = true;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const unsigned char c = static_cast<unsigned char>(text[i]);
    if (line_start && (c == '.' || c == '\'')) out += "\\&";
    line_start = c == '\n';
    if (c == '\\') {
      out += "\\e";
    } else if (c == '-') {
      out += "\\-";
    } else if (c < 0x80) {
      out += static_cast<char>(c);
    } else {
      // A UTF-8 sequence: its length from the lead byte, then six bits per continuation byte.
      const int extra = c >= 0xf0 ? 3 : c >= 0xe0 ? 2 : c >= 0xc0 ? 1 : 0;
      std::uint32_t code = extra == 3 ? c & 0x07u : extra == 2 ? c & 0x0fu : extra == 1 ? c & 0x1fu : 0xfffdu;
      for (int k = 0; k < extra && i + 1 < text.size(); ++k) code = (code << 6) | (static_cast<unsigned char>(text[++i]) & 0x3fu);
      char buf[16];
      std::snprintf(buf, sizeof buf, "\\[u%04X]", static_cast<unsigned>(code));
      out += buf;
    }
  }
  return out;
}

std::string synopsis(const CLI::App& sub) {
  std::string s = "pathex " + sub.get_name() + " [options]";
  for (const CLI::Option* o : visible_options(sub))
    if (o->get_positional()) {
      const bool many = o->get_items_expected_max() > 1;
      s += o->get_required() ? " " + option_name(*o) : " [" + option_name(*o) + "]";
      if (many) s += "...";
    }
  return s;
}

}  // namespace

std::string man_page(const CLI::App& app, const std::string& version) {
  std::ostringstream m;
  const std::string description = app.get_description();
  const std::string summary = description.substr(0, description.find('\n'));
  m << ".TH PATHEX 1 \"\" \"pathex " << version << "\" \"User Commands\"\n"
    << ".SH NAME\npathex \\- " << roff(summary.substr(summary.find(':') + 2)) << "\n"
    << ".SH SYNOPSIS\n";
  for (const CLI::App* sub : subcommands(app)) m << ".B " << roff(synopsis(*sub)) << "\n.br\n";
  m << ".B pathex \\-\\-help\\fR | \\fB\\-\\-version\\fR | \\fB\\-\\-man\\fR | \\fB\\-\\-bash\\-completion\n"
    << ".SH DESCRIPTION\n" << [&] {
         // The lines after the summary; an example starts a paragraph of its own.
         std::string body = roff(description.substr(std::min(description.size(), summary.size() + 1)));
         for (std::size_t at = body.find("\nExample:"); at != std::string::npos; at = body.find("\nExample:", at + 5))
           body.insert(at + 1, ".PP\n");
         return body;
       }() << "\n"
    << ".PP\nEvery command prints its own help with \\fBpathex\\fR \\fIcommand\\fR \\fB\\-\\-help\\fR.\n"
    << ".SH COMMANDS\n";
  for (const CLI::App* sub : subcommands(app)) {
    m << ".SS \"" << roff(synopsis(*sub)) << "\"\n" << roff(sub->get_description()) << "\n";
    std::string group;
    for (const CLI::Option* o : visible_options(*sub)) {
      if (o->get_group() != group && !o->get_positional() && o->get_group() != "Options")
        m << ".PP\n\\fI" << roff(o->get_group()) << "\\fR\n";
      group = o->get_group();
      m << ".TP\n\\fB" << roff(option_name(*o)) << "\\fR";
      if (takes_value(*o) && !o->get_positional()) m << " \\fI" << roff(o->get_type_name()) << "\\fR";
      m << "\n" << roff(o->get_description());
      if (!o->get_default_str().empty()) m << " (default: " << roff(o->get_default_str()) << ")";
      m << "\n";
    }
    if (!sub->get_footer().empty()) m << ".PP\n.nf\n" << roff(sub->get_footer()) << "\n.fi\n";
  }
  if (!app.get_footer().empty()) m << ".SH EXIT STATUS\n.nf\n" << roff(app.get_footer()) << "\n.fi\n";
  m << ".SH SEE ALSO\nThe README of the pathex sources, and \\fBpathex\\fR \\fIcommand\\fR \\fB\\-\\-help\\fR.\n";
  return m.str();
}

std::string bash_completion(const CLI::App& app, const std::vector<std::string>& renderers) {
  auto join = [](const std::vector<std::string>& words) {
    std::string s;
    for (const std::string& w : words) s += (s.empty() ? "" : " ") + w;
    return s;
  };
  std::vector<std::string> names;
  for (const CLI::App* sub : subcommands(app)) names.push_back(sub->get_name());
  std::ostringstream b;
  b << "# bash completion for pathex, generated by `pathex --bash-completion` from its command-line\n"
    << "# definitions. Installed as share/bash-completion/completions/pathex.\n"
    << "_pathex() {\n"
    << "  local cur=\"${COMP_WORDS[COMP_CWORD]}\" prev=\"${COMP_WORDS[COMP_CWORD-1]}\" cmd=\"\" w\n"
    << "  for w in \"${COMP_WORDS[@]:1:COMP_CWORD-1}\"; do\n"
    << "    case \"$w\" in " << [&] {
         std::string alts;
         for (const std::string& n : names) alts += (alts.empty() ? "" : "|") + n;
         return alts;
       }() << ") cmd=\"$w\"; break ;; esac\n"
    << "  done\n"
    << "  if [[ -z \"$cmd\" ]]; then\n"
    << "    COMPREPLY=($(compgen -W \"" << join(names) << " --help --version --man --bash-completion\" -- \"$cur\"))\n"
    << "    return\n"
    << "  fi\n"
    << "  local opts=\"\" values=\"\" value_option=0\n"
    << "  case \"$cmd\" in\n";
  for (const CLI::App* sub : subcommands(app)) {
    std::vector<std::string> opts{"--help"};
    std::ostringstream values;
    for (const CLI::Option* o : visible_options(*sub)) {
      if (o->get_positional()) continue;
      const std::string name = option_name(*o);
      opts.push_back(name);
      if (!takes_value(*o)) continue;
      std::vector<std::string> c = name == "--renderer" ? renderers : choices(*o);
      values << "        " << name << ") value_option=1; values=\"" << join(c) << "\" ;;\n";
    }
    b << "    " << sub->get_name() << ")\n"
      << "      opts=\"" << join(opts) << "\"\n"
      << "      case \"$prev\" in\n" << values.str() << "      esac ;;\n";
  }
  b << "  esac\n"
    << "  if [[ $value_option == 1 ]]; then\n"
    << "    COMPREPLY=($(compgen -W \"$values\" -- \"$cur\"))\n"
    << "    [[ -z \"$values\" || \"$prev\" == --renderer ]] && COMPREPLY+=($(compgen -f -- \"$cur\"))\n"
    << "  elif [[ \"$cur\" == -* ]]; then\n"
    << "    COMPREPLY=($(compgen -W \"$opts\" -- \"$cur\"))\n"
    << "  else\n"
    << "    COMPREPLY=($(compgen -f -- \"$cur\"))\n"
    << "  fi\n"
    << "}\n"
    << "complete -o filenames -F _pathex pathex\n";
  return b.str();
}

}  // namespace pathex::cli
