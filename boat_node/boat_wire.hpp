#pragma once
/// \file
/// The nodes' one wire module: every conversion from a boat's or a wearable's own record to the
/// topic type of idl/telltale.idl it is published as. The shore's side of the same types is
/// shore_server/wire.hpp; tests/unit/boat_wire_test.cpp holds each pair to a round trip across
/// the two (the boat's to_wire, then the shore's from_wire, gives every field back).
///
/// Adding a member to a wire type (a new type on a new topic, idl/README.md) is one edit here on
/// the nodes' side. Live samples, backfill and earlier runs are all filled by these functions:
/// a record read back from the session log goes on the wire exactly as it went live.

#include <cstdint>
#include <string>

#include "session_log.hpp"
#include "telltale.h"
#include "telltale/fusion/pdr.hpp"

namespace telltale::boat {

/// BoatAttitude (telltale_boat_attitude, telltale_boat_backfill) of run `run` (the boot id).
/// leds.level carries the boat's own alarm colour (the shore ignores it: idl/README.md).
void to_wire(const LogRecord& r, const std::string& boat_id, std::uint64_t run,
             msg::BoatAttitude& m);

/// BoatFix (telltale_boat_fix, telltale_boat_fix_backfill) of run `run`.
void to_wire(const FixRecord& r, const std::string& boat_id, std::uint64_t run, msg::BoatFix& m);

/// A wind instrument's reading made the true wind on the boat (telltale/fusion/wind.hpp).
struct WindRecord {
  std::uint64_t seq = 0;
  std::uint64_t t_utc_ns = 0;
  double from_deg = 0.0;
  double speed_m_s = 0.0;  ///< NaN when the instrument gave none
  const char* source = "";
};

/// BoatWind (telltale_boat_wind) of run `run`.
void to_wire(const WindRecord& r, const std::string& boat_id, std::uint64_t run, msg::BoatWind& m);

/// Where the wearable's sensor sits: a phone carried in any pose (the classifier's pose goes on
/// the wire), or strapped to the foot or the trunk (that is the pose: FOOT, TRUNK).
enum class WearableMount { kCarried, kFoot, kTrunk };

/// What a wearable publishes of its dead reckoning, and where its sensor sits.
struct WearableRecord {
  std::uint64_t seq = 0;
  std::uint64_t t_utc_ns = 0;
  fusion::PdrOutput pdr;
  WearableMount mount = WearableMount::kCarried;
};

/// WearableMotion (telltale_wearable_motion): the gait from the cadence class (still at no
/// cadence), the pose from the classifier (foot or trunk for a strapped-on sensor).
void to_wire(const WearableRecord& r, const std::string& athlete_id, msg::WearableMotion& m);

}  // namespace telltale::boat
