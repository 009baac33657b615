#include "heading_input.hpp"

#include <cmath>
#include <stdexcept>

#include "nmea.hpp"

namespace telltale::boat {

struct HeadingInput::Reader {
  std::unique_ptr<sensors::NmeaStreamReader> stream;
  int port = 0;
  std::thread thread;
};

namespace {
fusion::HeadingFusionParams params_for(std::size_t n) {
  if (n < 1 || n > fusion::kMaxHeadingSensors)
    throw std::invalid_argument("between 1 and 8 heading sensors");
  fusion::HeadingFusionParams p;
  p.sensor_count = static_cast<int>(n);
  // NMEA compasses: ~0.5 deg noise, ~0.1 s from measurement to sentence.
  for (std::size_t i = 0; i < n; ++i) {
    p.noise_deg[i] = 0.5;
    p.latency_s[i] = 0.1;
  }
  return p;
}
}  // namespace

HeadingInput::HeadingInput(const std::vector<std::string>& specs, double variation_deg)
    : buffer_(static_cast<int>(specs.size())),
      fusion_(params_for(specs.size())),
      variation_deg_(variation_deg) {
  for (std::size_t i = 0; i < specs.size(); ++i) {
    const std::string& spec = specs[i];
    if (spec.rfind("nmea:", 0) != 0)
      throw std::invalid_argument("--heading takes nmea:DEVICE[@BAUD] or nmea:udp:[ADDR:]PORT");
    const std::string where = spec.substr(5);
    auto r = std::make_unique<Reader>();
    if (where.rfind("udp:", 0) == 0) {
      std::string addr = "127.0.0.1";
      std::string port = where.substr(4);
      if (const auto colon = port.rfind(':'); colon != std::string::npos) {
        addr = port.substr(0, colon);
        port = port.substr(colon + 1);
      }
      auto udp = std::make_unique<sensors::NmeaUdpReader>(
          addr, static_cast<std::uint16_t>(std::stoul(port)));
      r->port = udp->port();
      r->stream = std::move(udp);
    } else {
      int baud = 4800;
      std::string device = where;
      if (const auto at = where.find('@'); at != std::string::npos) {
        device = where.substr(0, at);
        baud = std::stoi(where.substr(at + 1));
      }
      r->stream = std::make_unique<sensors::NmeaSerialReader>(device, baud);
    }
    const int index = static_cast<int>(i);
    r->thread = std::thread([this, index, stream = r->stream.get()] {
      stream->run([this, index](const sensors::NmeaHeading& h,
                                sensors::NmeaClock::time_point when) {
        double deg = h.true_deg;
        if (!std::isfinite(deg) && std::isfinite(h.magnetic_deg) && std::isfinite(variation_deg_))
          deg = std::fmod(h.magnetic_deg + variation_deg_ + 360.0, 360.0);
        if (!std::isfinite(deg)) return;  // magnetic only, no variation configured
        const double t = std::chrono::duration<double>(when - epoch_).count();
        std::lock_guard lock(mutex_);
        buffer_.push(index, t, deg);
        any_reading_ = true;
      });
    });
    readers_.push_back(std::move(r));
  }
}

HeadingInput::~HeadingInput() {
  for (auto& r : readers_) r->stream->stop();
  for (auto& r : readers_) r->thread.join();
}

double HeadingInput::tick(std::chrono::steady_clock::time_point now) {
  std::lock_guard lock(mutex_);
  if (!any_reading_) return std::nan("");
  buffer_.flush_into(fusion_, std::chrono::duration<double>(now - epoch_).count());
  return fusion_.heading_deg();
}

std::uint32_t HeadingInput::sensors_in_use() const {
  std::lock_guard lock(mutex_);
  return static_cast<std::uint32_t>(fusion_.diagnostics().sensors_in_use);
}

bool HeadingInput::degraded() const {
  std::lock_guard lock(mutex_);
  const auto& d = fusion_.diagnostics();
  return d.sensors_excluded != 0 || d.model_mismatch;
}

int HeadingInput::port(std::size_t i) const { return readers_.at(i)->port; }

}  // namespace telltale::boat
