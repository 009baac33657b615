// One GNSS receiver: gpsd (libgps) or NMEA 0183 over serial / UDP (see gnss_input.hpp).
#include "gnss_input.hpp"

#include <gps.h>

#include <chrono>
#include <cmath>
#include <ctime>
#include <limits>
#include <stdexcept>

#include "nmea_gnss.hpp"
#include "nmea_wind.hpp"
#include "shutdown.hpp"

namespace telltale::boat {
namespace {

constexpr std::size_t kMaxQueued = 256;  ///< ~10 s at 25 Hz: the node takes them every sample

double mono_s() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

std::uint16_t parse_port(const std::string& s) {
  std::size_t used = 0;
  unsigned long v = 0;
  try {
    v = std::stoul(s, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != s.size() || s.empty() || v > 65535)
    throw std::invalid_argument("--gnss: bad port '" + s + "'");
  return static_cast<std::uint16_t>(v);
}

}  // namespace

GnssInput::GnssInput(const std::string& spec, RunClock clock, GnssGateParams params)
    : clock_(clock), gate_(params) {
  if (spec == "gpsd" || spec.rfind("gpsd:", 0) == 0) {
    std::string host = "localhost";
    std::string port = DEFAULT_GPSD_PORT;
    if (spec.size() > 5) {
      const std::string rest = spec.substr(5);
      const auto colon = rest.rfind(':');
      host = colon == std::string::npos ? rest : rest.substr(0, colon);
      if (colon != std::string::npos) port = std::to_string(parse_port(rest.substr(colon + 1)));
      if (host.empty()) host = "localhost";
    }
    describe_ = "gpsd:" + host + ":" + port;
    thread_ = std::thread([this, host, port] { run_gpsd(host, port); });
    return;
  }
  if (spec.rfind("nmea:", 0) != 0)
    throw std::invalid_argument(
        "--gnss takes gpsd[:HOST[:PORT]], nmea:DEVICE[@BAUD] or nmea:udp:[ADDR:]PORT, got '" +
        spec + "'");
  const std::string where = spec.substr(5);
  if (where.rfind("udp:", 0) == 0) {
    std::string addr = "127.0.0.1";
    std::string port = where.substr(4);
    if (const auto colon = port.rfind(':'); colon != std::string::npos) {
      addr = port.substr(0, colon);
      port = port.substr(colon + 1);
    }
    auto udp = std::make_unique<sensors::NmeaUdpReader>(addr, parse_port(port));
    port_ = udp->port();
    nmea_ = std::move(udp);
    describe_ = "nmea:udp:" + addr + ":" + std::to_string(port_);
  } else {
    int baud = 4800;
    std::string device = where;
    if (const auto at = where.find('@'); at != std::string::npos) {
      device = where.substr(0, at);
      try {
        baud = std::stoi(where.substr(at + 1));
      } catch (const std::exception&) {
        throw std::invalid_argument("--gnss: bad baud rate in '" + spec + "'");
      }
    }
    if (device.empty()) throw std::invalid_argument("--gnss nmea: needs a device");
    nmea_ = std::make_unique<sensors::NmeaSerialReader>(device, baud);
    describe_ = "nmea:" + device + "@" + std::to_string(baud);
  }
  connected_ = true;
  thread_ = std::thread([this] { run_nmea(); });
}

GnssInput::~GnssInput() {
  stop_ = true;
  if (nmea_) nmea_->stop();
  if (thread_.joinable()) thread_.join();
}

void GnssInput::on_epoch(const sensors::GnssReading& r) {
  const auto fix = [&] {
    std::lock_guard lock(mutex_);
    return gate_.on_epoch(r, mono_s(), clock_.now_ns());
  }();
  if (!fix) return;
  std::lock_guard lock(mutex_);
  if (queue_.size() >= kMaxQueued) {
    queue_.pop_front();
    ++overflows_;
  }
  queue_.push_back(*fix);
}

void GnssInput::run_nmea() {
  sensors::GnssEpochAssembler epochs;
  const auto handler = [&](std::string_view line, sensors::NmeaClock::time_point t) {
    const auto r = sensors::parse_nmea_gnss(line, nmea_->options());
    if (r.status == sensors::NmeaStatus::kUnsupported) {
      // A wind instrument on the same NMEA line (a multiplexer's output): its readings, with the
      // boat clock of their arrival, for the node to make true with its heading and velocity.
      const auto w = sensors::parse_nmea_wind(line, nmea_->options());
      if (w.status == sensors::NmeaStatus::kOk) {
        std::lock_guard lock(mutex_);
        if (wind_.size() >= kMaxQueued) wind_.pop_front();
        wind_.push_back({clock_.now_ns(), w.reading});
      }
      return w.status;
    }
    if (r.status != sensors::NmeaStatus::kOk) return r.status;
    const double ts = std::chrono::duration<double>(t.time_since_epoch()).count();
    if (auto done = epochs.add(r.gnss, ts)) on_epoch(*done);
    return r.status;
  };
  // Short polls: an epoch is complete once the line has been quiet for 25 ms.
  while (!stop_ && nmea_->poll_lines(10, handler)) {
    if (auto done = epochs.flush_if_quiet(mono_s())) on_epoch(*done);
  }
  std::lock_guard lock(mutex_);
  connected_ = false;
}

void GnssInput::run_gpsd(const std::string& host, const std::string& port) {
  while (!stop_) {
    gps_data_t gps{};
    if (gps_open(host.c_str(), port.c_str(), &gps) != 0) {
      for (int i = 0; i < 10 && !stop_; ++i) std::this_thread::sleep_for(std::chrono::milliseconds(100));
      continue;
    }
    gps_stream(&gps, WATCH_ENABLE | WATCH_JSON, nullptr);
    {
      std::lock_guard lock(mutex_);
      connected_ = true;
    }
    int satellites = 0;
    while (!stop_) {
      if (!gps_waiting(&gps, 200000)) continue;
      if (gps_read(&gps, nullptr, 0) < 0) break;  // gpsd went away: reconnect
      if (gps.set & SATELLITE_SET) satellites = gps.satellites_used;
      if (!(gps.set & MODE_SET)) continue;        // not a TPV report
      const gps_fix_t& f = gps.fix;
      sensors::GnssReading r;
      const bool has_pos = f.mode >= MODE_2D && (gps.set & LATLON_SET) && std::isfinite(f.latitude) &&
                           std::isfinite(f.longitude);
      // gpsd's status: dead reckoning, time-only and simulated "fixes" are not measured ones.
      const bool measured = f.status != STATUS_DR && f.status != STATUS_TIME && f.status != STATUS_SIM;
      if (!has_pos || !measured) {
        r.fix = sensors::GnssFixKind::kNone;
      } else if (f.status == STATUS_DGPS_FIX || f.status == STATUS_RTK_FIX ||
                 f.status == STATUS_RTK_FLT) {
        r.fix = sensors::GnssFixKind::kDgnss;
      } else {
        r.fix = f.mode == MODE_2D ? sensors::GnssFixKind::k2D : sensors::GnssFixKind::k3D;
      }
      constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
      r.lat_deg = has_pos ? f.latitude : kNaN;
      r.lon_deg = has_pos ? f.longitude : kNaN;
      r.sog_m_s = (gps.set & SPEED_SET) ? f.speed : kNaN;
      r.cog_deg = (gps.set & TRACK_SET) ? f.track : kNaN;
      r.satellites = satellites;
      r.hdop = std::isfinite(gps.dop.hdop) ? gps.dop.hdop : kNaN;
      r.time_of_day_s = kNaN;
      if ((gps.set & TIME_SET) && f.time.tv_sec > 0) {
        r.utc_ns = static_cast<std::uint64_t>(f.time.tv_sec) * 1000000000ull +
                   static_cast<std::uint64_t>(f.time.tv_nsec);
      }
      on_epoch(r);
    }
    gps_stream(&gps, WATCH_DISABLE, nullptr);
    gps_close(&gps);
    std::lock_guard lock(mutex_);
    connected_ = false;
    if (!stop_) ++reconnects_;
  }
}

void GnssInput::take(std::vector<GnssFix>& out) {
  out.clear();
  std::lock_guard lock(mutex_);
  out.assign(queue_.begin(), queue_.end());
  queue_.clear();
}

void GnssInput::take_wind(std::vector<TimedWind>& out) {
  out.clear();
  std::lock_guard lock(mutex_);
  out.assign(wind_.begin(), wind_.end());
  wind_.clear();
}

GnssInputStats GnssInput::stats() const {
  GnssInputStats s;
  if (nmea_) s.nmea = nmea_->stats();
  std::lock_guard lock(mutex_);
  s.gate = gate_.stats();
  s.gpsd_reconnects = reconnects_;
  s.queue_overflows = overflows_;
  s.clock_offset_s = gate_.clock_offset_s();
  s.connected = connected_;
  return s;
}

}  // namespace telltale::boat
