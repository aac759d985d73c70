#include "server/experiment_store.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <ctime>
#include <filesystem>

#include "io/experiment_folder.hpp"
#include "model/environment_error.hpp"
#include "model/input_error.hpp"
#include "server/journal.hpp"

namespace uphill {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using Kind = ContainedDirectory::Kind;


std::string UtcNow(const char* format) {
  const std::time_t t = std::chrono::system_clock::to_time_t(std::chrono::system_clock::now());
  std::tm tm{};
  gmtime_r(&t, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, format, &tm);
  return buf;
}

std::string KindName(Kind kind) {
  switch (kind) {
    case Kind::kDirectory: return "a folder";
    case Kind::kLink: return "a symbolic link";
    case Kind::kFile: return "a file";
    default: return "not a regular file";
  }
}

void RequireWritable(const std::string& path, const std::string& shown) {
  if (::access(path.c_str(), W_OK | X_OK) != 0)
    throw EnvironmentError(shown + ": the folder cannot be written (" + std::strerror(errno) +
                           "): the server saves every change there");
}

// "EXP" without trailing slashes ("EXP/" names the same folder).
fs::path WithoutTrailingSlash(const std::string& directory) {
  std::string s = directory;
  while (s.size() > 1 && s.back() == '/') s.pop_back();
  return fs::path(s);
}

}  // namespace

std::string ContentHash(const std::string& bytes) {
  std::uint64_t h = 1469598103934665603ull;
  for (unsigned char c : bytes) {
    h ^= c;
    h *= 1099511628211ull;
  }
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(h));
  return buf;
}

