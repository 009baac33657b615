#include "import_service.hpp"

#include <unistd.h>

namespace telltale::shore::import {

ImportService::ImportService(Store& store, std::filesystem::path spool_dir, OnChange on_change)
    : store_(store), spool_(std::move(spool_dir)), on_change_(std::move(on_change)) {
  store_.fail_unfinished();
  std::filesystem::create_directories(spool_);
  worker_ = std::thread([this] { worker_loop(); });
}

ImportService::~ImportService() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  cv_.notify_all();
  worker_.join();
  // Queued imports never ran: marked failed now (and at the next start, should this not end).
  store_.fail_unfinished();
  std::error_code ec;
  std::filesystem::remove_all(spool_, ec);
}

std::filesystem::path ImportService::spool_path() {
  std::lock_guard lock(mutex_);
  return spool_ / ("upload-" + std::to_string(::getpid()) + "-" + std::to_string(++next_spool_));
}

std::int64_t ImportService::submit(ImportRequest request, std::uint64_t bytes) {
  const std::int64_t id = store_.begin(request.boat_id, request.file_name, bytes);
  {
    std::lock_guard lock(mutex_);
    progress_[id] = 0;
    queue_.emplace_back(id, std::move(request));
  }
  cv_.notify_all();
  if (on_change_)
    if (auto r = store_.get(id)) on_change_(*r);
  return id;
}

std::optional<ImportRecord> ImportService::status(std::int64_t id) {
  auto r = store_.get(id);
  if (!r) return r;
  std::lock_guard lock(mutex_);
  if (const auto it = progress_.find(id); it != progress_.end() && r->state == "running")
    r->bytes_read = it->second;
  return r;
}

void ImportService::worker_loop() {
  for (;;) {
    std::pair<std::int64_t, ImportRequest> job;
    {
      std::unique_lock lock(mutex_);
      cv_.wait(lock, [&] { return stopping_ || !queue_.empty(); });
      if (stopping_) return;
      job = std::move(queue_.front());
      queue_.pop_front();
    }
    const std::int64_t id = job.first;
    const ImportRecord r = store_.run(id, job.second, [&](std::uint64_t bytes) {
      std::lock_guard lock(mutex_);
      progress_[id] = bytes;
    });
    std::error_code ec;
    std::filesystem::remove(job.second.path, ec);
    {
      std::lock_guard lock(mutex_);
      progress_.erase(id);
    }
    if (on_change_) on_change_(r);
  }
}

}  // namespace telltale::shore::import
