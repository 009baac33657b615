// Speed and course from positions where a log has none (see course_from_positions.hpp).
#include "course_from_positions.hpp"

#include <cmath>

#include "telltale/fusion/geo.hpp"

namespace telltale::shore::import {
namespace {

constexpr double kDeg = M_PI / 180.0;

bool has_position(const ImportPoint& p) {
  return std::isfinite(p.lat_deg) && std::isfinite(p.lon_deg);
}

}  // namespace

void CourseFromPositions::emit(const ImportPoint* before, ImportPoint p, const ImportPoint* after) {
  const bool need = !std::isfinite(p.sog_m_s) || !std::isfinite(p.cog_deg);
  const ImportPoint* a = before && has_position(*before) ? before : nullptr;
  const ImportPoint* b = after && has_position(*after) ? after : nullptr;
  if (need && has_position(p)) {
    // The widest pair of known positions around p within kMaxSpanS: both neighbours, else p and
    // the one that is there.
    const ImportPoint* from = a ? a : &p;
    const ImportPoint* to = b ? b : &p;
    double dt = (static_cast<double>(to->t_utc_ns) - static_cast<double>(from->t_utc_ns)) * 1e-9;
    if (dt > kMaxSpanS && a && b) {  // a gap on one side: the other side alone
      const double da = (static_cast<double>(p.t_utc_ns) - static_cast<double>(a->t_utc_ns)) * 1e-9;
      if (da <= kMaxSpanS) to = &p;
      else from = &p;
      dt = (static_cast<double>(to->t_utc_ns) - static_cast<double>(from->t_utc_ns)) * 1e-9;
    }
    if (dt > 0.0 && dt <= kMaxSpanS) {
      const auto [east, north] = fusion::offset_m(from->lat_deg, from->lon_deg, to->lat_deg, to->lon_deg);
      const double speed = std::hypot(east, north) / dt;
      if (!std::isfinite(p.sog_m_s)) p.sog_m_s = speed;
      if (!std::isfinite(p.cog_deg) && speed >= kMinCourseSpeed) {
        const double c = std::atan2(east, north) / kDeg;
        p.cog_deg = c < 0.0 ? c + 360.0 : c;
      }
    }
  }
  next_.point(p);
}

void CourseFromPositions::point(const ImportPoint& p) {
  if (have_cur_) {
    emit(have_prev_ ? &prev_ : nullptr, cur_, &p);
    prev_ = cur_;
    have_prev_ = true;
  }
  cur_ = p;
  have_cur_ = true;
}

void CourseFromPositions::finish() {
  if (!have_cur_) return;
  emit(have_prev_ ? &prev_ : nullptr, cur_, nullptr);
  have_cur_ = have_prev_ = false;
}

}  // namespace telltale::shore::import
