#include "self_documentation.hpp"

#include <filesystem>
#include <iostream>
#include <sstream>
#include <vector>

#include "io/atomic_file.hpp"
#include "io/units.hpp"

namespace uphill::cli {
namespace {

namespace fs = std::filesystem;

// ---- the command tree ----------------------------------------------------------------------

// The visible subcommands (CLI11 keeps option groups as nameless subcommands, and hides those
// whose group is empty).
std::vector<const CLI::App*> Subcommands(const CLI::App& app) {
  return app.get_subcommands(
      [](const CLI::App* sub) { return !sub->get_name().empty() && !sub->get_group().empty(); });
}

std::vector<const CLI::Option*> VisibleOptions(const CLI::App& app, bool positional) {
  return app.get_options([positional](const CLI::Option* o) {
    return !o->get_group().empty() && o->get_positional() == positional && (positional || o->nonpositional());
  });
}

// {"uphill", "calibrate", "camera"}; the program's name without a folder (CLI11 names an unnamed
// App after argv[0]).
std::vector<std::string> CommandPath(const CLI::App& app) {
  std::vector<std::string> path;
  for (const CLI::App* a = &app; a != nullptr; a = a->get_parent()) path.insert(path.begin(), a->get_name());
  path.front() = fs::path(path.front()).filename().string();
  return path;
}

std::string Join(const std::vector<std::string>& parts, const std::string& separator) {
  std::string out;
  for (const auto& p : parts) out += (out.empty() ? "" : separator) + p;
  return out;
}

// "-o, --out" in the order CLI11 was given them: short names first.
std::vector<std::string> FlagNames(const CLI::Option& o) {
  std::vector<std::string> names;
  for (const auto& s : o.get_snames()) names.push_back("-" + s);
  for (const auto& l : o.get_lnames()) names.push_back("--" + l);
  return names;
}

// Flags expect no items (CLI11 adds them with expected(0)).
bool TakesValue(const CLI::Option& o) { return o.get_items_expected_max() > 0; }

// The value's label as --help shows it ("TEXT", "UINT"), without validator descriptions.
std::string ValueLabel(const CLI::Option& o) {
  if (!o.get_option_text().empty()) return o.get_option_text();
  const std::string type = o.get_type_name();
  return type.substr(0, type.find(':'));
}

// A number without a unit (a count, a port): nothing to complete.
bool IsNumeric(const CLI::Option& o) {
  const std::string label = ValueLabel(o);
  return label == "INT" || label == "UINT" || label == "FLOAT" || label == "NUMBER";
}

// The choices of an option checked by CLI::IsMember (its type name ends in ":{a,b,c}").
std::vector<std::string> Choices(const CLI::Option& o) {
  const std::string type = o.get_type_name();
  const auto open = type.find(":{");
  const auto close = type.find('}', open);
  if (open == std::string::npos || close == std::string::npos) return {};
  std::vector<std::string> choices;
  std::stringstream items(type.substr(open + 2, close - open - 2));
  for (std::string item; std::getline(items, item, ',');) choices.push_back(item);
  return choices;
}

// Calls f on app and every visible subcommand below it, parents first.
template <typename F>
void ForEachCommand(const CLI::App& app, F&& f) {
  f(app);
  for (const CLI::App* sub : Subcommands(app)) ForEachCommand(*sub, f);
}

// ---- roff ----------------------------------------------------------------------------------

// Text for a roff line: backslashes escaped, hyphens as \- (so that flags copy and paste as
// ASCII hyphen-minus), a leading dot or quote protected, each line of the text kept.
std::string Roff(const std::string& text) {
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

std::string Bold(const std::string& s) { return "\\fB" + Roff(s) + "\\fR"; }
std::string Italic(const std::string& s) { return "\\fI" + Roff(s) + "\\fR"; }

std::string PageName(const CLI::App& app) { return Join(CommandPath(app), "-"); }

// The one-line description, without the program's "uphill: " prefix of its --help.
std::string Summary(const CLI::App& app) {
  const std::string prefix = CommandPath(app).back() + ": ";
  const std::string d = app.get_description();
  return d.rfind(prefix, 0) == 0 ? d.substr(prefix.size()) : d;
}

// Paragraphs of `text` (blank lines separate them) as roff paragraphs.
std::string Paragraphs(const std::string& text) {
  std::string out;
  std::stringstream lines(text);
  bool pending_break = false;
  for (std::string line; std::getline(lines, line);) {
    if (line.find_first_not_of(" \t") == std::string::npos) {
      pending_break = !out.empty();
      continue;
    }
    if (pending_break) out += ".PP\n";
    pending_break = false;
    out += Roff(line) + "\n";
  }
  return out;
}

std::string OptionEntry(const CLI::Option& o, bool positional) {
  std::string head = positional ? Italic(o.get_name(true, false)) : "";
  if (!positional) {
    std::vector<std::string> bold;
    for (const auto& n : FlagNames(o)) bold.push_back(Bold(n));
    head = Join(bold, ", ");
    if (TakesValue(o)) head += " " + Italic(ValueLabel(o));
  }
  std::string body = o.get_description();
  const auto choices = Choices(o);
  if (!choices.empty()) body += " (one of: " + Join(choices, ", ") + ")";
  if (!o.get_default_str().empty()) body += " (default: " + o.get_default_str() + ")";
  if (o.get_required()) body += " (required)";
  if (o.get_expected_max() == CLI::detail::expected_max_vector_size) body += " (may be repeated)";
  return ".TP\n" + head + "\n" + Roff(body) + "\n";
}

std::string Synopsis(const CLI::App& app) {
  std::string out = ".B " + Roff(Join(CommandPath(app), " ")) + "\n";
  if (!Subcommands(app).empty()) out += Italic("COMMAND") + " ";
  if (!VisibleOptions(app, false).empty()) out += "[" + Italic("OPTIONS") + "]";
  for (const CLI::Option* p : VisibleOptions(app, true)) {
    std::string name = Italic(p->get_name(true, false));
    if (p->get_expected_max() == CLI::detail::expected_max_vector_size) name += "...";
    out += " " + (p->get_required() ? name : "[" + name + "]");
  }
  return out + "\n";
}

// Sections that only the program's own page carries: what the user needs to know once.
std::string ProgramSections() {
  std::string s;
  s += ".SH UNITS\n";
  s += Roff("SI inside the library. On the command line every length and angle carries its unit: lengths " +
            AcceptedUnits(Dimension::kLength) + "; angles " + AcceptedUnits(Dimension::kAngle) +
            "; times " + AcceptedUnits(Dimension::kTime) + "; speeds " +
            AcceptedUnits(Dimension::kVelocity) + "; accelerations " +
            AcceptedUnits(Dimension::kAcceleration) +
            ". A number without a unit is refused. Tables print lengths in mm and angles in degrees, and "
            "every column header names its unit; JSON output is always SI (metres, radians, seconds).") +
       "\n";
  s += ".SH EXIT STATUS\n.TP\n0\nSuccess.\n.TP\n1\n";
  s += Roff("An internal error: a bug. Please report it with the command line.") + "\n.TP\n2\n";
  s += Roff("Bad input or environment: a flag, a file, a row or a column (the one-line message names it "
            "and the rule broken), or what the program needs from the machine (gnuplot, a writable output "
            "folder, a free port). In a batch the other rows are still processed and printed.") +
       "\n";
  s += ".SH FILES\n.TP\n" + Italic("PREFIX/share/uphill/data/") + "\n";
  s += Roff("Sample inputs: two synthetic experiments laid out like the seed paper's series "
            "(series1-fixed-D, series2-fixed-L) and a converter batch (convert_batch.csv). "
            "paper-figures reads the experiments from here when --data is not given.") +
       "\n.TP\n" + Italic("PREFIX/share/doc/uphill/") + "\n";
  s += Roff("The manual: README.md, the pages of docs/, the input formats (data/README.md) and the camera "
            "calibration procedure (calibration/README.md).") +
       "\n.TP\n" + Italic("PREFIX/share/systemd/user/uphill-serve.service") + "\n";
  s += Roff("A systemd user unit that runs `uphill serve` on this computer only (127.0.0.1), for a lab PC: "
            "systemctl --user enable --now uphill-serve; the experiment folder and port in "
            "~/.config/uphill/serve.env (docs/install.md).") +
       "\n.TP\n" + Italic("PREFIX/share/applications/uphill-serve.desktop") + "\n";
  s += Roff("A desktop launcher that starts that service and opens its page in the browser.") + "\n.PP\n";
  s += Roff("PREFIX is the installation prefix: /usr for the Debian package, /usr/local for "
            "`cmake --install` by default.") +
       "\n";
  return s;
}

std::string ManPage(const CLI::App& app, const std::string& version) {
  const bool program = app.get_parent() == nullptr;
  std::string upper = PageName(app);
  for (char& c : upper) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  std::string page = ".\\\" Generated by `" + CommandPath(app).front() +
                     " --man-pages` from the program's own command tree. Do not edit.\n";
  page += ".TH " + Roff(upper) + " 1 \"\" \"" + Roff(version) + "\" \"uphill manual\"\n";
  page += ".nh\n.ad l\n";  // no hyphenation, ragged right: flags and paths stay whole
  page += ".SH NAME\n" + Roff(PageName(app)) + " \\- " + Roff(Summary(app)) + "\n";
  page += ".SH SYNOPSIS\n" + Synopsis(app);
  page += ".SH DESCRIPTION\n" + Roff(Summary(app)) + ".\n";
  if (!app.get_footer().empty()) page += ".PP\n" + Paragraphs(app.get_footer());
  if (program)
    page += ".PP\n" + Roff("Each command has its own page, named after it: ") + Bold(PageName(app) + "-convert") +
            "(1) and so on (see COMMANDS). " + Roff("Every command prints its flags with --help.") + "\n";

  const auto positionals = VisibleOptions(app, true);
  if (!positionals.empty()) {
    page += ".SH ARGUMENTS\n";
    for (const CLI::Option* p : positionals) page += OptionEntry(*p, true);
  }
  const auto options = VisibleOptions(app, false);
  if (!options.empty()) {
    page += ".SH OPTIONS\n";
    for (const CLI::Option* o : options) page += OptionEntry(*o, false);
  }
  const auto subcommands = Subcommands(app);
  if (!subcommands.empty()) {
    page += ".SH COMMANDS\n";
    for (const CLI::App* sub : subcommands)
      page += ".TP\n" + Bold(sub->get_name()) + "\n" + Roff(Summary(*sub)) + ". See " +
              Bold(PageName(*sub)) + "(1).\n";
  }
  if (program) page += ProgramSections();

  std::vector<std::string> see_also;
  if (!program) see_also.push_back(Bold(PageName(*app.get_parent())) + "(1)");
  for (const CLI::App* sub : subcommands) see_also.push_back(Bold(PageName(*sub)) + "(1)");
  see_also.push_back(Italic("PREFIX/share/doc/uphill/README.md"));
  page += ".SH SEE ALSO\n" + Join(see_also, ",\n") + "\n";
  return page;
}

// ---- bash ----------------------------------------------------------------------------------

// s as one bash word in single quotes.
std::string BashWord(const std::string& s) {
  std::string out = "'";
  for (char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

}  // namespace

int WriteManPages(const CLI::App& root, const std::string& dir, const std::string& version) {
  fs::create_directories(dir);
  int pages = 0;
  ForEachCommand(root, [&](const CLI::App& app) {
    WriteFileAtomically((fs::path(dir) / (PageName(app) + ".1")).string(), ManPage(app, version));
    ++pages;
  });
  return pages;
}

std::string BashCompletion(const CLI::App& root) {
  const std::string program = CommandPath(root).front();
  const std::string function = "_" + program + "_complete";
  // Per command (its path as words): the subcommands, the flags, the flags that take a value,
  // and the choices of each flag that has them.
  std::string commands, subcommand_cases, option_cases, choice_cases;
  ForEachCommand(root, [&](const CLI::App& app) {
    const std::string path = Join(CommandPath(app), " ");
    std::vector<std::string> subs, flags, valued, numeric;
    for (const CLI::App* sub : Subcommands(app)) {
      subs.push_back(sub->get_name());
      commands += " " + BashWord(path + " " + sub->get_name());
    }
    for (const CLI::Option* o : VisibleOptions(app, false)) {
      for (const auto& name : FlagNames(*o)) {
        flags.push_back(name);
        if (TakesValue(*o)) (IsNumeric(*o) ? numeric : valued).push_back(name);
        const auto choices = Choices(*o);
        if (!choices.empty())
          choice_cases += "    " + BashWord(path + "|" + name) + ") choices=" + BashWord(Join(choices, " ")) + " ;;\n";
      }
    }
    subcommand_cases += "    " + BashWord(path) + ") subcommands=" + BashWord(Join(subs, " ")) + " ;;\n";
    option_cases += "    " + BashWord(path) + ") options=" + BashWord(Join(flags, " ")) +
                    "; valued=" + BashWord(" " + Join(valued, " ") + " ") +
                    "; numeric=" + BashWord(" " + Join(numeric, " ") + " ") + " ;;\n";
  });

  // The function: find the command being typed (the longest run of subcommand words), then
  // complete a choice, nothing (a number), a file (another value), a flag or a subcommand.
  std::string s = R"(# bash completion for @PROGRAM@. Generated by `@PROGRAM@ --bash-completion` from the program's own
# command tree. Do not edit. Completes subcommands, the flags of the command being typed, the
# choices of flags that have them, and file names for other values. Needs only bash.
@FUNCTION@() {
  local cur=${COMP_WORDS[COMP_CWORD]} prev=${COMP_WORDS[COMP_CWORD-1]}
  # --flag=value: bash splits at '=' (COMP_WORDBREAKS); complete the value.
  if [[ $cur == = ]]; then prev=${COMP_WORDS[COMP_CWORD-1]}; cur=""
  elif [[ $prev == = ]]; then prev=${COMP_WORDS[COMP_CWORD-2]}; fi
  local path=@PROGRAM_WORD@ i c candidate
  local -a commands=(@COMMANDS@ )
  for ((i = 1; i < COMP_CWORD; i++)); do
    candidate="$path ${COMP_WORDS[i]}"
    for c in "${commands[@]}"; do [[ $c == "$candidate" ]] && path=$candidate && break; done
  done
  local subcommands="" options="" valued="" numeric="" choices=""
  case $path in
@SUBCOMMAND_CASES@  esac
  case $path in
@OPTION_CASES@  esac
  case "$path|$prev" in
@CHOICE_CASES@  esac
  if [[ -n $choices ]]; then
    mapfile -t COMPREPLY < <(compgen -W "$choices" -- "$cur")
  elif [[ $numeric == *" $prev "* ]]; then
    COMPREPLY=()
  elif [[ $valued == *" $prev "* || ( $cur != -* && -z $subcommands ) ]]; then
    mapfile -t COMPREPLY < <(compgen -f -- "$cur")
    compopt -o filenames 2> /dev/null
  elif [[ $cur == -* ]]; then
    mapfile -t COMPREPLY < <(compgen -W "$options" -- "$cur")
  else
    mapfile -t COMPREPLY < <(compgen -W "$subcommands" -- "$cur")
  fi
}
complete -F @FUNCTION@ @PROGRAM@
)";
  for (const auto& [token, text] : std::vector<std::pair<std::string, std::string>>{
           {"@SUBCOMMAND_CASES@", subcommand_cases},
           {"@OPTION_CASES@", option_cases},
           {"@CHOICE_CASES@", choice_cases},
           {"@COMMANDS@", commands},
           {"@FUNCTION@", function},
           {"@PROGRAM_WORD@", BashWord(program)},
           {"@PROGRAM@", program}}) {
    for (auto at = s.find(token); at != std::string::npos; at = s.find(token, at + text.size()))
      s.replace(at, token.size(), text);
  }
  return s;
}

void AddSelfDocumentationFlags(CLI::App& app, const std::string& version) {
  // Hidden (empty group): for the build and for packagers, not a user's everyday flags.
  app.add_option_function<std::string>(
         "--man-pages",
         [&app, version](const std::string& dir) {
           const int pages = WriteManPages(app, dir, version);
           std::cout << "wrote " << pages << " manual pages into " << dir << "\n";
           throw CLI::Success();
         },
         "write the manual pages (roff) into DIR and exit")
      ->group("");
  app.add_option_function<std::string>(
         "--bash-completion",
         [&app](const std::string& file) {
           const std::string script = BashCompletion(app);
           if (file == "-") std::cout << script;
           else WriteFileAtomically(file, script);
           throw CLI::Success();
         },
         "write the bash completion script to FILE (- for stdout) and exit")
      ->group("");
}

}  // namespace uphill::cli
