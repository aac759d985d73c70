// ExperimentStore: the one owner of an experiment folder while `uphill serve` runs. Every
// accepted change is durable before it is acknowledged, and edits from several tabs or people
// never silently overwrite each other.
//
// Durability. A change is (1) appended to EXP/journal.jsonl and fsynced, then (2) applied in
// memory, then (3) experiment.json and measurements.csv are replaced with
// WriteFileAtomically (write, fsync, rename, fsync the folder). Only then does the caller
// acknowledge it. A crash at any point leaves complete files of version N or N − 1 and a journal
// that holds N: on start the journal is replayed and the files rewritten (data/README.md,
// "Journal"). A torn last journal line is a change that was never acknowledged: it is cut off.
//
// Files edited by hand. Each journal entry records hashes (FNV-1a 64) of the two files it
// produced. If experiment.json on disk matches no entry, someone changed the folder while the
// server was not running: the files win, and the next change starts a new history in the journal
// with a snapshot of them (nothing in the files is overwritten by an old journal).
//
// Versions. The state has a version, +1 per change. Every change names the version it was made
// against; a different one throws VersionConflict (the page then shows the current state and
// keeps the technician's draft), so two tabs cannot overwrite each other's rows.
//
// Undo is one linear history for the experiment (all clients): it applies the inverse of the last
// change that has not been undone, as a new change with a new version. Creating the experiment
// cannot be undone. The history survives restarts (it is replayed from the journal).
//
// Thread-safe: one mutex serialises every call.
#pragma once

#include <cstdint>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "server/experiment_state.hpp"

namespace uphill {

inline constexpr const char* kJournalFile = "journal.jsonl";
inline constexpr std::size_t kMaxUndo = 500;

struct StoreSnapshot {
  std::int64_t version = 0;
  ExperimentState state;
  bool can_undo = false;
};

// A change made against a version that is no longer current.
class VersionConflict : public std::runtime_error {
 public:
  VersionConflict(std::int64_t expected, StoreSnapshot current)
      : std::runtime_error("the experiment changed meanwhile (you edited version " + std::to_string(expected) +
                           ", it is now version " + std::to_string(current.version) +
                           "): your change was not applied; check the current rows and enter it again"),
        current_(std::move(current)) {}
  const StoreSnapshot& current() const { return current_; }

 private:
  StoreSnapshot current_;
};

class ExperimentStore {
 public:
  // Opens (or prepares to create) the folder and recovers its state. Does not write anything.
  // Throws InputError for an unreadable experiment.json, std::runtime_error for a damaged journal.
  explicit ExperimentStore(std::string directory);
  ~ExperimentStore();
  ExperimentStore(const ExperimentStore&) = delete;
  ExperimentStore& operator=(const ExperimentStore&) = delete;

  StoreSnapshot Get() const;

  // Each change: throws VersionConflict, InputError (the request's content: nothing is written),
  // or std::runtime_error (a system call failed; the message says what was kept).
  StoreSnapshot SetMetadata(std::int64_t version, const nlohmann::json& experiment, const std::string& unit);
  // index: position among the rows (default: at the end).
  StoreSnapshot AddRow(std::int64_t version, const nlohmann::json& row, std::optional<std::int64_t> index = {});
  StoreSnapshot EditRow(std::int64_t version, std::int64_t id, const nlohmann::json& row);
  StoreSnapshot DeleteRow(std::int64_t version, std::int64_t id);
  StoreSnapshot Undo(std::int64_t version);

  const std::string& directory() const { return directory_; }
  // What opening did, in one line (e.g. "replayed 3 journal entries"), for the server's log.
  const std::string& recovery_note() const { return recovery_note_; }

 private:
  StoreSnapshot SnapshotLocked() const;
  void CheckVersion(std::int64_t version) const;
  StoreSnapshot Commit(const nlohmann::json& op, bool undo);
  void Append(const nlohmann::json& entry);
  void WriteFiles();

  std::string directory_;
  mutable std::mutex mutex_;
  ExperimentState state_;
  std::int64_t version_ = 0;
  std::vector<nlohmann::json> undo_;  // inverses, last change last
  bool need_snapshot_ = true;         // the journal does not (yet) describe state_
  std::string json_hash_, csv_hash_;  // of the files as they are on disk ("" = absent)
  int journal_fd_ = -1;
  std::string recovery_note_;
};

// FNV-1a 64 of the bytes, 16 hex digits (stable across runs and platforms).
std::string ContentHash(const std::string& bytes);

}  // namespace uphill
