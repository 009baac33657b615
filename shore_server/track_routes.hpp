#pragma once
/// \file
/// Positions in the REST API: a boat's track, a session as GPX 1.1, heel against speed, and the
/// join that puts the fix current at each attitude sample's time beside it (exports, GPX).

#include <httplib.h>

#include <cstdint>
#include <string>
#include <vector>

#include "http_api.hpp"
#include "store.hpp"

namespace telltale::shore {

/// A fix older than this is not "current" at a sample's time (the receiver paused).
inline constexpr std::uint64_t kFixJoinMaxAgeNs = 2000000000ULL;

/// Walks a boat's fixes alongside increasing times, a page at a time.
class FixJoin {
 public:
  FixJoin(Store& store, std::string boat_id, std::uint64_t from_ns, std::uint64_t to_ns);
  /// The latest fix at or before t_ns, not older than kFixJoinMaxAgeNs; nullptr if none. Times
  /// must not decrease between calls.
  const FixSample* at(std::uint64_t t_ns);

 private:
  void refill();
  Store& store_;
  std::string boat_id_;
  std::uint64_t to_ns_;
  std::uint64_t after_ns_;
  std::vector<FixSample> page_;
  std::size_t next_ = 0;  ///< first fix of page_ after the current one
  std::optional<FixSample> current_;
  bool exhausted_ = false;
};

void register_track_routes(httplib::Server& server, ShoreContext& ctx);

}  // namespace telltale::shore
