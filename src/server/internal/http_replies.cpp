#include "http_replies.hpp"

#include <cctype>
#include <filesystem>
#include <stdexcept>
#include <string_view>

#include "io/utf8.hpp"
#include "model/input_error.hpp"

namespace uphill::internal {

using nlohmann::json;
using nlohmann::ordered_json;

namespace {

constexpr const char* kPagePolicy =
    "default-src 'none'; script-src 'self'; style-src 'self'; img-src 'self'; connect-src 'self'; "
    "form-action 'none'; frame-ancestors 'none'; base-uri 'none'";

// A request body as JSON. Nesting is bounded: no request of the page is deeper than 4.
// Marks a byte that is not UTF-8 while the field holding it is looked for: U+FDD0, a
// noncharacter that no keyboard produces.
constexpr std::string_view kBadByteMark = "\xEF\xB7\x90";

// The path of the first key or string value that contains the mark, as the API names fields
// ("row.note", "experiment.body.a"), or "" if none.
std::string MarkedField(const json& j, const std::string& path) {
  const auto marked = [](const std::string& s) { return s.find(kBadByteMark) != std::string::npos; };
  if (j.is_string()) return marked(j.get_ref<const std::string&>()) ? path : "";
  if (j.is_object())
    for (const auto& [key, value] : j.items()) {
      const std::string inner = path.empty() ? key : path + "." + key;
      if (marked(key)) return inner;
      if (std::string found = MarkedField(value, inner); !found.empty()) return found;
    }
  if (j.is_array())
    for (std::size_t i = 0; i < j.size(); ++i)
      if (std::string found = MarkedField(j[i], path + "[" + std::to_string(i) + "]"); !found.empty()) return found;
  return "";
}

const json::parser_callback_t kDepthLimit = [](int depth, json::parse_event_t, json&) {
  if (depth > 16) throw InputError("request", "JSON nested too deeply");
  return true;
};

// Text that is not UTF-8 (a Latin-1 paste, a broken client) is refused naming the field that
// holds it, which JSON's own parser cannot do: the bad bytes are marked, the marked document is
// parsed, and the field with the mark is named.
[[noreturn]] void RefuseNotUtf8(const std::string& body) {
  std::string marked;
  std::string_view rest = body;
  for (std::size_t bad; (bad = InvalidUtf8At(rest)) != std::string_view::npos;) {
    marked.append(rest.substr(0, bad)).append(kBadByteMark);
    rest.remove_prefix(bad + 1);
  }
  marked.append(rest);
  const json j = json::parse(marked, nullptr, false);
  std::string field = j.is_discarded() ? "" : MarkedField(j, "");
  if (field.empty()) field = "request";
  // The key itself may be the bad text: name it with the mark shown as U+FFFD.
  for (std::size_t at; (at = field.find(kBadByteMark)) != std::string::npos;) field.replace(at, kBadByteMark.size(), "\xEF\xBF\xBD");
  throw InputError(field.substr(0, 96), "is not valid UTF-8 text (the page sends UTF-8: retype or paste it again)");
}

}  // namespace

void SecurityHeaders(httplib::Response& res) {
  if (!res.has_header("Content-Security-Policy")) res.set_header("Content-Security-Policy", kPagePolicy);
  if (!res.has_header("Cache-Control")) res.set_header("Cache-Control", "no-store");
  res.set_header("X-Content-Type-Options", "nosniff");
  res.set_header("Referrer-Policy", "no-referrer");
  res.set_header("X-Frame-Options", "DENY");
}

void SendJson(httplib::Response& res, int status, const ordered_json& body) {
  res.status = status;
  // Text that is not UTF-8 never gets this far (422 naming the field); `replace` keeps an answer
  // an answer even if some did.
  res.set_content(body.dump(-1, ' ', false, ordered_json::error_handler_t::replace), "application/json; charset=utf-8");
}

void SendError(httplib::Response& res, int status, const std::string& message, const std::string& field) {
  ordered_json body = {{"error", message}};
  if (!field.empty()) body["field"] = field;
  SendJson(res, status, body);
}

json ParseBody(const httplib::Request& req) {
  if (req.body.empty()) return json::object();
  if (InvalidUtf8At(req.body) != std::string_view::npos) RefuseNotUtf8(req.body);
  return json::parse(req.body, kDepthLimit);
}

std::int64_t VersionOf(const json& body) {
  if (!body.is_object() || !body.contains("version") || !body.at("version").is_number_integer())
    throw std::invalid_argument("version: missing (the version of the state the change was made against)");
  return body.at("version").get<std::int64_t>();
}

bool IsJsonContentType(const std::string& value) {
  std::string v;
  for (char c : value)
    if (c != ' ' && c != '\t') v += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return v == "application/json" || v == "application/json;charset=utf-8";
}

std::string ContentType(const std::string& name) {
  const std::string ext = std::filesystem::path(name).extension().string();
  if (ext == ".html") return "text/html; charset=utf-8";
  if (ext == ".json") return "application/json; charset=utf-8";
  if (ext == ".svg") return "image/svg+xml";
  if (ext == ".png") return "image/png";
  if (ext == ".jpg" || ext == ".jpeg") return "image/jpeg";
  return "text/plain; charset=utf-8";  // .md, .gp, .dat, anything else: shown, never run
}

httplib::Server::HandlerResponse Refuse(httplib::Response& res, int status, const std::string& message,
                                        const std::string& field) {
  SendError(res, status, message, field);
  SecurityHeaders(res);
  res.set_header("Connection", "close");
  internal::BoundedHttpServer::CloseAfterResponse();
  return httplib::Server::HandlerResponse::Handled;
}

}  // namespace uphill::internal