ExperimentStore::ExperimentStore(std::string directory) {
  if (directory.empty()) directory = ".";
  // The folder: resolved once, checked now rather than at the first save.
  struct stat st {};
  if (::stat(directory.c_str(), &st) == 0) {
    if (!S_ISDIR(st.st_mode))
      throw EnvironmentError(directory + ": is a file, not a folder (give the experiment's folder)");
    folder_ = std::make_unique<ContainedDirectory>(ContainedDirectory::Open(directory));
    RequireWritable(folder_->path(), directory);
    directory_ = folder_->path();
  } else if (errno == ENOENT) {
    const fs::path path = WithoutTrailingSlash(directory);
    const std::string name = path.filename().string();
    if (name.empty() || name == "." || name == "..") throw EnvironmentError(directory + ": does not exist");
    const std::string parent = path.has_parent_path() ? path.parent_path().string() : ".";
    struct stat parent_st {};
    if (::stat(parent.c_str(), &parent_st) != 0)
      throw EnvironmentError(directory + ": cannot be created: the folder " + parent +
                             (errno == ENOENT ? " does not exist" : std::string(" cannot be read: ") + std::strerror(errno)));
    if (!S_ISDIR(parent_st.st_mode))
      throw EnvironmentError(directory + ": cannot be created: " + parent + " is not a folder");
    parent_ = std::make_unique<ContainedDirectory>(ContainedDirectory::Open(parent));
    RequireWritable(parent_->path(), parent);
    directory_ = (fs::path(parent_->path()) / name).string();
  } else if (errno == ENOTDIR) {
    throw EnvironmentError(directory + ": a part of the path is a file, not a folder");
  } else {
    throw EnvironmentError(directory + ": cannot be opened: " + std::strerror(errno));
  }

  std::optional<std::string> json_text, csv_text, journal_text;
  std::optional<JournalHead> head;
  const std::string journal_path = (fs::path(directory_) / kJournalFile).string();
  std::string notes;  // things worth saying besides the journal's story
  if (folder_) {
    for (const char* name : {kExperimentJsonFile, kMeasurementsCsvFile, kJournalFile, kJournalHeadFile}) {
      const Kind kind = folder_->KindOf(name);
      if (kind != Kind::kAbsent && kind != Kind::kFile)
        throw EnvironmentError((fs::path(directory_) / name).string() + ": is " + KindName(kind) +
                               ", not a regular file: refused (the server reads and writes only regular files "
                               "inside the experiment folder)");
    }
    if (const Kind report = folder_->KindOf("report"); report != Kind::kAbsent && report != Kind::kDirectory)
      notes = "; " + (fs::path(directory_) / "report").string() + " is " + KindName(report) +
              ": the report is neither written nor served until it is a folder";
    json_text = folder_->ReadFile(kExperimentJsonFile, kMaxExperimentFileBytes);
    csv_text = folder_->ReadFile(kMeasurementsCsvFile, kMaxExperimentFileBytes);
    journal_text = folder_->ReadFile(kJournalFile, kMaxJournalBytes);
    if (const auto text = folder_->ReadFile(kJournalHeadFile, 1 << 16)) head = ParseJournalHead(*text);
  }
  json_hash_ = json_text ? ContentHash(*json_text) : "";
  csv_hash_ = csv_text ? ContentHash(*csv_text) : "";
  const auto load_files = [&] {
    const ExperimentFolder folder = ParseExperimentJson(directory_, *json_text);
    std::optional<CsvTable> measurements;
    if (csv_text) measurements = ParseMeasurements(folder, *csv_text);
    return StateFromFolder(folder, measurements);
  };

  const JournalScan scan = ScanJournal(journal_text.value_or(""));
  std::optional<std::string> damage = scan.damage;
  if (!damage && head && scan.format == 2 && head->journal == scan.id && head->seq > scan.last_seq)
    damage = "it ends at entry " + std::to_string(scan.last_seq) + " but entry " + std::to_string(head->seq) +
             " (version " + std::to_string(head->version) + ") was acknowledged (" + kJournalHeadFile +
             "): the journal was cut short";
  const std::int64_t highest_version = std::max(scan.max_version, head ? head->version : std::int64_t{0});
  need_header_ = scan.format != 2;
  journal_id_ = scan.id;
  seq_ = scan.last_seq;

  bool replayed = false;
  if (!damage && !scan.entries.empty()) {
    bool consistent = !json_text;  // no files yet: the journal is all there is
    for (std::size_t k = scan.entries.size(); k-- > 0 && !consistent;) {
      const json& e = scan.entries[k];
      consistent = e.value("json_hash", "") == json_hash_ &&
                   (e.value("csv_hash", "") == csv_hash_ ||
                    (k > 0 && scan.entries[k - 1].value("csv_hash", "") == csv_hash_));
    }
    if (consistent) {
      try {
        for (const json& e : scan.entries) {
          const json inverse = ApplyOperation(state_, e.at("op"));
          version_ = e.at("version").get<std::int64_t>();
          if (e.at("op").at("type") == "snapshot" || inverse.at("type") == "snapshot") {
            undo_.clear();
          } else if (e.value("undo", false)) {
            if (!undo_.empty()) undo_.pop_back();
          } else {
            undo_.push_back(inverse);
            if (undo_.size() > kMaxUndo) undo_.erase(undo_.begin());
          }
        }
        replayed = true;
        need_snapshot_ = need_header_;  // a legacy journal continues as a new format-2 section
        journal_message_ = "replayed " + std::to_string(scan.entries.size()) + " journal entries (version " +
                           std::to_string(version_) + ")";
      } catch (const std::exception& e) {
        damage = std::string("an entry cannot be applied: ") + e.what();
        state_ = ExperimentState();
        undo_.clear();
        version_ = 0;
      }
    } else {
      state_ = load_files();
      LoadCalibrationFiles();
      version_ = highest_version + 1;
      need_snapshot_ = true;
      journal_message_ = "the files were changed outside the server: they win; the journal continues with a "
                         "snapshot of them at the next change";
    }
  } else if (!damage) {
    if (json_text) {
      state_ = load_files();
      LoadCalibrationFiles();
      version_ = highest_version + 1;
      journal_message_ = journal_text ? "opened the files (the journal holds no entries)" : "opened the files (no journal yet)";
    } else {
      version_ = highest_version;
      journal_message_ = "new experiment (nothing written until it is created)";
    }
    need_snapshot_ = true;
  }

  if (damage) {
    // Never trust it: the files are the state, and nothing is rewritten from the journal.
    if (!json_text)
      throw InputError(journal_path, "is damaged (" + *damage + ") and there is no " + kExperimentJsonFile +
                                         " to fall back on: repair the journal, or move it aside to start a new "
                                         "experiment");
    state_ = load_files();
    LoadCalibrationFiles();
    undo_.clear();
    version_ = highest_version + 1;
    need_snapshot_ = true;
    journal_damaged_ = true;
    journal_message_ = "the journal is damaged (" + *damage +
                       "): the files were kept as they are and nothing was rewritten from the journal; the next "
                       "change moves the journal aside and starts a new one";
  } else {
    if (scan.torn_tail) {
      // A line that was being written when the server stopped: never acknowledged, cut off.
      const int fd = folder_->OpenForAppend(kJournalFile);
      const int rc = ::ftruncate(fd, static_cast<off_t>(scan.good_bytes));
      const int saved = errno;
      ::close(fd);
      if (rc != 0) throw EnvironmentError(journal_path + ": cannot cut off an unfinished line: " + std::strerror(saved));
      journal_message_ = "cut off an unfinished (unacknowledged) journal line (" + *scan.torn_tail + "); " + journal_message_;
    }
    // Bring the files up to the journal (a crash may have left them one change behind).
    if (replayed)
      for (const auto& [path, content] : state_.files)
        if (const auto text = folder_ ? folder_->ReadFile(path, kMaxCalibrationFileBytes) : std::nullopt)
          file_hashes_[path] = ContentHash(*text);
    if (replayed && state_.exists &&
        (ContentHash(state_.ExperimentJson()) != json_hash_ || ContentHash(state_.MeasurementsCsv()) != csv_hash_ ||
         CalibrationFilesBehind())) {
      WriteFiles();
      journal_message_ += "; rewrote the files from the journal (they were behind it)";
    }
  }
  recovery_note_ = journal_message_ + notes;
}

