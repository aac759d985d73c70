// ExperimentStore: the one owner of an experiment folder while `uphill serve` runs. Every
// accepted change is durable before it is acknowledged, and edits from several tabs or people
// never silently overwrite each other.
//
// The folder. Its path is resolved once, when the store opens; every file in it is then read
// and written through ContainedDirectory (no symbolic link is followed, at any level). The
// store checks at once that it can work there: the path is a folder (or does not exist yet and
// its parent is a folder), the folder can be written, and experiment.json, measurements.csv and
// the journal are regular files if present. Anything else is refused before the server starts.
//
// Durability. A change is (1) appended to EXP/journal.jsonl and fsynced, then (2) applied in
// memory, then (3) experiment.json and measurements.csv are replaced atomically (write, fsync,
// rename, fsync the folder), then (4) EXP/journal.head.json records the change's entry. Only
// then does the caller acknowledge it. A crash at any point leaves complete files of version N or
// N − 1 and a journal that holds N: on start the journal is replayed and the files rewritten
// (data/README.md, "Journal").
//
// Trust. The journal is checked before it is replayed (server/journal.hpp): every entry has a
// sequence number and a CRC-32, versions follow one another, and the head file names the last
// acknowledged entry. A torn last line that the files show was never acknowledged is cut off.
// Anything else — a missing, repeated or damaged entry, a journal shorter than the head file
// says — is damage: the store then never rewrites the files from the journal. The files are the
// state (the version continues above every version the journal mentions, so an old tab cannot
// overwrite anything), the damage is reported (recovery_note(), journal_status()), and the first
// change moves the damaged journal aside (journal.damaged-<UTC time>.jsonl, kept for a person to
// read) and starts a new one with a snapshot of the files. A damaged journal without the files
// to fall back on cannot be opened (InputError naming the journal and the damage).
//
// Files edited by hand. Each journal entry records hashes (FNV-1a 64) of the two files it
// produced. If experiment.json on disk matches no entry of a sound journal, someone changed the
// folder while the server was not running: the files win, and the next change starts a new
// history in the journal with a snapshot of them (nothing in the files is overwritten by an old
// journal).
//
// Versions. The state has a version, +1 per change, never going back across restarts. Every
// change names the version it was made against; a different one throws VersionConflict (the page
// then shows the current state and keeps the technician's draft), so two tabs cannot overwrite
// each other's rows.
//
// Undo is one linear history for the experiment (all clients): it applies the inverse of the last
// change that has not been undone, as a new change with a new version. Creating the experiment
// cannot be undone. The history survives restarts (it is replayed from the journal).
//
// Thread-safe: one mutex serialises every call.
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "io/contained_directory.hpp"
#include "server/experiment_state.hpp"

namespace uphill {

inline constexpr const char* kJournalFile = "journal.jsonl";
inline constexpr std::size_t kMaxUndo = 500;
// Reading limits: experiment files are small; a journal of a long lab day stays far below this.
inline constexpr std::size_t kMaxExperimentFileBytes = 64u << 20;
inline constexpr std::size_t kMaxJournalBytes = 1u << 30;
inline constexpr std::size_t kMaxCalibrationFileBytes = 1u << 20;

struct StoreSnapshot {
  std::int64_t version = 0;
  ExperimentState state;
  bool can_undo = false;
};

// What the store found in the journal when it opened, and what it did: for the page and the log.
struct JournalStatus {
  bool damaged = false;  // the journal could not be trusted: the files were kept, nothing rewritten
  std::string message;   // one line (e.g. "replayed 12 journal entries (version 14)")
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
  // Opens (or prepares to create) the folder, checks it (above) and recovers its state. Writes
  // nothing, except cutting off a torn, unacknowledged last journal line. Throws EnvironmentError
  // for a folder it cannot work in, InputError for an unreadable experiment.json or a damaged
  // journal without files.
  explicit ExperimentStore(std::string directory);
  ~ExperimentStore();
  ExperimentStore(const ExperimentStore&) = delete;
  ExperimentStore& operator=(const ExperimentStore&) = delete;

  StoreSnapshot Get() const;

  // Each change: throws VersionConflict, InputError (the request's content: nothing is written),
  // or EnvironmentError (a system call failed; the message says what was kept).
  StoreSnapshot SetMetadata(std::int64_t version, const nlohmann::json& experiment, const std::string& unit);
  // index: position among the rows (default: at the end).
  StoreSnapshot AddRow(std::int64_t version, const nlohmann::json& row, std::optional<std::int64_t> index = {});
  // Rows pasted or imported, after the others, as one change (one undo removes them all). Every
  // row is validated first: FieldErrors names each refused one, and then none is added.
  StoreSnapshot AddRows(std::int64_t version, const nlohmann::json& rows);
  StoreSnapshot EditRow(std::int64_t version, std::int64_t id, const nlohmann::json& row);
  StoreSnapshot DeleteRow(std::int64_t version, std::int64_t id);
  StoreSnapshot Undo(std::int64_t version);
  // A calibration file of the folder (experiment_state.hpp, operation "file"): `content` becomes
  // the file at `path` and `path` the experiment's `camera` (role "camera") or its scene `name`
  // (role "scene"). Journaled, written atomically and undone like a row.
  StoreSnapshot SaveCalibrationFile(std::int64_t version, const std::string& role, const std::string& name,
                                    const std::string& path, const std::string& content);

  // The folder's resolved absolute path.
  const std::string& directory() const { return directory_; }
  // The open folder, or null while it does not exist yet (it is created with the experiment).
  // Valid for the store's lifetime once non-null.
  const ContainedDirectory* folder() const;
  // What opening did, in one line (e.g. "replayed 3 journal entries"), for the server's log.
  const std::string& recovery_note() const { return recovery_note_; }
  JournalStatus journal_status() const;

 private:
  StoreSnapshot SnapshotLocked() const;
  void CheckVersion(std::int64_t version) const;
  StoreSnapshot Commit(const nlohmann::json& op, bool undo);
  void EnsureFolder();
  void OpenJournalForWriting();
  void WriteRaw(const std::string& line);
  void Append(nlohmann::json entry);
  void WriteFiles();
  void WriteHead();
  void LoadCalibrationFiles();
  bool CalibrationFilesBehind() const;

  std::string directory_;
  std::unique_ptr<ContainedDirectory> parent_;  // while the folder does not exist yet
  std::unique_ptr<ContainedDirectory> folder_;
  mutable std::mutex mutex_;
  ExperimentState state_;
  std::int64_t version_ = 0;
  std::vector<nlohmann::json> undo_;  // inverses, last change last
  bool need_snapshot_ = true;         // the journal does not (yet) describe state_
  bool need_header_ = false;          // the journal has no format-2 header yet (new or legacy)
  bool journal_damaged_ = false;      // move the journal aside before writing
  std::string journal_id_;
  std::int64_t seq_ = 0;              // of the last entry written
  std::string json_hash_, csv_hash_;  // of the files as they are on disk ("" = absent)
  std::map<std::string, std::string> file_hashes_;  // of the calibration files on disk
  int journal_fd_ = -1;
  std::string recovery_note_;
  std::string journal_message_;
};

// FNV-1a 64 of the bytes, 16 hex digits (stable across runs and platforms).
std::string ContentHash(const std::string& bytes);

}  // namespace uphill
