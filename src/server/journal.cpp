#include "server/journal.hpp"

#include <sys/random.h>
#include <unistd.h>

#include <boost/crc.hpp>
#include <cstdio>
#include <string_view>

namespace uphill {
namespace {

using nlohmann::json;

constexpr std::string_view kCrcKey = ",\"crc32\":\"";
// `,"crc32":"` + 8 hex digits + `"}`.
constexpr std::size_t kCrcSuffixLength = kCrcKey.size() + 8 + 2;

std::string Crc32Hex(std::string_view bytes) {
  boost::crc_32_type crc;
  crc.process_bytes(bytes.data(), bytes.size());
  char buf[9];
  std::snprintf(buf, sizeof buf, "%08x", static_cast<unsigned>(crc.checksum()));
  return buf;
}

bool IsLowerHex(std::string_view s) {
  for (char c : s)
    if (!((c >= '0' && c <= '9') || (c >= 'a' && c <= 'f'))) return false;
  return true;
}

// A line decoded: the JSON body, or what is wrong with it.
struct Decoded {
  json body;
  bool checksummed = false;  // format 2: it carried a checksum, and the checksum matched
  std::string problem;       // "" when the line is usable
};

Decoded Decode(std::string_view line) {
  Decoded d;
  std::string text(line);
  const bool has_crc = line.size() > kCrcSuffixLength &&
                       line.substr(line.size() - kCrcSuffixLength, kCrcKey.size()) == kCrcKey &&
                       line.substr(line.size() - 2) == "\"}";
  if (has_crc) {
    const std::string_view hex = line.substr(line.size() - 10, 8);
    text = std::string(line.substr(0, line.size() - kCrcSuffixLength)) + "}";
    if (!IsLowerHex(hex) || Crc32Hex(text) != hex) {
      d.problem = "checksum mismatch (the line was changed or damaged after it was written)";
      return d;
    }
    d.checksummed = true;
  }
  try {
    d.body = json::parse(text);
  } catch (const json::exception&) {
    d.problem = "not JSON";
    return d;
  }
  if (!d.body.is_object()) d.problem = "not a JSON object";
  return d;
}

std::int64_t IntegerOr(const json& j, const char* key, std::int64_t fallback) {
  if (!j.is_object() || !j.contains(key) || !j.at(key).is_number_integer()) return fallback;
  return j.at(key).get<std::int64_t>();
}

bool IsSnapshot(const json& entry) {
  return entry.contains("op") && entry.at("op").is_object() && entry.at("op").value("type", "") == "snapshot";
}

// The version rule shared by both formats: a change adds 1, a snapshot keeps or raises it.
std::string VersionProblem(const json& entry, bool first, std::int64_t previous) {
  if (!entry.contains("version") || !entry.at("version").is_number_integer()) return "has no version";
  if (!entry.contains("op") || !entry.at("op").is_object()) return "has no operation";
  const std::int64_t v = entry.at("version").get<std::int64_t>();
  if (first) return IsSnapshot(entry) ? "" : "the first entry is not a snapshot";
  if (IsSnapshot(entry)) return v >= previous ? "" : "version " + std::to_string(v) + " goes back from " + std::to_string(previous);
  if (v != previous + 1)
    return "version " + std::to_string(v) + " follows version " + std::to_string(previous) +
           (v > previous + 1 ? " (an entry is missing)" : " (an entry is repeated or out of order)");
  return "";
}

}  // namespace

std::string EncodeJournalLine(const json& body) {
  std::string text = body.dump();  // sorted keys, no spaces, UTF-8 as is
  const std::string crc = Crc32Hex(text);
  text.pop_back();  // the closing brace
  text.append(kCrcKey).append(crc).append("\"}\n");
  return text;
}

std::string NewJournalId() {
  unsigned long long r = 0;
  if (::getrandom(&r, sizeof r, 0) != static_cast<ssize_t>(sizeof r))
    r = static_cast<unsigned long long>(::getpid()) * 0x9e3779b97f4a7c15ull ^ static_cast<unsigned long long>(::time(nullptr));
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", r);
  return buf;
}

std::string JournalHeaderLine(const std::string& id) {
  return EncodeJournalLine({{"format", kJournalFormat}, {"journal", id}, {"seq", 0}});
}

JournalScan ScanJournal(const std::string& text) {
  JournalScan scan;
  std::size_t start = 0;
  int line_number = 0;
  bool stopped = false;        // a problem was found: later lines only feed max_version
  bool v1_first = true;        // the next legacy entry is the first of its kind
  std::int64_t previous_version = 0;
  bool v2_first = true;
  const auto problem_at = [&](int line, const std::string& what, bool last_line) {
    const std::string message = "line " + std::to_string(line) + ": " + what;
    if (last_line) scan.torn_tail = message;
    else scan.damage = message;
    stopped = true;
  };
  while (start < text.size()) {
    const std::size_t newline = text.find('\n', start);
    const bool complete = newline != std::string::npos;
    const std::size_t end = complete ? newline : text.size();
    const bool last_line = !complete || end + 1 >= text.size();
    ++line_number;
    const Decoded d = Decode(std::string_view(text).substr(start, end - start));
    if (d.problem.empty()) scan.max_version = std::max(scan.max_version, IntegerOr(d.body, "version", 0));
    if (!stopped) {
      if (!complete) {
        problem_at(line_number, "incomplete (no end of line)", true);
      } else if (!d.problem.empty()) {
        problem_at(line_number, d.problem, last_line);
      } else if (d.body.value("format", "") == kJournalFormat) {
        if (!d.checksummed || IntegerOr(d.body, "seq", -1) != 0 || !d.body.contains("journal") ||
            !d.body.at("journal").is_string()) {
          problem_at(line_number, "malformed journal header", last_line);
        } else {
          // A new section: what came before it (a legacy journal) is superseded.
          scan.format = 2;
          scan.id = d.body.at("journal").get<std::string>();
          scan.entries.clear();
          scan.last_seq = 0;
          v2_first = true;
        }
      } else if (d.body.contains("format")) {
        problem_at(line_number, "a journal of another format (" + d.body.at("format").dump().substr(0, 40) +
                                    "): this uphill reads uphill-journal/2 and the format before it",
                   last_line);
      } else if (scan.format == 2) {
        const std::int64_t seq = IntegerOr(d.body, "seq", -1);
        std::string version_problem;
        if (!d.checksummed) {
          problem_at(line_number, "has no checksum", last_line);
        } else if (seq != scan.last_seq + 1) {
          problem_at(line_number,
                     "entry " + std::to_string(seq) + " follows entry " + std::to_string(scan.last_seq) +
                         (seq > scan.last_seq + 1 ? " (an entry is missing)" : " (an entry is repeated or out of order)"),
                     last_line);
        } else if (!(version_problem = VersionProblem(d.body, v2_first, previous_version)).empty()) {
          problem_at(line_number, version_problem, last_line);
        } else {
          scan.last_seq = seq;
          previous_version = d.body.at("version").get<std::int64_t>();
          v2_first = false;
          scan.entries.push_back(d.body);
        }
      } else {
        const std::string version_problem = VersionProblem(d.body, v1_first, previous_version);
        if (d.checksummed || d.body.contains("seq")) {
          problem_at(line_number, "an entry of format 2 without the journal's header line", last_line);
        } else if (!version_problem.empty()) {
          problem_at(line_number, version_problem, last_line);
        } else {
          scan.format = 1;
          previous_version = d.body.at("version").get<std::int64_t>();
          v1_first = false;
          scan.entries.push_back(d.body);
        }
      }
      if (!stopped) scan.good_bytes = end + 1;
    }
    start = complete ? newline + 1 : text.size();
  }
  return scan;
}

std::string EncodeJournalHead(const JournalHead& head) {
  return json({{"format", kJournalHeadFormat}, {"journal", head.journal}, {"seq", head.seq}, {"version", head.version}})
             .dump() +
         "\n";
}

std::optional<JournalHead> ParseJournalHead(const std::string& text) {
  try {
    const json j = json::parse(text);
    if (!j.is_object() || j.value("format", "") != kJournalHeadFormat) return std::nullopt;
    JournalHead head;
    head.journal = j.at("journal").get<std::string>();
    head.seq = j.at("seq").get<std::int64_t>();
    head.version = j.at("version").get<std::int64_t>();
    return head;
  } catch (const json::exception&) {
    return std::nullopt;
  }
}

}  // namespace uphill