ExperimentStore::~ExperimentStore() {
  if (journal_fd_ >= 0) ::close(journal_fd_);
}

StoreSnapshot ExperimentStore::SnapshotLocked() const { return StoreSnapshot{version_, state_, !undo_.empty()}; }

StoreSnapshot ExperimentStore::Get() const {
  std::lock_guard lock(mutex_);
  return SnapshotLocked();
}

const ContainedDirectory* ExperimentStore::folder() const {
  std::lock_guard lock(mutex_);
  return folder_.get();
}

JournalStatus ExperimentStore::journal_status() const {
  std::lock_guard lock(mutex_);
  return {journal_damaged_, journal_message_};
}

void ExperimentStore::CheckVersion(std::int64_t version) const {
  if (version != version_) throw VersionConflict(version, SnapshotLocked());
}

void ExperimentStore::EnsureFolder() {
  if (folder_) return;
  const std::string name = fs::path(directory_).filename().string();
  folder_ = std::make_unique<ContainedDirectory>(parent_->Subdirectory(name, true));
  parent_->Sync();  // the new folder's name survives a crash
  parent_.reset();
}

void ExperimentStore::OpenJournalForWriting() {
  EnsureFolder();
  if (journal_fd_ >= 0 && !need_header_) return;
  if (journal_damaged_) {
    if (folder_->KindOf(kJournalFile) != Kind::kAbsent) {
      const std::string stamp = UtcNow("%Y%m%dT%H%M%SZ");
      std::string aside;
      for (int n = 1;; ++n) {
        aside = "journal.damaged-" + stamp + (n > 1 ? "-" + std::to_string(n) : "") + ".jsonl";
        if (folder_->KindOf(aside) == Kind::kAbsent) break;
      }
      folder_->RenameNoReplace(kJournalFile, aside);
      journal_message_ += "; moved the damaged journal aside to " + aside + " and started a new one";
    }
    journal_damaged_ = false;
    need_header_ = true;
    need_snapshot_ = true;
  }
  if (journal_fd_ < 0) {
    const bool existed = folder_->KindOf(kJournalFile) == Kind::kFile;
    journal_fd_ = folder_->OpenForAppend(kJournalFile);
    if (!existed) folder_->Sync();  // the new file's name must survive a crash too
  }
  if (need_header_) {
    const std::string id = NewJournalId();
    WriteRaw(JournalHeaderLine(id));
    journal_id_ = id;
    seq_ = 0;
    need_header_ = false;
    need_snapshot_ = true;
  }
}

