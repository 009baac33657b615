#pragma once
/// \file
/// PDR stage: the pose classifier (seed 003). Owns the pose feature window, the BP network and
/// the vote that turns its per-step answers into the pose in force (how many identical answers,
/// and when a change is allowed), because every other stage works in that pose's walking frame
/// and must hear of a change at one place. Pose switches (the step waveforms) are the PDR's.

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include "telltale/fusion/imu_sample.hpp"
#include "telltale/fusion/phone_pose.hpp"

namespace telltale::fusion {

/// The three features seed 003 kept after PCA (Table 1), over a sliding time window:
/// acceleration energy = total (3-axis) variance of the specific force, m^2/s^4;
/// acceleration variance = variance of |f|, m^2/s^4; gyro variance = total (3-axis) variance of
/// the angular rate, rad^2/s^2 (NaN when the samples carry no gyro).
struct PoseFeatures {
  double acc_energy = 0.0;
  double acc_variance = 0.0;
  double gyro_variance = 0.0;
};

class PoseFeatureWindow {
 public:
  static constexpr std::size_t kCapacity = 1024;
  explicit PoseFeatureWindow(double window_s = 2.0) : window_s_(window_s) {}
  /// Adds one sample (t strictly increasing, finite acc; gyro may be NaN).
  void push(const ImuSample& s);
  [[nodiscard]] PoseFeatures features() const;
  /// Mean specific force over the window (sensor frame): the gravity direction, m/s^2.
  [[nodiscard]] Eigen::Vector3d mean_acc() const;
  [[nodiscard]] std::size_t size() const { return size_; }
  [[nodiscard]] double span_s() const;

 private:
  void pop();
  double window_s_;
  std::array<ImuSample, kCapacity> buf_{};
  std::size_t head_ = 0, size_ = 0;
  Eigen::Vector3d sum_f_ = Eigen::Vector3d::Zero(), sum_f2_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d sum_w_ = Eigen::Vector3d::Zero(), sum_w2_ = Eigen::Vector3d::Zero();
  double sum_m_ = 0.0, sum_m2_ = 0.0;
  std::size_t gyro_count_ = 0;
};

// ---------------------------------------------------------------------------------------------
/// BP network of seed 003 (eqs. (4)-(10)): 3 inputs, one sigmoid hidden layer, 4 linear outputs
/// (one per pose, trained toward one-hot targets), pose = the largest output. Hidden size 8: the
/// rules of eqs. (1)-(3) give sqrt(n+m)+a = 3..13, log2(n) = 2, sqrt(nm) = 3.5; 8 was the
/// smallest that reached the training accuracy plateau (tools/train_pose.cpp).
/// Inputs are log features, standardised with the training mean and scale.
struct PoseNetwork {
  static constexpr int kInputs = 3;
  static constexpr int kHidden = 8;
  static constexpr int kOutputs = kPoseCount;
  using Input = Eigen::Matrix<double, kInputs, 1>;
  using Output = Eigen::Matrix<double, kOutputs, 1>;
  Eigen::Matrix<double, kHidden, kInputs> w_ih = Eigen::Matrix<double, kHidden, kInputs>::Zero();
  Eigen::Matrix<double, kHidden, 1> b_h = Eigen::Matrix<double, kHidden, 1>::Zero();
  Eigen::Matrix<double, kOutputs, kHidden> w_ho = Eigen::Matrix<double, kOutputs, kHidden>::Zero();
  Output b_o = Output::Zero();
  Input in_mean = Input::Zero();
  Input in_scale = Input::Ones();
  bool trained = false;

  /// Network input for a feature triple (log, then standardised). NaN gyro variance -> NaN.
  [[nodiscard]] Input input(const PoseFeatures& f) const;
  [[nodiscard]] Output forward(const Input& x) const;
  /// Pose for a feature triple; nullopt when untrained or a feature is not finite.
  [[nodiscard]] std::optional<PhonePose> classify(const PoseFeatures& f) const;
};

/// Deterministic back-propagation training (seed 003, steps 1-7): per-sample gradient descent on
/// the squared error with learning rate `eta`, samples visited in a seeded shuffled order each
/// epoch. Sets the input standardisation from the data.
struct PoseTrainingParams {
  int epochs = 400;
  double eta = 0.05;
  std::uint64_t seed = 1;
};
[[nodiscard]] PoseNetwork train_pose_network(const std::vector<PoseFeatures>& features,
                                             const std::vector<PhonePose>& labels,
                                             PoseTrainingParams params = {});

/// Seed 003 eqs. (14)-(15): v_walking = M v_sensor for a pose (identity for hand-held, arm swing).
[[nodiscard]] Eigen::Matrix3d pose_rotation(PhonePose pose);

struct PoseClassifierParams {
  double window_s = 2.0;      ///< pose feature window, s
  double gravity_deg = 45.0;  ///< a pose whose M does not bring gravity this close to the
                              ///< walking frame's up is not plausible
  int confirm_steps = 3;      ///< identical classifications before the pose changes
  int fallback_steps = 10;    ///< identical answers that change the pose without a switch
  /// The same between poses with one walking frame (hand-held and arm swing: no re-orientation
  /// for the waveforms to see). Fewer are needed: no frame turns with a wrong answer, and until
  /// the change the old pose's walking-direction correction is applied to the new pose's steps
  /// (~10 deg after an arm swing, measured).
  int fallback_same_frame_steps = 5;
};

/// The pose in force: classified at every step, changed when an answer is confirmed.
class PoseClassifier {
 public:
  using Params = PoseClassifierParams;
  /// A confirmed pose (possibly the one in force: a switch that ends where it began).
  struct Change {
    PhonePose from = PhonePose::kHandHeld;
    PhonePose to = PhonePose::kHandHeld;
    bool first = false;  ///< no pose was known before
  };
  PoseClassifier(Params params, const PoseNetwork& net)
      : params_(params), net_(net), window_(params.window_s) {}
  void push(const ImuSample& s) { window_.push(s); }
  [[nodiscard]] const PoseFeatureWindow& window() const { return window_; }
  /// At a step: classifies the window and votes. A pose can only change around a detected
  /// switch (`settling`: the phone steady again after one; turns fool the gyro-variance
  /// feature), or when one answer persists for fallback_steps; the first pose is the first
  /// confirmed answer. `steps` counted so far: without any answer the hand-held frame is taken
  /// after confirm_steps.
  std::optional<Change> at_step(bool settling, std::size_t steps);
  /// A switch is over: the new pose needs fresh answers.
  void restart_vote() { candidate_count_ = 0; }
  [[nodiscard]] PhonePose pose() const { return applied_; }
  [[nodiscard]] bool known() const { return known_; }
  /// The pose the latest answers give, if any since restart_vote.
  [[nodiscard]] std::optional<PhonePose> candidate() const {
    return candidate_count_ > 0 ? std::optional<PhonePose>(candidate_) : std::nullopt;
  }

 private:
  /// The best-scoring plausible pose for the window, if the network can answer.
  [[nodiscard]] std::optional<PhonePose> classify() const;
  Params params_;
  PoseNetwork net_;
  PoseFeatureWindow window_;
  PhonePose applied_ = PhonePose::kHandHeld;
  PhonePose candidate_ = PhonePose::kHandHeld;
  int candidate_count_ = 0;
  bool known_ = false;
};

}  // namespace telltale::fusion
