#pragma once
/// \file
/// PDR stage of the trunk's pipeline (TrunkPdr): the trunk's recent motion, and a step's length
/// and direction from it. A sensor rigid to the trunk (a belt, the lower back) rides on the body's
/// centre of mass, which over each step vaults over the stance leg as an inverted pendulum: it
/// rises and falls by h while it moves forward by the chord of the leg's arc,
///   L_single = 2 sqrt(2 l h - h^2)          (l: the leg's length, the pendulum's).
/// During double support (both feet down, ~20 % of each step in a normal walk: 10 % of the gait
/// cycle at each of its two foot contacts) the body moves on at the same speed but the pendulum
/// does not describe it, so the step is
///   L = L_single / (1 - double_support).
/// h is measured: the vertical specific force over the step (the attitude filter's up), less its
/// mean over the step (gravity, and whatever acceleration a period leaves, which a bounded motion
/// does not), integrated twice. Over one step the trunk comes back to its height, so the
/// velocity's unknown constant is the one that makes its mean zero, and what is left of a trend
/// in the height is taken off as a line. The step is measured, not modelled from height and
/// cadence: on the IPOL lower-back walks the height-and-cadence laws were 1.2-1.3 x long for
/// walkers whose steps are short for their cadence (docs/pdr.md).
/// What it cannot do: running (the body is lowest, not highest, at mid-stance: a spring, not a
/// pendulum); a sensor away from the trunk (a hand, a pocket on the thigh).
///
/// Memory: fixed-size arrays, no heap.

#include <array>
#include <cstddef>

namespace telltale::fusion {

struct TrunkStepParams {
  /// Leg length (greater trochanter to floor) over body height: 0.53 (Winter's anthropometric
  /// table, Biomechanics and Motor Control of Human Movement).
  double leg_per_height = 0.53;
  /// Share of each step with both feet on the ground in a normal walk (stance 60 % of the gait
  /// cycle, swing 40 %: 2 x 10 % of double support per cycle of two steps).
  double double_support = 0.20;
  /// An excursion beyond this share of the leg is no walking step (a jump, the sensor handled):
  /// the step has no length from the pendulum. A walk's is 2-5 cm on a 0.9 m leg.
  double max_excursion_per_leg = 0.15;
};

/// One step's result: its length (m) and the trunk's mean yaw over it (rad, counter-clockwise
/// about up from the first sample's). `ok` false: too few samples or no pendulum's excursion.
struct TrunkStep {
  double length_m = 0.0;
  double yaw_rad = 0.0;
  bool ok = false;
};

class TrunkMotion {
 public:
  using Params = TrunkStepParams;
  explicit TrunkMotion(Params params = {}) : params_(params) {}
  /// One sample: time (s, increasing), the specific force along up (m/s^2) and the yaw (rad).
  void add(double t_s, double vertical_m_s2, double yaw_rad);
  /// The step between t0_s and t1_s (the heel strikes that close the step before and this one)
  /// of a walker of height_m. The samples must still be held (kRing: 5 s at 400 Hz).
  [[nodiscard]] TrunkStep step(double t0_s, double t1_s, double height_m) const;
  static constexpr std::size_t kRing = 2048;

 private:
  Params params_;
  std::array<double, kRing> t_{}, a_{}, yaw_{};
  std::size_t head_ = 0;   ///< next write
  std::size_t count_ = 0;  ///< held samples
};

}  // namespace telltale::fusion
