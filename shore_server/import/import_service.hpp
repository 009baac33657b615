#pragma once
/// \file
/// Runs imports in the background: an upload is spooled to a file, queued, and stored by one
/// worker thread (imports are one transaction each and would wait for each other anyway), while
/// its progress (bytes read) and result are asked for by id. Every import's start and end is
/// handed to `on_change` (the live stream's `import` event). Imports left running by a shore
/// that stopped are marked failed at the next start.

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <filesystem>
#include <functional>
#include <map>
#include <mutex>
#include <optional>
#include <thread>

#include "import_store.hpp"

namespace telltale::shore::import {

class ImportService {
 public:
  using OnChange = std::function<void(const ImportRecord&)>;
  /// Creates the import tables and the spool folder (removed at destruction). Throws StoreError
  /// or std::filesystem::filesystem_error.
  ImportService(Store& store, std::filesystem::path spool_dir, OnChange on_change = {});
  ~ImportService();
  ImportService(const ImportService&) = delete;
  ImportService& operator=(const ImportService&) = delete;

  /// A fresh file name in the spool folder for an upload.
  [[nodiscard]] std::filesystem::path spool_path();
  /// Queues the file at request.path (the service deletes it when done); returns the import id.
  std::int64_t submit(ImportRequest request, std::uint64_t bytes);
  /// The import as it stands: running with its progress, or its result. nullopt: no such id.
  [[nodiscard]] std::optional<ImportRecord> status(std::int64_t id);
  /// See ImportStore::list.
  [[nodiscard]] std::vector<ImportRecord> list(const std::optional<std::string>& boat_id,
                                               std::optional<std::int64_t> session,
                                               std::size_t limit) {
    return store_.list(boat_id, session, limit);
  }

 private:
  void worker_loop();
  ImportStore store_;
  std::filesystem::path spool_;
  OnChange on_change_;
  std::mutex mutex_;
  std::condition_variable cv_;
  std::deque<std::pair<std::int64_t, ImportRequest>> queue_;
  std::map<std::int64_t, std::uint64_t> progress_;  ///< running and queued: bytes read
  std::uint64_t next_spool_ = 0;
  bool stopping_ = false;
  std::thread worker_;
};

}  // namespace telltale::shore::import
