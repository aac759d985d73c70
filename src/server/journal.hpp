// The journal of `uphill serve` (EXP/journal.jsonl) as bytes: how an entry is written and how a
// journal is read back and checked before it is trusted. ExperimentStore (experiment_store.hpp)
// decides what to do with what is found. Format: data/README.md, "Journal".
//
// Format uphill-journal/2: a header line
//   {"format":"uphill-journal/2","journal":"<16 hex id>","seq":0,"crc32":"<8 hex>"}
// then one entry per line, each with `seq` (1, 2, 3, … in the file: a missing or repeated line
// is a gap) and, as its last member, `crc32`: the CRC-32 (Boost.CRC, the zlib/PNG polynomial) of
// the line's bytes with the `,"crc32":"…"` member taken out. A line whose checksum does not match
// was damaged after it was written.
//
// Format 1 (journals written before) has no header, no seq and no checksum; it is still read: its
// lines must be JSON and its versions must follow one another (a deleted line leaves a gap).
// When the store next writes to such a journal it appends a format-2 header and a snapshot, and
// only that section is replayed from then on.
//
// The head file EXP/journal.head.json, replaced atomically after every change,
//   {"format":"uphill-journal-head/1","journal":"<id>","seq":N,"version":V}
// records the last entry that was acknowledged, so that a journal cut short at a line boundary
// (which leaves no torn line) is noticed too.
#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

namespace uphill {

inline constexpr const char* kJournalFormat = "uphill-journal/2";
inline constexpr const char* kJournalHeadFormat = "uphill-journal-head/1";
inline constexpr const char* kJournalHeadFile = "journal.head.json";

// One line: `body` (an object without `crc32`) serialised, its checksum appended, and '\n'.
std::string EncodeJournalLine(const nlohmann::json& body);
// The header line of a new journal with this id.
std::string JournalHeaderLine(const std::string& id);
// A new random journal id (16 hex digits).
std::string NewJournalId();

struct JournalScan {
  int format = 0;          // 0: empty, 1: legacy lines only, 2: a format-2 section is the journal
  std::string id;          // format 2: the journal's id
  std::vector<nlohmann::json> entries;  // the entries to replay (format 2: the last section), in order
  std::int64_t last_seq = 0;            // format 2: seq of the last good entry (0: none)
  // The first problem that is not just the last line, "line N: …" (then entries stop before it).
  std::optional<std::string> damage;
  // The last line is incomplete (no '\n') or fails its checksum or is not JSON, and nothing else
  // is wrong: a change that was being written when the server stopped, if the files agree.
  std::optional<std::string> torn_tail;
  std::size_t good_bytes = 0;  // length of the journal without the torn tail
  std::int64_t max_version = 0;  // the largest version in any readable line, damaged parts included
};

JournalScan ScanJournal(const std::string& text);

struct JournalHead {
  std::string journal;
  std::int64_t seq = 0, version = 0;
};
std::string EncodeJournalHead(const JournalHead& head);
// nullopt when the text is not a head file of this format (an unreadable head is ignored: the
// journal's own checks still apply).
std::optional<JournalHead> ParseJournalHead(const std::string& text);

}  // namespace uphill