void ExperimentStore::WriteRaw(const std::string& line) {
  const std::string journal_path = (fs::path(directory_) / kJournalFile).string();
  const off_t before = ::lseek(journal_fd_, 0, SEEK_END);
  std::size_t done = 0;
  const auto fail = [&](const char* what) {
    const int saved = errno;
    // Cut the partial line off now; if that fails too, the next start cuts it (a torn line).
    if (before >= 0 && ::ftruncate(journal_fd_, before) != 0) {
    }
    throw EnvironmentError(journal_path + ": " + what + " failed (" + std::strerror(saved) +
                           "): the change was not saved");
  };
  while (done < line.size()) {
    const ssize_t n = ::write(journal_fd_, line.data() + done, line.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) fail("write");
    done += static_cast<std::size_t>(n);
  }
  if (::fsync(journal_fd_) != 0) fail("fsync");
}

void ExperimentStore::Append(json entry) {
  entry["seq"] = seq_ + 1;
  WriteRaw(EncodeJournalLine(entry));
  ++seq_;
}

void ExperimentStore::LoadCalibrationFiles() {
  // The calibration files experiment.json names become part of the state (so that undo and the
  // journal restore them); one that is missing or unreadable is left to the reader that needs it.
  if (!folder_ || !state_.metadata.is_object()) return;
  std::vector<std::string> paths;
  if (state_.metadata.contains("camera") && state_.metadata.at("camera").is_string())
    paths.push_back(state_.metadata.at("camera").get<std::string>());
  if (state_.metadata.contains("scenes") && state_.metadata.at("scenes").is_object())
    for (const auto& [name, path] : state_.metadata.at("scenes").items())
      if (path.is_string()) paths.push_back(path.get<std::string>());
  for (const std::string& path : paths) {
    try {
      CheckRelativePath(path, "path");
      if (const auto text = folder_->ReadFile(path, kMaxCalibrationFileBytes)) {
        state_.files[path] = *text;
        file_hashes_[path] = ContentHash(*text);
      }
    } catch (const std::exception&) {
    }
  }
}

bool ExperimentStore::CalibrationFilesBehind() const {
  for (const auto& [path, content] : state_.files) {
    const auto it = file_hashes_.find(path);
    if (it == file_hashes_.end() || it->second != ContentHash(content)) return true;
  }
  return false;
}

void ExperimentStore::WriteFiles() {
  EnsureFolder();
  // Calibration files first: experiment.json then names files that are there.
  for (const auto& [path, content] : state_.files) {
    const std::string h = ContentHash(content);
    if (const auto it = file_hashes_.find(path); it != file_hashes_.end() && it->second == h) continue;
    const std::size_t slash = path.rfind('/');
    if (slash == std::string::npos) {
      folder_->WriteFileAtomically(path, content);
    } else {
      const ContainedDirectory sub = folder_->Subdirectory(path.substr(0, slash), true);
      sub.WriteFileAtomically(path.substr(slash + 1), content);
    }
    file_hashes_[path] = h;
  }
  const std::string json_text = state_.ExperimentJson();
  const std::string csv_text = state_.MeasurementsCsv();
  // experiment.json first: recovery accepts a new experiment.json with the previous CSV.
  if (const std::string h = ContentHash(json_text); h != json_hash_) {
    folder_->WriteFileAtomically(kExperimentJsonFile, json_text);
    json_hash_ = h;
  }
  if (const std::string h = ContentHash(csv_text); h != csv_hash_) {
    folder_->WriteFileAtomically(kMeasurementsCsvFile, csv_text);
    csv_hash_ = h;
  }
}

void ExperimentStore::WriteHead() {
  try {
    folder_->WriteFileAtomically(kJournalHeadFile, EncodeJournalHead({journal_id_, seq_, version_}));
  } catch (const EnvironmentError&) {
    // The head only lets the next start notice a journal cut short; the change itself is saved.
  }
}

