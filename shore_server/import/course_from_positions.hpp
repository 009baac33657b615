#pragma once
/// \file
/// Speed and course over ground for logs that carry positions only (a watch's or a phone's GPX,
/// an NMEA log with GLL but no VTG): an ImportSink stage between a parser and the store.
///
/// A point without SOG (or COG) gets the velocity of the central difference of its neighbours'
/// positions, (p[i+1] - p[i-1]) / (t[i+1] - t[i-1]): the velocity at the middle point to second
/// order, with the receiver's slowly wandering position error (metres over tens of seconds, fix
/// to fix centimetres) mostly cancelling. The first and last points of a run take the one-sided
/// difference. Neighbours more than kMaxSpanS apart are a gap: no velocity across it. Below
/// kMinCourseSpeed the course is left unknown (a boat that barely moves has no course, as the
/// boat's own GNSS gate says). What the file states is never replaced. One point is held back
/// (memory: three points); finish() passes the last on.

#include "record.hpp"

namespace telltale::shore::import {

class CourseFromPositions : public ImportSink {
 public:
  static constexpr double kMaxSpanS = 10.0;
  static constexpr double kMinCourseSpeed = 0.3;  ///< m/s

  explicit CourseFromPositions(ImportSink& next) : next_(next) {}
  void point(const ImportPoint& p) override;
  void event(const ImportEvent& e) override { next_.event(e); }
  void wind(const ImportWind& w) override { next_.wind(w); }
  void device(std::string_view d) override { next_.device(d); }
  /// The last point held back, with its velocity from the one before it.
  void finish();

 private:
  void emit(const ImportPoint* before, ImportPoint p, const ImportPoint* after);
  ImportSink& next_;
  bool have_prev_ = false, have_cur_ = false;
  ImportPoint prev_, cur_;
};

}  // namespace telltale::shore::import
