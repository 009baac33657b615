#include "telltale/fusion/pdr.hpp"

#include <Eigen/Dense>
#include <cmath>
#include <sstream>

#include "pose_bp_data.hpp"

namespace telltale::fusion {
namespace {

bool gyro_ok(const ImuSample& s) { return s.gyro_body_rad_s.allFinite(); }

}  // namespace

// --- model file -------------------------------------------------------------------------------
std::string format_pdr_model(const PoseNetwork& net, const StepLengthModel& len) {
  std::ostringstream o;
  o.precision(17);
  o << "# Telltale PDR model: BP pose network (seed 003) + step-length coefficients.\n"
       "# Written by tools/train_pose (deterministic); do not edit by hand.\n"
       "# pose order: hand-held call pocket arm-swing\n";
  auto put = [&o](const char* name, const auto& m) {
    o << name << ' ' << m.rows() << ' ' << m.cols();
    for (Eigen::Index r = 0; r < m.rows(); ++r)
      for (Eigen::Index c = 0; c < m.cols(); ++c) o << ' ' << m(r, c);
    o << '\n';
  };
  put("in_mean", net.in_mean);
  put("in_scale", net.in_scale);
  put("w_ih", net.w_ih);
  put("b_h", net.b_h);
  put("w_ho", net.w_ho);
  put("b_o", net.b_o);
  Eigen::Matrix<double, kPoseCount, 3> abc;
  for (int p = 0; p < kPoseCount; ++p)
    abc.row(p) = len.abc[static_cast<std::size_t>(p)].transpose();
  put("step_length_abc", abc);
  return o.str();
}

bool parse_pdr_model(std::string_view text, PoseNetwork& net_out, StepLengthModel& len_out) {
  PoseNetwork net;
  Eigen::Matrix<double, kPoseCount, 3> abc;
  int found = 0;
  std::istringstream in{std::string(text)};
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream ls(line);
    std::string name;
    long rows = 0, cols = 0;
    if (!(ls >> name >> rows >> cols)) return false;
    auto read = [&](auto& m) {
      if (rows != m.rows() || cols != m.cols()) return false;
      for (Eigen::Index r = 0; r < m.rows(); ++r)
        for (Eigen::Index c = 0; c < m.cols(); ++c)
          if (!(ls >> m(r, c)) || !std::isfinite(m(r, c))) return false;
      ++found;
      return true;
    };
    bool ok = false;
    if (name == "in_mean")
      ok = read(net.in_mean);
    else if (name == "in_scale")
      ok = read(net.in_scale);
    else if (name == "w_ih")
      ok = read(net.w_ih);
    else if (name == "b_h")
      ok = read(net.b_h);
    else if (name == "w_ho")
      ok = read(net.w_ho);
    else if (name == "b_o")
      ok = read(net.b_o);
    else if (name == "step_length_abc")
      ok = read(abc);
    if (!ok) return false;
  }
  if (found != 7) return false;
  net.trained = true;
  net_out = net;
  for (int p = 0; p < kPoseCount; ++p)
    len_out.abc[static_cast<std::size_t>(p)] = abc.row(p).transpose();
  return true;
}

namespace {
struct Builtin {
  PoseNetwork net;
  StepLengthModel len;
  Builtin() { (void)parse_pdr_model(kPoseBpText, net, len); }
};
const Builtin& builtin() {
  static const Builtin b;
  return b;
}
}  // namespace

const PoseNetwork& builtin_pose_network() { return builtin().net; }
const StepLengthModel& builtin_step_length_model() { return builtin().len; }

// --- PDR --------------------------------------------------------------------------------------
Pdr::Pdr(Params params, const PoseNetwork& net, const StepLengthModel& lengths)
    : params_(params),
      step_length_(params.step_length, lengths),
      clock_(params.step_clock),
      pose_(params.pose, net),
      recent_(StandLimits{params.stand_still_s, params.stand_gyro_rad_s,
                          params.gyro_bias.acc_std_m_s2}),
      heading_(params.heading),
      walking_(params.walking_direction),
      sensors_(params.gyro_bias, params.calibrate_mag, params.hard_iron),
      acc_bias_(params.acc_bias),
      track_(params.track, params.calibrate_mag),
      switch_(params.pose_switch) {}

const StepDiagnostics& Pdr::step_diagnostics() const { return phone_steps_.diagnostics(); }

void Pdr::count_steps(const ClockStep& step) {
  diag_.filled_steps += static_cast<unsigned>(step.extra);
  out_.steps += static_cast<std::size_t>(step.extra) + 1;
  set_cadence(out_, clock_.cadence().interval_s());
}

void Pdr::detect_switch(double t_prev, double t_s,
                        const std::array<Eigen::Vector3d, 2>& ups_before) {
  switch (switch_.at_step(recent_.step_wave(t_prev, t_s))) {
    case PoseSwitch::Event::kBegan: {
      // The phone may have begun to move a step or two before the waveforms said so: those
      // steps join the switch (re-laid at its end) and the up direction before them is the
      // old pose's.
      const std::size_t back = relay_.begin(ups_before);
      reset_walking_direction();
      ++diag_.switches;
      forget_vertical_field();
      switch_.choose_stand_in(back, params_.walking_direction.straight_deg);
      break;
    }
    case PoseSwitch::Event::kSettling:
      pose_.restart_vote();  // the phone is steady again: fresh answers for the new pose
      break;
    case PoseSwitch::Event::kNone:
      break;
  }
}

