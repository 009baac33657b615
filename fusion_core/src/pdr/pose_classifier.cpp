#include "telltale/fusion/pdr/pose_classifier.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <random>

namespace telltale::fusion {
namespace {

double sigmoid(double x) { return 1.0 / (1.0 + std::exp(-x)); }

}  // namespace

// --- features ---------------------------------------------------------------------------------
void PoseFeatureWindow::pop() {
  const ImuSample& s = buf_[head_];
  const double m = s.acc_body_m_s2.norm();
  sum_f_ -= s.acc_body_m_s2;
  sum_f2_ -= s.acc_body_m_s2.cwiseAbs2();
  sum_m_ -= m;
  sum_m2_ -= m * m;
  if (s.gyro_body_rad_s.allFinite()) {
    sum_w_ -= s.gyro_body_rad_s;
    sum_w2_ -= s.gyro_body_rad_s.cwiseAbs2();
    --gyro_count_;
  }
  head_ = (head_ + 1) % kCapacity;
  --size_;
}

void PoseFeatureWindow::push(const ImuSample& s) {
  while (size_ > 0 && (size_ == kCapacity || buf_[head_].t_s < s.t_s - window_s_)) pop();
  buf_[(head_ + size_) % kCapacity] = s;
  ++size_;
  const double m = s.acc_body_m_s2.norm();
  sum_f_ += s.acc_body_m_s2;
  sum_f2_ += s.acc_body_m_s2.cwiseAbs2();
  sum_m_ += m;
  sum_m2_ += m * m;
  if (s.gyro_body_rad_s.allFinite()) {
    sum_w_ += s.gyro_body_rad_s;
    sum_w2_ += s.gyro_body_rad_s.cwiseAbs2();
    ++gyro_count_;
  }
}

double PoseFeatureWindow::span_s() const {
  if (size_ < 2) return 0.0;
  return buf_[(head_ + size_ - 1) % kCapacity].t_s - buf_[head_].t_s;
}

Eigen::Vector3d PoseFeatureWindow::mean_acc() const {
  return size_ ? Eigen::Vector3d(sum_f_ / static_cast<double>(size_)) : Eigen::Vector3d::Zero();
}

PoseFeatures PoseFeatureWindow::features() const {
  PoseFeatures f;
  if (size_ == 0) return f;
  const double n = static_cast<double>(size_);
  const Eigen::Vector3d mean_f = sum_f_ / n;
  f.acc_energy = std::max(0.0, (sum_f2_ / n - mean_f.cwiseAbs2()).sum());
  const double mean_m = sum_m_ / n;
  f.acc_variance = std::max(0.0, sum_m2_ / n - mean_m * mean_m);
  if (gyro_count_ == 0) {
    f.gyro_variance = std::nan("");
  } else {
    const double ng = static_cast<double>(gyro_count_);
    const Eigen::Vector3d mean_w = sum_w_ / ng;
    f.gyro_variance = std::max(0.0, (sum_w2_ / ng - mean_w.cwiseAbs2()).sum());
  }
  return f;
}

// --- BP network -------------------------------------------------------------------------------
PoseNetwork::Input PoseNetwork::input(const PoseFeatures& f) const {
  // Log features: the variances span three decades between a phone at the ear and a swinging
  // arm, and their ratios (not differences) separate the poses.
  const Input raw(std::log(f.acc_energy + 1e-4), std::log(f.acc_variance + 1e-4),
                  std::log(f.gyro_variance + 1e-6));
  return (raw - in_mean).cwiseQuotient(in_scale);
}

PoseNetwork::Output PoseNetwork::forward(const Input& x) const {
  // Eq. (4): H_j = f(sum_i w_ij x_i - a_j) with a sigmoid f; eq. (5): O_k = sum_j H_j w_jk - b_k.
  const Eigen::Matrix<double, kHidden, 1> h = (w_ih * x + b_h).unaryExpr(&sigmoid);
  return w_ho * h + b_o;
}

std::optional<PhonePose> PoseNetwork::classify(const PoseFeatures& f) const {
  if (!trained) return std::nullopt;
  const Input x = input(f);
  if (!x.allFinite()) return std::nullopt;
  Eigen::Index k = 0;
  forward(x).maxCoeff(&k);
  return static_cast<PhonePose>(k);
}

PoseNetwork train_pose_network(const std::vector<PoseFeatures>& features,
                               const std::vector<PhonePose>& labels, PoseTrainingParams params) {
  PoseNetwork net;
  const std::size_t n = std::min(features.size(), labels.size());
  if (n == 0) return net;
  // Standardisation from the data (log features).
  std::vector<PoseNetwork::Input> raw(n);
  for (std::size_t i = 0; i < n; ++i) raw[i] = net.input(features[i]);
  PoseNetwork::Input mean = PoseNetwork::Input::Zero(), sq = PoseNetwork::Input::Zero();
  for (const auto& r : raw) mean += r;
  mean /= static_cast<double>(n);
  for (const auto& r : raw) sq += (r - mean).cwiseAbs2();
  net.in_mean = mean;
  net.in_scale = (sq / static_cast<double>(n)).cwiseSqrt().cwiseMax(1e-6);
  std::vector<PoseNetwork::Input> x(n);
  for (std::size_t i = 0; i < n; ++i) x[i] = (raw[i] - mean).cwiseQuotient(net.in_scale);

  // Step 1: small random initial weights (seeded; uniform +-0.5 from our own transform).
  std::mt19937_64 rng(params.seed);
  auto uni = [&rng] { return static_cast<double>(rng() >> 11) * 0x1.0p-53 - 0.5; };
  for (int i = 0; i < net.w_ih.size(); ++i) net.w_ih.data()[i] = uni();
  for (int i = 0; i < net.b_h.size(); ++i) net.b_h.data()[i] = uni();
  for (int i = 0; i < net.w_ho.size(); ++i) net.w_ho.data()[i] = uni();
  for (int i = 0; i < net.b_o.size(); ++i) net.b_o.data()[i] = uni();
  std::vector<std::size_t> order(n);
  std::iota(order.begin(), order.end(), 0);
  for (int epoch = 0; epoch < params.epochs; ++epoch) {
    for (std::size_t i = n - 1; i > 0; --i) std::swap(order[i], order[rng() % (i + 1)]);
    for (const std::size_t i : order) {
      // Steps 2-3: forward pass.
      const Eigen::Matrix<double, PoseNetwork::kHidden, 1> h =
          (net.w_ih * x[i] + net.b_h).unaryExpr(&sigmoid);
      const PoseNetwork::Output o = net.w_ho * h + net.b_o;
      // Step 4: error e_k = Y_k - O_k against the one-hot target.
      PoseNetwork::Output e = -o;
      e[static_cast<Eigen::Index>(labels[i])] += 1.0;
      // Steps 5-6 (eqs. (7)-(10)): weights and thresholds along the error gradient.
      const Eigen::Matrix<double, PoseNetwork::kHidden, 1> back =
          (net.w_ho.transpose() * e)
              .cwiseProduct(
                  h.cwiseProduct(Eigen::Matrix<double, PoseNetwork::kHidden, 1>::Ones() - h));
      net.w_ho += params.eta * e * h.transpose();
      net.b_o += params.eta * e;
      net.w_ih += params.eta * back * x[i].transpose();
      net.b_h += params.eta * back;
    }
  }
  net.trained = true;
  return net;
}

Eigen::Matrix3d pose_rotation(PhonePose pose) {
  Eigen::Matrix3d m = Eigen::Matrix3d::Identity();
  if (pose == PhonePose::kCall) m << 0, 0, -1, 0, -1, 0, -1, 0, 0;  // eq. (14)
  if (pose == PhonePose::kPocket) m << 0, 0, -1, 0, 1, 0, 1, 0, 0;  // eq. (15)
  return m;
}

// --- the pose in force --------------------------------------------------------------------------
std::optional<PhonePose> PoseClassifier::classify() const {
  // The classifier sees only the three features of seed 003; the rotation matrices of eqs.
  // (14)-(15) also assume how the phone sits in each pose. We keep the best-scoring pose whose
  // matrix brings the window's mean gravity near the walking frame's up (our addition: without
  // it a pocket taken for a phone call turns the heading upside down).
  if (!net_.trained) return std::nullopt;
  const PoseNetwork::Input x = net_.input(window_.features());
  const Eigen::Vector3d g = window_.mean_acc();
  if (!x.allFinite() || !(g.norm() > 1.0)) return std::nullopt;
  PoseNetwork::Output score = net_.forward(x);
  const double cos_max = std::cos(params_.gravity_deg * M_PI / 180.0);
  for (int k = 0; k < kPoseCount; ++k) {
    Eigen::Index best = 0;
    score.maxCoeff(&best);
    const auto p = static_cast<PhonePose>(best);
    if ((pose_rotation(p) * g).normalized().z() > cos_max) return p;
    score[best] = -std::numeric_limits<double>::infinity();
  }
  return std::nullopt;
}

std::optional<PoseClassifier::Change> PoseClassifier::at_step(bool settling, std::size_t steps) {
  const std::optional<PhonePose> pose = classify();
  if (!pose) {
    if (!known_ && steps >= static_cast<std::size_t>(params_.confirm_steps)) {
      // No classification possible (no gyroscope, or no model): keep the hand-held frame
      // (M = I) rather than holding the track back for ever.
      known_ = true;
    }
    return std::nullopt;
  }
  if (*pose == candidate_) {
    ++candidate_count_;
  } else {
    candidate_ = *pose;
    candidate_count_ = 1;
  }
  // (The fallback is for a pose that changes: the old pose's long run of answers must not end a
  // switch the moment it is detected.)
  const bool same_frame = pose_rotation(candidate_).isApprox(pose_rotation(applied_));
  const int fallback = same_frame ? params_.fallback_same_frame_steps : params_.fallback_steps;
  const bool may_change =
      !known_ || settling || (candidate_ != applied_ && candidate_count_ >= fallback);
  if (candidate_count_ < params_.confirm_steps || !may_change) return std::nullopt;
  const Change change{applied_, candidate_, !known_};
  applied_ = candidate_;
  known_ = true;
  return change;
}

}  // namespace telltale::fusion
