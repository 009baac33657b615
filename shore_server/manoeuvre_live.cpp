// Live manoeuvres (see manoeuvre_live.hpp).
#include "manoeuvre_live.hpp"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <limits>
#include <numbers>

#include "json_views.hpp"
#include "live_hub.hpp"
#include "manoeuvre_routes.hpp"
#include "telltale/fusion/wind.hpp"

namespace telltale::shore {

namespace {

// A manoeuvre this close to the start of a window that has lost its oldest data is seen through
// a cut window (its entry or its turn's start missing): it was reported while whole.
constexpr double kLeadS = 30.0;
// Heel that stopped this long before the course no longer holds back a manoeuvre's final
// report (a boat whose IMU went quiet still gets its manoeuvres measured).
constexpr double kHeelLagS = 5.0;

// The boat sailed a steady course over [from_s, to_s]: every COG there within `tolerance_deg` of
// their circular mean (true without a COG: a boat too slow for one turns no manoeuvre).
bool steady(const std::vector<fusion::CourseSample>& course, double from_s, double to_s,
            double tolerance_deg) {
  constexpr double kRad = std::numbers::pi / 180.0;
  auto first = course.end(), last = course.end();
  while (last != course.begin() && std::prev(last)->t_s > to_s) --last;
  first = last;
  double sx = 0.0, sy = 0.0;
  while (first != course.begin() && std::prev(first)->t_s >= from_s) {
    --first;
    if (!std::isfinite(first->cog_deg)) continue;
    sx += std::cos(first->cog_deg * kRad);
    sy += std::sin(first->cog_deg * kRad);
  }
  if (sx == 0.0 && sy == 0.0) return true;
  const double mean = std::atan2(sy, sx) / kRad;
  for (auto it = first; it != last; ++it)
    if (std::abs(std::remainder(it->cog_deg - mean, 360.0)) > tolerance_deg) return false;
  return true;
}

double seconds_between(std::uint64_t base_ns, std::uint64_t t_ns) {
  return t_ns >= base_ns ? static_cast<double>(t_ns - base_ns) * 1e-9
                         : -static_cast<double>(base_ns - t_ns) * 1e-9;
}

std::uint64_t at_ns(std::uint64_t base_ns, double t_s) {
  const double ns = std::round(t_s * 1e9);
  if (ns >= 0) return base_ns + static_cast<std::uint64_t>(ns);
  const auto back = static_cast<std::uint64_t>(-ns);
  return back < base_ns ? base_ns - back : 0;
}

}  // namespace

ManoeuvreTracker::ManoeuvreTracker(Sink sink, Config config)
    : sink_(std::move(sink)), config_(config) {}

ManoeuvreTracker::Boat& ManoeuvreTracker::boat(const std::string& id, std::uint64_t t_ns) {
  auto [it, added] = boats_.try_emplace(id);
  if (added) it->second.base_ns = t_ns;
  return it->second;
}

void ManoeuvreTracker::on_fix(const FixSample& fix) {
  Boat& b = boat(fix.boat_id, fix.t_utc_ns);
  double t = seconds_between(b.base_ns, fix.t_utc_ns);
  if (!b.course.empty() && t <= b.course.back().t_s) {
    // A clock that went back further than the window (a boat's clock set anew): start over, or
    // the boat would be deaf until its clock caught up. A sample merely late is dropped: the
    // detector takes time-ordered data.
    if (t >= b.course.back().t_s - config_.window_s) return;
    b = Boat{};
    b.base_ns = fix.t_utc_ns;
    t = 0.0;
  }
  if (!b.course.empty() && t - b.course.back().t_s >= config_.session_gap_s) {
    b.history.clear();  // a new session: its wind is its own
    b.wind_from_deg.reset();
  }
  if (b.course.empty()) b.next_run_s = t + config_.run_every_s;
  b.course.push_back({t, fix.cog_deg, fix.sog_m_s});
  while (b.course.size() > config_.max_fixes || b.course.front().t_s < t - config_.window_s) {
    b.course.pop_front();
    b.trimmed = true;
  }
  if (t >= b.next_run_s) {
    b.next_run_s = t + config_.run_every_s;
    run(fix.boat_id, b);
  }
}

void ManoeuvreTracker::on_attitude(const AttitudeSample& sample) {
  Boat& b = boat(sample.boat_id, sample.t_utc_ns);
  const double t = seconds_between(b.base_ns, sample.t_utc_ns);
  if (!b.heel.empty() && t <= b.heel.back().t_s) {
    if (t >= b.heel.back().t_s - config_.window_s) return;
    b.heel.clear();  // the clock went back: the course starts over with its next fix
  }
  b.heel.push_back({t, sample.heel_deg, sample.pitch_deg});
  while (b.heel.size() > config_.max_attitude || b.heel.front().t_s < t - config_.window_s)
    b.heel.pop_front();
}

void ManoeuvreTracker::on_wind(const WindSample& wind) {
  Boat& b = boat(wind.boat_id, wind.t_utc_ns);
  const double t = seconds_between(b.base_ns, wind.t_utc_ns);
  if (!b.instrument.empty() && t < b.instrument.back().first) b.instrument.clear();  // clock back
  b.instrument.emplace_back(t, wind.from_deg);
  while (b.instrument.size() > kMaxInstrumentReadings ||
         b.instrument.front().first < t - kInstrumentWindS)
    b.instrument.pop_front();
}

std::size_t ManoeuvreTracker::held(const std::string& boat_id) const {
  const auto it = boats_.find(boat_id);
  return it == boats_.end() ? 0 : it->second.course.size() + it->second.heel.size();
}

void ManoeuvreTracker::forget(const std::string& boat_id) { boats_.erase(boat_id); }

void ManoeuvreTracker::retain(const std::function<bool(const std::string&)>& known) {
  std::erase_if(boats_, [&](const auto& e) { return !known(e.first); });
}

void ManoeuvreTracker::release(const std::string& boat_id) {
  const auto it = boats_.find(boat_id);
  if (it == boats_.end()) return;
  Boat& b = it->second;
  std::deque<fusion::CourseSample>().swap(b.course);
  std::deque<fusion::HeelSample>().swap(b.heel);
  std::deque<std::pair<double, double>>().swap(b.instrument);
  b.trimmed = false;  // what comes next starts afresh, as a session does
}

void ManoeuvreTracker::run(const std::string& id, Boat& b) {
  course_buf_.assign(b.course.begin(), b.course.end());
  // Heel older than the course window is of no use to the detector (its grid starts with the
  // course and takes heel up to 1 s old).
  const double start = course_buf_.front().t_s, end = course_buf_.back().t_s;
  heel_buf_.clear();
  for (const auto& h : b.heel)
    if (h.t_s >= start - 1.0) heel_buf_.push_back(h);
  fusion::ManoeuvreOptions options;
  // The wind: the coach's, else the boat's instrument over its last 2 minutes (when it is still
  // reading: none older than the window's end by 2 minutes), else the estimate from its tacks.
  options.wind_from_deg = config_.wind_from_deg ? config_.wind_from_deg : b.wind_from_deg;
  if (!config_.wind_from_deg && !b.instrument.empty() &&
      b.instrument.back().first >= end - kInstrumentWindS) {
    instrument_buf_.clear();
    for (const auto& [t, d] : b.instrument) instrument_buf_.push_back(d);
    if (const auto m = fusion::wind_mean(instrument_buf_)) options.wind_from_deg = m->from_deg;
  }
  const fusion::ManoeuvreReport rep = fusion::analyse_manoeuvres(course_buf_, heel_buf_, options);
  ++runs_;
  const double heel_end = heel_buf_.empty() ? end : heel_buf_.back().t_s;
  // Heel complete up to a grid tick once a sample at or after it is in (the grid takes the latest
  // at or before each tick), so heel a tick behind the course holds nothing back.
  const double data_end = heel_end >= end - kHeelLagS ? std::min(end, heel_end + 0.1) : end;
  const bool quiet = steady(course_buf_, end - kQuietS, end, kQuietDeg);
  for (const auto& m : rep.manoeuvres) {
    if (b.trimmed && m.t0_s < start + kLeadS) continue;
    // The nearest report not yet taken by another manoeuvre of this run: tacks of a tacking
    // duel, 10 s apart, stay apart.
    Seen* same = nullptr;
    for (auto& s : b.seen)
      if (s.run != runs_ && std::abs(s.t0_s - m.t0_s) < kSameManoeuvreS &&
          (!same || std::abs(s.t0_s - m.t0_s) < std::abs(same->t0_s - m.t0_s)))
        same = &s;
    // The windows end 25 s after t0, the course after the turn 15 s after its end: later than
    // that for a long turn (a 720's t0 is half its turning done, its end ~half its duration on).
    const double turn_half = std::isfinite(m.turn_duration_s) ? m.turn_duration_s / 1.6 : 0.0;
    const double windows_end = m.t0_s + std::max(config_.final_after_s, turn_half + 16.0);
    // A turn begun later than 16 s after this one's end changes nothing of it: the detector
    // measures its course after over the 15 s from its padded end (~0.9 s after the turn's) and
    // joins turns less than 3 s apart only. Checked 3 s further, as the course needs ~1 s of a
    // helm's turn to leave kQuietDeg and the detector's rate sees a turn 0.5 s early.
    const double turn_end = m.t0_s + turn_half;
    const bool settled = data_end >= turn_end + 19.0 &&
                         steady(course_buf_, turn_end + 1.0, turn_end + 19.0, kQuietDeg);
    const bool final = data_end >= windows_end &&
                       (settled || quiet || data_end >= m.t0_s + kFinalByS);
    if (same && (same->final || !final)) {
      same->t0_s = m.t0_s;  // follows t0 as it settles, so the next run still matches it
      same->run = runs_;
      continue;
    }
    if (!same) same = &b.seen.emplace_back();
    same->t0_s = m.t0_s;
    same->final = final;
    same->run = runs_;
    sink_({id, m, at_ns(b.base_ns, m.t0_s), final});
    if (final) {
      b.history.push_back(m);
      if (b.history.size() > kMaxHistory) b.history.pop_front();
      const std::vector<fusion::Manoeuvre> h(b.history.begin(), b.history.end());
      b.wind_from_deg = fusion::estimate_wind(h);
    }
  }
  std::erase_if(b.seen, [&](const Seen& s) { return s.t0_s < start; });
}

ManoeuvreLive::ManoeuvreLive(LiveHub& hub, const FleetModel& fleet, double session_gap_s)
    : fleet_(fleet),
      tracker_(
          [&hub](const LiveManoeuvre& lm) {
            nlohmann::json j = manoeuvre_object(lm.manoeuvre, lm.t0_utc_ns);
            j["boat_id"] = lm.boat_id;
            j["final"] = lm.final;
            hub.publish_event("manoeuvre", to_json_text(j), lm.boat_id);
          },
          [session_gap_s] {
            ManoeuvreTracker::Config c;
            c.session_gap_s = session_gap_s;
            return c;
          }()) {}

void ManoeuvreLive::queue_fix(const FixSample& fix) {
  std::lock_guard lock(mutex_);
  if (inbox_.size() >= 50000) inbox_.erase(inbox_.begin(), inbox_.begin() + 10000);
  inbox_.push_back(fix);
  has_fixes_.store(true, std::memory_order_release);
}

void ManoeuvreLive::on_attitude(const AttitudeSample& sample) { tracker_.on_attitude(sample); }

void ManoeuvreLive::queue_wind(const WindSample& wind) {
  std::lock_guard lock(mutex_);
  if (wind_inbox_.size() >= 50000)
    wind_inbox_.erase(wind_inbox_.begin(), wind_inbox_.begin() + 10000);
  wind_inbox_.push_back(wind);
  has_fixes_.store(true, std::memory_order_release);
}

void ManoeuvreLive::take_fixes() {
  // The flag spares the worker the lock for the batches that come with no fix in them.
  if (has_fixes_.load(std::memory_order_acquire)) {
    {
      std::lock_guard lock(mutex_);
      taken_.swap(inbox_);
      wind_taken_.swap(wind_inbox_);
      has_fixes_.store(false, std::memory_order_relaxed);
    }
    // The wind first: a fix may run the detector, which reads the boat's instrument wind.
    for (const auto& w : wind_taken_) tracker_.on_wind(w);
    wind_taken_.clear();
    for (const auto& f : taken_) tracker_.on_fix(f);
    taken_.clear();
  }
  const auto now = std::chrono::steady_clock::now();
  if (now >= next_retain_) {
    next_retain_ = now + std::chrono::minutes(1);
    std::vector<std::string> silent;
    tracker_.retain([&](const std::string& id) {
      const auto view = fleet_.boat(id);
      if (view && view->stale && now - view->last_arrival > std::chrono::seconds(90))
        silent.push_back(id);
      return view.has_value();
    });
    for (const auto& id : silent) tracker_.release(id);
  }
}

}  // namespace telltale::shore