void Pdr::classify_pose(double t_s) {
  // Pose: classified at every step (PoseClassifier); a switch that saw no confirmed pose
  // within pose_window_steps keeps the previous one.
  switch_.count_settling_step();
  if (const auto change = pose_.at_step(switch_.settling(), out_.steps)) {
    switch_.end();
    const Eigen::Matrix3d r = pose_rotation(change->to) * pose_rotation(change->from).transpose();
    if (!r.isIdentity(1e-9)) {
      heading_.change_frame(r);  // new walking frame: heading again from the magnetometer
      sum_sin_ = sum_cos_ = 0.0;
      headings_.new_frame(t_s);
    }
    if (change->to != change->from) {
      if (!change->first) ++diag_.pose_changes;
      reset_walking_direction();
      forget_vertical_field();
    }
  }
}

double Pdr::walked_heading() {
  // The heading filter's circular mean over the step (its heading if it had none).
  double heading = heading_.heading_rad();
  if (sum_sin_ != 0.0 || sum_cos_ != 0.0) heading = wrap_2pi(std::atan2(sum_sin_, sum_cos_));
  sum_sin_ = sum_cos_ = 0.0;
  const double yaw_corr =
      walking_.at_step(heading, pose_.pose() == PhonePose::kArmSwing, heading_.state().up);
  if (params_.track.revise && !switch_.switching()) revise_pose_yaw(yaw_corr);
  return wrap_2pi(heading - yaw_corr);
}

void Pdr::on_step(const ClockStep& step) {
  const double t_s = step.t_s, t_prev = step.prev_t_s;
  track_.begin_step();
  const std::array<Eigen::Vector3d, 2> ups_before = switch_.ups();
  count_steps(step);
  acc_bias_.at_step(t_s, sensors_.mag_calibration().offset_uT());
  if (t_prev >= 0.0) detect_switch(t_prev, t_s, ups_before);
  switch_.end_step();
  classify_pose(t_s);
  const double walked_rad = walked_heading();
  lay_step(t_s, t_prev, step.extra, walked_rad, ups_before);
}

void Pdr::lay_step(double t_s, double t_prev, int missed, double walked_rad,
                   const std::array<Eigen::Vector3d, 2>& ups_before) {
  double heading = walked_rad;
  const Eigen::Vector2d step_axis_x = axis_sum_[0], step_axis_z = axis_sum_[1];
  axis_sum_[0].setZero();
  axis_sum_[1].setZero();
  // During a switch the straight heading from before it stands in (PoseSwitch::choose_stand_in).
  const bool replaced = switch_.switching() && switch_.stand_in_rad();
  if (replaced) {
    heading = *switch_.stand_in_rad();
    ++diag_.replaced_headings;
  } else if (!switch_.switching()) {
    switch_.note_heading(heading);
  }
  // Eq. (13) and eq. (11). The first step has no frequency yet: the person's usual walk.
  const double hz = out_.step_hz > 0.0 ? out_.step_hz : 1.8;
  const double step_m = step_length_.step_m(pose_.pose(), hz);
  double len = (1.0 + missed) * step_m;
  out_.last_step_length_m = len;
  heading_.set_speed(step_m * hz);
  out_.distance_m += len;
  if (missed > 0 && !replaced) {
    // The steps a gap held are laid along the heading the gap had part by part (a corner walked
    // while the detector was blind is a corner, not a diagonal): one displacement, the chord.
    const Eigen::Vector2d turn = headings_.gap_turn(t_prev, t_s, 1 + missed);
    heading = wrap_2pi(heading + std::atan2(turn.y(), turn.x()));
    len *= turn.norm();
  }
  if (!pose_.known() || !heading_.initialised()) {
    // At the start the pose (hence the walking frame and the heading) is not known yet: the
    // first steps are laid along the first heading we get (a straight start).
    track_.hold(len);
    return;
  }
  track_.lay(len, heading, !switch_.switching(), sensors_.mag_calibration().offset_uT());
  SwitchStep laid;  // what a later re-laying of this step needs
  laid.length_m = len;
  laid.laid_rad = heading;
  laid.old_frame_rad = walked_rad;
  laid.slot = switch_.slot();
  laid.up = switch_.ups()[switch_.slot()];
  laid.axis_sum = {step_axis_x, step_axis_z};
  book_laid_step(laid, heading, ups_before);
  out_.heading_deg = heading * 180.0 / M_PI;
}

