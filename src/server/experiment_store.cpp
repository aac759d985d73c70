#include "server/experiment_store.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "io/atomic_file.hpp"
#include "io/experiment_folder.hpp"
#include "model/input_error.hpp"

namespace uphill {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

std::optional<std::string> ReadFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return std::nullopt;
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

std::string HashOfFile(const std::string& path) {
  const auto content = ReadFile(path);
  return content ? ContentHash(*content) : "";
}

std::string NowUtc() {
  const std::time_t t = std::chrono::system_clock::to_time_t(std::chrono::system_clock::now());
  std::tm tm{};
  gmtime_r(&t, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &tm);
  return buf;
}

[[noreturn]] void ThrowSystem(const std::string& what, const std::string& path) {
  throw std::runtime_error(what + " " + path + ": " + std::strerror(errno));
}

void FsyncDirectory(const std::string& directory) {
  const int fd = ::open(directory.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) ThrowSystem("open", directory);
  const int rc = ::fsync(fd);
  ::close(fd);
  if (rc != 0) ThrowSystem("fsync", directory);
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

ExperimentStore::ExperimentStore(std::string directory) : directory_(std::move(directory)) {
  const std::string json_path = (fs::path(directory_) / kExperimentJsonFile).string();
  const std::string csv_path = (fs::path(directory_) / kMeasurementsCsvFile).string();
  const std::string journal_path = (fs::path(directory_) / kJournalFile).string();
  json_hash_ = HashOfFile(json_path);
  csv_hash_ = HashOfFile(csv_path);

  // The journal: complete lines only. A last line without its newline was being written when the
  // server stopped; it was never acknowledged, so it is cut off.
  std::vector<json> entries;
  if (const auto text = ReadFile(journal_path)) {
    std::size_t start = 0, good_end = 0;
    int line = 0;
    while (start < text->size()) {
      const std::size_t newline = text->find('\n', start);
      if (newline == std::string::npos) break;  // torn tail
      ++line;
      try {
        entries.push_back(json::parse(text->begin() + start, text->begin() + newline));
      } catch (const json::exception&) {
        throw std::runtime_error(journal_path + ", line " + std::to_string(line) +
                                 ": damaged (not JSON). Move the journal aside to start from the files.");
      }
      start = good_end = newline + 1;
    }
    if (good_end < text->size()) {
      if (::truncate(journal_path.c_str(), static_cast<off_t>(good_end)) != 0) ThrowSystem("truncate", journal_path);
      recovery_note_ = "cut off an unfinished (unacknowledged) journal line; ";
    }
  }

  const bool files_exist = !json_hash_.empty();
  bool files_consistent = !files_exist;  // no files yet: the journal is all there is
  for (std::size_t k = entries.size(); k-- > 0 && !files_consistent;) {
    const json& e = entries[k];
    files_consistent = e.value("json_hash", "") == json_hash_ &&
                       (e.value("csv_hash", "") == csv_hash_ ||
                        (k > 0 && entries[k - 1].value("csv_hash", "") == csv_hash_));
  }
  if (!entries.empty() && files_consistent) {
    try {
      if (entries.front().at("op").at("type") != "snapshot")
        throw std::runtime_error("the first entry is not a snapshot");
      for (const json& e : entries) {
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
    } catch (const std::exception& e) {
      throw std::runtime_error(journal_path + ": cannot be replayed (" + e.what() +
                               "). Move the journal aside to start from the files.");
    }
    need_snapshot_ = false;
    recovery_note_ += "replayed " + std::to_string(entries.size()) + " journal entries (version " +
                      std::to_string(version_) + ")";
    // Bring the files up to the journal (a crash may have left them one change behind).
    if (state_.exists &&
        (ContentHash(state_.ExperimentJson()) != json_hash_ || ContentHash(state_.MeasurementsCsv()) != csv_hash_)) {
      WriteFiles();
      recovery_note_ += "; rewrote the files from the journal";
    }
  } else if (files_exist) {
    state_ = LoadStateFromFiles(directory_);
    version_ = entries.empty() ? 1 : entries.back().value("version", std::int64_t{0}) + 1;
    recovery_note_ += entries.empty() ? "opened the files (no journal yet)"
                                      : "the files were changed outside the server: they win; the journal "
                                        "continues with a snapshot of them at the next change";
  } else {
    recovery_note_ += "new experiment (nothing written until it is created)";
  }
}

ExperimentStore::~ExperimentStore() {
  if (journal_fd_ >= 0) ::close(journal_fd_);
}

StoreSnapshot ExperimentStore::SnapshotLocked() const { return StoreSnapshot{version_, state_, !undo_.empty()}; }

StoreSnapshot ExperimentStore::Get() const {
  std::lock_guard lock(mutex_);
  return SnapshotLocked();
}

void ExperimentStore::CheckVersion(std::int64_t version) const {
  if (version != version_) throw VersionConflict(version, SnapshotLocked());
}

void ExperimentStore::Append(const json& entry) {
  const std::string journal_path = (fs::path(directory_) / kJournalFile).string();
  if (journal_fd_ < 0) {
    fs::create_directories(directory_);
    const bool existed = fs::exists(journal_path);
    journal_fd_ = ::open(journal_path.c_str(), O_WRONLY | O_APPEND | O_CREAT | O_CLOEXEC, 0644);
    if (journal_fd_ < 0) ThrowSystem("open", journal_path);
    if (!existed) FsyncDirectory(directory_);  // the new file's name must survive a crash too
  }
  const std::string line = entry.dump() + "\n";
  const off_t before = ::lseek(journal_fd_, 0, SEEK_END);
  std::size_t done = 0;
  while (done < line.size()) {
    const ssize_t n = ::write(journal_fd_, line.data() + done, line.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      const int saved = errno;
      if (before >= 0 && ::ftruncate(journal_fd_, before) != 0) { /* the torn line is cut on the next start */ }
      errno = saved;
      ThrowSystem("write", journal_path);
    }
    done += static_cast<std::size_t>(n);
  }
  if (::fsync(journal_fd_) != 0) ThrowSystem("fsync", journal_path);
}

void ExperimentStore::WriteFiles() {
  fs::create_directories(directory_);
  const std::string json_text = state_.ExperimentJson();
  const std::string csv_text = state_.MeasurementsCsv();
  // experiment.json first: recovery accepts a new experiment.json with the previous CSV.
  if (const std::string h = ContentHash(json_text); h != json_hash_) {
    WriteFileAtomically((fs::path(directory_) / kExperimentJsonFile).string(), json_text);
    json_hash_ = h;
  }
  if (const std::string h = ContentHash(csv_text); h != csv_hash_) {
    WriteFileAtomically((fs::path(directory_) / kMeasurementsCsvFile).string(), csv_text);
    csv_hash_ = h;
  }
}

StoreSnapshot ExperimentStore::Commit(const json& op, bool undo) {
  ExperimentState next = state_;
  const json inverse = ApplyOperation(next, op);  // InputError: nothing written
  if (need_snapshot_) {
    Append({{"version", version_}, {"time", NowUtc()}, {"op", {{"type", "snapshot"}, {"state", ToJson(state_)}}},
            {"undo", false}, {"json_hash", json_hash_}, {"csv_hash", csv_hash_}});
    need_snapshot_ = false;
  }
  Append({{"version", version_ + 1}, {"time", NowUtc()}, {"op", op}, {"undo", undo},
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
    throw std::runtime_error(std::string("the change is saved in ") + kJournalFile +
                             " but the experiment files could not be replaced (" + e.what() +
                             "); they are rewritten at the next change or restart");
  }
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

StoreSnapshot ExperimentStore::Undo(std::int64_t version) {
  std::lock_guard lock(mutex_);
  CheckVersion(version);
  if (undo_.empty()) throw InputError("undo", "nothing to undo");
  return Commit(undo_.back(), true);
}

}  // namespace uphill