StoreSnapshot ExperimentStore::Commit(const json& op, bool undo) {
  ExperimentState next = state_;
  const json inverse = ApplyOperation(next, op);  // InputError: nothing written
  OpenJournalForWriting();
  if (need_snapshot_) {
    Append({{"version", version_}, {"time", UtcNow("%Y-%m-%dT%H:%M:%SZ")},
            {"op", {{"type", "snapshot"}, {"state", ToJson(state_)}}}, {"undo", false}, {"json_hash", json_hash_},
            {"csv_hash", csv_hash_}});
    need_snapshot_ = false;
  }
  Append({{"version", version_ + 1}, {"time", UtcNow("%Y-%m-%dT%H:%M:%SZ")}, {"op", op}, {"undo", undo},
          {"json_hash", next.exists ? ContentHash(next.ExperimentJson()) : ""},
          {"csv_hash", next.exists ? ContentHash(next.MeasurementsCsv()) : ""}});
  state_ = std::move(next);
  ++version_;
  if (inverse.at("type") == "snapshot") {
    undo_.clear();  // creating the experiment is not undone
  } else if (undo) {
    undo_.pop_back();
  } else {
    undo_.push_back(inverse);
    if (undo_.size() > kMaxUndo) undo_.erase(undo_.begin());
  }
  try {
    WriteFiles();
  } catch (const std::exception& e) {
    throw EnvironmentError(std::string("the change is saved in ") + kJournalFile +
                           " but the experiment files could not be replaced (" + e.what() +
                           "); they are rewritten at the next change or restart");
  }
  WriteHead();
  return SnapshotLocked();
}

StoreSnapshot ExperimentStore::SetMetadata(std::int64_t version, const json& experiment, const std::string& unit) {
  const json metadata = ValidateMetadata(experiment);
  ValidateUnit(unit);
  std::lock_guard lock(mutex_);
  CheckVersion(version);
  return Commit({{"type", "meta"}, {"experiment", metadata}, {"unit", unit}}, false);
}

StoreSnapshot ExperimentStore::AddRow(std::int64_t version, const json& row, std::optional<std::int64_t> index) {
  std::lock_guard lock(mutex_);
  CheckVersion(version);
  if (!state_.exists) throw InputError("experiment", "does not exist yet: create it first");
  Row r = ValidateRow(row, state_);
  r.id = state_.next_id;
  json op = {{"type", "put"}, {"row", ToJson(r)}};
  if (index) op["index"] = *index;
  return Commit(op, false);
}

StoreSnapshot ExperimentStore::AddRows(std::int64_t version, const json& rows) {
  std::lock_guard lock(mutex_);
  CheckVersion(version);
  if (!state_.exists) throw InputError("experiment", "does not exist yet: create it first");
  json ops = json::array();
  std::int64_t id = state_.next_id;
  for (Row& r : ValidateRows(rows, state_)) {
    r.id = id++;
    ops.push_back({{"type", "put"}, {"row", ToJson(r)}});
  }
  return Commit({{"type", "batch"}, {"ops", ops}}, false);
}

StoreSnapshot ExperimentStore::EditRow(std::int64_t version, std::int64_t id, const json& row) {
  std::lock_guard lock(mutex_);
  CheckVersion(version);
  if (state_.IndexOf(id) < 0) throw InputError("row " + std::to_string(id), "does not exist");
  Row r = ValidateRow(row, state_);
  r.id = id;
  return Commit({{"type", "put"}, {"row", ToJson(r)}}, false);
}

StoreSnapshot ExperimentStore::DeleteRow(std::int64_t version, std::int64_t id) {
  std::lock_guard lock(mutex_);
  CheckVersion(version);
  return Commit({{"type", "delete"}, {"id", id}}, false);
}

StoreSnapshot ExperimentStore::SaveCalibrationFile(std::int64_t version, const std::string& role,
                                                   const std::string& name, const std::string& path,
                                                   const std::string& content) {
  std::lock_guard lock(mutex_);
  CheckVersion(version);
  if (!state_.exists) throw InputError("experiment", "does not exist yet: create it first");
  if (content.size() > kMaxCalibrationFileBytes) throw InputError(path, "is too large for a calibration file");
  return Commit({{"type", "file"}, {"role", role}, {"name", name}, {"path", path}, {"content", content}}, false);
}

StoreSnapshot ExperimentStore::Undo(std::int64_t version) {
  std::lock_guard lock(mutex_);
  CheckVersion(version);
  if (undo_.empty()) throw InputError("undo", "nothing to undo");
  return Commit(undo_.back(), true);
}

}  // namespace uphill
