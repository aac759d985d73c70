// ValidateMetadata and FieldErrors (experiment_state.hpp): experiment.json as the page's form sends
// it, every field checked on its own so that one answer names all that are wrong.
#include <algorithm>
#include <string>
#include <vector>

#include "io/experiment_folder.hpp"
#include "io/units.hpp"
#include "model/input_error.hpp"
#include "server/experiment_state.hpp"
#include "internal/state_text.hpp"

namespace uphill {
namespace {

using internal::CheckText;
using internal::Trim;
using nlohmann::json;
using nlohmann::ordered_json;

bool IsAngle(const std::string& key) { return key == "theta" || key == "alpha"; }

void CheckQuantity(const json& j, const std::string& field, Dimension dimension) {
  const std::string s = CheckText(j, field, 64);
  ParseQuantity(s, dimension, field);  // throws InputError naming the field
}

// Collects the violations of independent fields, so that one request learns all of them.
class Violations {
 public:
  template <class Check>
  void Try(Check&& check) {
    try {
      check();
    } catch (const FieldErrors& e) {
      errors_.insert(errors_.end(), e.errors().begin(), e.errors().end());
    } catch (const InputError& e) {
      errors_.push_back(e);
    }
  }
  bool empty() const { return errors_.empty(); }
  void ThrowIfAny() const {
    if (!errors_.empty()) throw FieldErrors(errors_);
  }