void Pdr::book_laid_step(const SwitchStep& laid, double heading,
                         const std::array<Eigen::Vector3d, 2>& ups_before) {
  const bool switching = switch_.switching();
  if (switching) relay_.add(laid);
  if (!switching && !relay_.empty()) {
    relay_switch_steps(heading, pose_.pose());
    relay_.clear();
  } else if (const auto candidate = pose_.candidate(); switching && candidate) {
    // Meanwhile the switch's steps are laid as the pose the classifier now sees would lay them
    // (again at every step, each time from the latest up direction): a walk may end before the
    // new pose is confirmed (a phone put away on arrival), and its last metres then point
    // where they went, not along the heading from before the switch.
    relay_switch_steps(std::nullopt, *candidate);
  }
  if (!switching) relay_.keep_last(laid, ups_before);
}

void Pdr::forget_vertical_field() {
  acc_bias_.forget(sensors_.last_t_s() + 3.0 * params_.heading.up_tau_s);
}

void Pdr::reset_walking_direction() {
  walking_.reset();
  track_.new_pose();
}

void Pdr::revise_pose_yaw(double corr) {
  const double d = track_.turn_pose(corr);
  if (d == 0.0) return;
  relay_.turn_last(d, track_.pose_steps());
}

void Pdr::relay_switch_steps(std::optional<double> heading_after, PhonePose pose) {
  relay_.relay(track_, switch_.ups(), switch_.stand_in_rad(), heading_after, pose,
               params_.pose_switch.tilt_deg);
}

const PdrOutput& Pdr::update(const ImuSample& raw, const Eigen::Vector3d& mag_uT) {
  ImuSample s;
  Eigen::Vector3d mag;
  if (!sensors_.arrive(raw, mag_uT, diag_, out_, s, mag)) return out_;
  pose_.push(s);
  recent_.push(s);
  // Into the walking frame of the pose in force (eqs. (14)-(15)).
  const Eigen::Matrix3d m = pose_rotation(pose_.pose());
  heading_.update(s.t_s, m * s.gyro_body_rad_s, m * (s.acc_body_m_s2 - acc_bias_.bias_m_s2()),
                  m * mag);
  if (!switch_.switching() && params_.acc_bias.learn && mag.allFinite() && heading_.initialised() &&
      gyro_ok(s) && pose_.pose() != PhonePose::kArmSwing && acc_bias_.settled(s.t_s))
    acc_bias_.add(s.gyro_body_rad_s, m.transpose() * heading_.state().up, mag);
  if (!switch_.switching() && params_.walking_direction.correct && gyro_ok(s)) {
    walking_.add(s.t_s, m * s.acc_body_m_s2, m * s.gyro_body_rad_s, heading_.state().up,
                 pose_.pose() == PhonePose::kArmSwing);
  } else {
    walking_.skip();
  }
  if (mag.allFinite() && heading_.initialised()) {
    // Walking direction of the two forward axes the poses use (sensor x: hand-held, arm swing;
    // sensor -z: call, pocket), from the field and the gyro-tracked up (sensor frame), summed
    // as unit vectors over the step: a switch's steps are re-laid with them (relay_switch_steps).
    const Eigen::Vector3d up = m.transpose() * heading_.state().up;
    const Eigen::Vector3d north = mag - mag.dot(up) * up;
    const Eigen::Vector3d east = north.cross(up);
    const Eigen::Vector3d x = Eigen::Vector3d::UnitX() - up.x() * up;
    const Eigen::Vector3d z = -Eigen::Vector3d::UnitZ() + up.z() * up;
    const Eigen::Vector2d hx(x.dot(east), x.dot(north)), hz(z.dot(east), z.dot(north));
    // A change db of the hard-iron offset turns north toward east by east.db / H (H the
    // horizontal field; |east| = |north| = H here), so every heading grows by east.db / H^2.
    const double h2 = north.squaredNorm();
    if (h2 > 1.0) {
      track_.add_offset_sensitivity(east / h2);
    }
    if (hx.norm() > 1e-9) axis_sum_[0] += hx.normalized();
    if (hz.norm() > 1e-9) axis_sum_[1] += hz.normalized();
  }
  if (heading_.initialised()) {
    const Eigen::Vector2d unit(std::cos(heading_.heading_rad()), std::sin(heading_.heading_rad()));
    sum_sin_ += unit.y();
    sum_cos_ += unit.x();
    headings_.add(s.t_s, unit);
    switch_.add_up(m.transpose() * heading_.state().up);
    if (!out_.step)
      out_.heading_deg = switch_.switching() && switch_.stand_in_rad()
                             ? *switch_.stand_in_rad() * 180.0 / M_PI
                             : heading_.heading_rad() * 180.0 / M_PI;
  }
  // The detectors' events, and the steps the clock reads in them (the pose window's energy
  // tells a gap walked from a stop).
  const PhoneEvents events = phone_steps_.update(s, m.transpose() * heading_.state().up);
  if (events.any()) {
    const auto step = clock_.at_events(events, recent_, pose_.window().features().acc_energy);
    if (step) {
      on_step(*step);
      out_.x_m = track_.x_m();
      out_.y_m = track_.y_m();
      out_.step = true;
    }
  }
  out_.pose = pose_.pose();
  out_.switching = switch_.switching();
  return out_;
}

}  // namespace telltale::fusion
