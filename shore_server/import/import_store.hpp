#pragma once
/// \file
/// An imported file into the recording: its points become the boat's attitude samples (heel,
/// pitch, heading) and GNSS fixes (position, SOG, COG), so every review, export and manoeuvre
/// route reads them as it reads live data.
///
/// - One transaction per file (Store::write_transaction): a file that fails to parse leaves
///   nothing behind; a binary log cut short or with an unknown row keeps its valid prefix and is
///   marked partial with the reason.
/// - Sessions: the file's points split where they pause longer than the store's session gap;
///   each span joins the boat's sessions it overlaps or touches within the gap (live ones
///   included), else becomes a new session. Samples and fixes are keyed (boat, UTC time) and
///   inserted OR IGNOREd: a file overlapping live data merges by time without duplicates.
/// - Source: the `imports` table keeps per file the boat, format, device, file name, SHA-256 of
///   the content, state, counts and error; `import_sessions` links it to its sessions and
///   `import_events` keeps its events (race timer, line ends, buttons).
/// - The same content for the same boat again is a no-op: the import is done at once with the
///   sessions of the first (`duplicate_of`).
/// - Imported rows carry seq 0 and boot id 0: no boat run's receipts count them.
/// The live writer waits while a file is stored (a 4-hour 2 Hz Atlas CSV: well under a second;
/// the store's queue holds the live samples meanwhile).

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "record.hpp"
#include "store.hpp"

namespace telltale::shore::import {

struct ImportRequest {
  std::string boat_id;
  std::optional<Format> format;  ///< nullopt: detected from the content
  ImportOptions options;
  std::string file_name;  ///< as the user named it (for the record only)
  std::string path;       ///< the content, on disk
};

struct ImportRecord {
  std::int64_t id = 0;
  std::string boat_id;
  std::string state = "running";  ///< running | done | failed
  std::string format;             ///< empty until detected
  std::string device;
  std::string file_name;
  std::string sha256;
  std::uint64_t bytes = 0;       ///< size of the file
  std::uint64_t bytes_read = 0;  ///< progress while running
  std::uint64_t points = 0;      ///< points the file held
  std::uint64_t samples_added = 0;  ///< attitude rows new to the store
  std::uint64_t fixes_added = 0;    ///< fix rows new to the store
  std::uint64_t wind_added = 0;     ///< wind instrument rows new to the store
  std::uint64_t events = 0;
  std::uint64_t skipped = 0;
  std::vector<std::int64_t> sessions;
  std::uint64_t start_ns = 0, end_ns = 0;  ///< time span of the file's points
  std::string error;
  std::string partial;  ///< why only a prefix was kept; empty when the whole file was
  std::int64_t duplicate_of = 0;  ///< the earlier import of the same content, or 0
};

class ImportStore {
 public:
  /// Creates the import tables when missing. Throws StoreError.
  explicit ImportStore(Store& store);

  /// Records a new import as running; returns its id.
  std::int64_t begin(const std::string& boat_id, const std::string& file_name, std::uint64_t bytes);
  /// Stores the file (see the file comment); `progress` is called now and then with the bytes
  /// read. Returns the finished record (done or failed); never throws for bad content.
  ImportRecord run(std::int64_t id, const ImportRequest& request,
                   const std::function<void(std::uint64_t)>& progress = {});
  /// Marks imports still running (a shore stopped in the middle) as failed.
  void fail_unfinished();
  /// An import as recorded; nullopt if there is no such id.
  [[nodiscard]] std::optional<ImportRecord> get(std::int64_t id);
  /// Imports (of one boat, or all), newest first, at most `limit`; `session`: only those that
  /// stored into that session.
  [[nodiscard]] std::vector<ImportRecord> list(const std::optional<std::string>& boat_id,
                                               std::optional<std::int64_t> session,
                                               std::size_t limit);

 private:
  void finish(const ImportRecord& r);
  Store& store_;
};

/// SHA-256 of a file, lowercase hex. Throws std::runtime_error when it cannot be read.
[[nodiscard]] std::string sha256_file(const std::string& path);

}  // namespace telltale::shore::import