 private:
  std::vector<InputError> errors_;
};

ordered_json ValidateBody(const json& j) {
  if (!j.contains("body") || !j.at("body").is_object()) throw InputError("experiment.body", "is missing");
  const json& body = j.at("body");
  Violations violations;
  for (const auto& [key, value] : body.items())
    if (!BodyKeys().count(key))
      violations.Try([&, k = key] { throw InputError("experiment.body." + k.substr(0, 32), "unknown key"); });
  const std::string type = CheckText(body.value("type", json("")), "experiment.body.type", 32);
  if (type != "sphere" && type != "spheroid" && type != "double-cone")
    throw InputError("experiment.body.type", "must be sphere, spheroid or double-cone");
  ordered_json out_body;
  out_body["type"] = type;
  const std::vector<std::string> dims = type == "sphere" ? std::vector<std::string>{"R"}
                                        : type == "spheroid" ? std::vector<std::string>{"a", "b"}
                                                             : std::vector<std::string>{"R", "h"};
  for (const auto& [key, value] : body.items()) {
    if (key == "type" || !BodyKeys().count(key)) continue;
    if (std::find(dims.begin(), dims.end(), key) == dims.end())
      violations.Try([&, k = key] { throw InputError("experiment.body." + k, "does not belong to a " + type); });
  }
  for (const std::string& d : dims)
    violations.Try([&] {
      if (!body.contains(d))
        throw InputError("experiment.body." + d, "is missing (a length with its unit, e.g. \"12.7 mm\")");
      CheckQuantity(body.at(d), "experiment.body." + d, Dimension::kLength);
      if (!(ParseQuantity(body.at(d).get<std::string>(), Dimension::kLength, d) > 0))
        throw InputError("experiment.body." + d, "must be > 0");
      out_body[d] = Trim(body.at(d).get<std::string>());
    });
  violations.ThrowIfAny();
  return out_body;
}

// `apparatus` or `uncertainties`: each key checked on its own.
ordered_json ValidateLengths(const json& s, const std::string& section) {
  if (!s.is_object()) throw InputError("experiment." + section, "must be a JSON object");
  const auto& keys = section == "apparatus" ? ApparatusKeys() : UncertaintyKeys();
  ordered_json o = ordered_json::object();
  Violations violations;
  for (const auto& [key, value] : s.items())
    violations.Try([&, k = key, &v = value] {
      const std::string field = "experiment." + section + "." + k.substr(0, 32);
      if (!keys.count(k)) throw InputError(field, "unknown key");
      if (v.is_string() && Trim(v.get<std::string>()).empty()) return;  // left blank
      if (k == "L_convention") {
        const std::string c = CheckText(v, field, 32);
        if (c != "horizontal" && c != "along-rail") throw InputError(field, "must be horizontal or along-rail");
        o[k] = c;
        return;
      }
      const Dimension dimension = IsAngle(k) ? Dimension::kAngle : Dimension::kLength;
      CheckQuantity(v, field, dimension);
      if (ParseQuantity(v.get<std::string>(), dimension, field) < 0) throw InputError(field, "must be >= 0");
      o[k] = Trim(v.get<std::string>());
    });
  violations.ThrowIfAny();
  return o;
}

}  // namespace

FieldErrors::FieldErrors(std::vector<InputError> errors)
    : InputError(errors.empty() ? InputError("request", "is refused") : errors.front()), errors_(std::move(errors)) {
  if (errors_.empty()) errors_.push_back(*this);
}

ordered_json ValidateMetadata(const json& j) {
  if (!j.is_object()) throw InputError("experiment", "must be a JSON object");
  Violations violations;
  for (const auto& [key, value] : j.items())
    if (!ExperimentKeys().count(key))
      violations.Try([&, k = key] { throw InputError("experiment." + k.substr(0, 32), "unknown key"); });
  ordered_json out;
  out["format"] = kExperimentFormat;
  if (j.contains("format") && j.at("format") != kExperimentFormat && j.at("format") != kExperimentFormat2)
    violations.Try([] {
      throw InputError("experiment.format", std::string("must be \"") + kExperimentFormat + "\" or \"" +
                                                kExperimentFormat2 + "\"");
    });
  for (const char* key : {"title", "operator", "date"})
    if (j.contains(key))
      violations.Try([&] {
        const std::string s = CheckText(j.at(key), std::string("experiment.") + key, kMaxNoteLength);
        if (!s.empty()) out[key] = s;
      });
  if (j.contains("notes"))
    violations.Try([&] {
      const json& notes = j.at("notes");
      if (notes.is_string()) {
        if (!notes.get<std::string>().empty()) out["notes"] = CheckText(notes, "experiment.notes", kMaxNoteLength);
      } else if (notes.is_array()) {
        if (notes.size() > 50) throw InputError("experiment.notes", "has more than 50 paragraphs");
        ordered_json list = ordered_json::array();
        for (const json& p : notes) {
          const std::string s = CheckText(p, "experiment.notes", kMaxNoteLength);
          if (!s.empty()) list.push_back(s);
        }
        if (!list.empty()) out["notes"] = list;
      } else {
        throw InputError("experiment.notes", "must be a string or a list of strings");
      }
    });
  violations.Try([&] { out["body"] = ValidateBody(j); });
  for (const char* section : {"apparatus", "uncertainties"})
    if (j.contains(section))
      violations.Try([&] {
        ordered_json o = ValidateLengths(j.at(section), section);
        if (!o.empty()) out[section] = o;
      });
  if (j.contains("camera"))
    violations.Try([&] {
      CheckRelativePath(j.at("camera").is_string() ? j.at("camera").get<std::string>() : "", "experiment.camera");
      out["camera"] = j.at("camera");
    });
  if (j.contains("scenes"))
    violations.Try([&] {
      const json& scenes = j.at("scenes");
      if (!scenes.is_object()) throw InputError("experiment.scenes", "must be a JSON object (name -> scene file)");
      if (scenes.size() > 100) throw InputError("experiment.scenes", "has more than 100 scenes");
      ordered_json o = ordered_json::object();
      for (const auto& [name, path] : scenes.items()) {
        const std::string field = "experiment.scenes." + name.substr(0, 32);
        CheckText(json(name), field, kMaxLabelLength);
        if (name.empty()) throw InputError("experiment.scenes", "a scene's name is empty");
        CheckRelativePath(path.is_string() ? path.get<std::string>() : "", field);
        o[name] = path;
      }
      if (!o.empty()) out["scenes"] = o;
    });
  if (j.contains("video_analysis"))
    violations.Try([&] {
      const json& v = j.at("video_analysis");
      if (!v.is_object() || v.size() > 16) throw InputError("experiment.video_analysis", "must be a JSON object");
      for (const auto& [key, value] : v.items())
        CheckText(value, "experiment.video_analysis." + key.substr(0, 32), 64);
      // The one option the form offers; io/experiment.hpp reads the others (and refuses them).
      if (v.contains("fit") && v.at("fit") != "g" && v.at("fit") != "mu")
        throw InputError("experiment.video_analysis.fit", "must be \"g\" (an effective g) or \"mu\" (rolling resistance)");
      out["video_analysis"] = v;
    });
  violations.ThrowIfAny();
  return out;
}

}  // namespace uphill
