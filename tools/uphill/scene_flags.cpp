#include "scene_flags.hpp"

#include <algorithm>

namespace uphill::cli {

std::string FlagName(const std::string& field) {
  std::string flag = "--" + field;
  std::replace(flag.begin(), flag.end(), '_', '-');
  return flag;
}

void AddSceneFlags(CLI::App* command, SceneFlags* flags) {
  static const std::map<std::string, std::string> kHelp = {
      {"body", "sphere | spheroid | double-cone"},
      {"label", "free text carried to the output"},
      {"R", "sphere radius or double-cone base radius, with unit (mm, m, in)"},
      {"a", "spheroid semi-axis across the rails (x and z), with unit"},
      {"b", "spheroid semi-axis along the rolling axis, with unit"},
      {"h", "double-cone half-length (base centre to apex), with unit"},
      {"L", "crossbar distance from O (horizontal unless --L-along-rail), with unit"},
      {"H", "height of the rails at the crossbar, with unit"},
      {"D", "rail separation at the crossbar, with unit"},
      {"theta", "inclination, with unit (deg, rad), instead of L, H, D"},
      {"alpha", "divergence angle, with unit (deg, rad), instead of L, H, D"},
      {"rod_diameter", "diameter of round rods, with unit (default: line rails)"},
  };
  for (const std::string& field : ConfigurationFieldNames()) {
    if (field == "L_convention") continue;  // the --L-along-rail flag below
    std::string help;
    if (auto it = kHelp.find(field); it != kHelp.end()) {
      help = it->second;
    } else if (field.rfind("u_", 0) == 0) {
      help = "standard uncertainty of " + FlagName(field.substr(2)) + ", same units";
    }
    command->add_option_function<std::string>(
        FlagName(field), [flags, field](const std::string& v) { flags->values[field] = v; }, help);
  }
  command->add_flag("--L-along-rail", flags->along_rail,
                    "L is measured along a rail from O (default: horizontally)");
}

FieldSource FlagSource(const SceneFlags& flags) {
  FieldSource source;
  source.lookup = [&flags](const std::string& name) -> std::optional<FieldSource::Field> {
    if (name == "L_convention") {
      if (!flags.along_rail) return std::nullopt;
      return FieldSource::Field{"along-rail", ""};
    }
    const auto it = flags.values.find(name);
    if (it == flags.values.end()) return std::nullopt;
    return FieldSource::Field{it->second, ""};
  };
  source.context = [](const std::string& name) {
    return name == "L_convention" ? std::string("--L-along-rail") : FlagName(name);
  };
  return source;
}

}  // namespace uphill::cli
