// train_pose: trains the BP pose network of seed 003 on simulated people and calibrates the
// per-pose step-length coefficients, then writes fusion_core/data/pose_bp.txt.
// Deterministic: same binary, same file. Usage: train_pose [OUT.txt]
#include <cstdio>
#include <fstream>
#include <string>

#include "telltale/fusion/pdr.hpp"
#include "telltale/fusion/sim/pose_dataset.hpp"

namespace {

namespace tf = telltale::fusion;

double accuracy(const tf::PoseNetwork& net, const tf::sim::PoseWindowSet& set) {
  std::size_t ok = 0;
  for (std::size_t i = 0; i < set.features.size(); ++i)
    ok += net.classify(set.features[i]) == set.labels[i] ? 1u : 0u;
  return static_cast<double>(ok) / static_cast<double>(set.features.size());
}

}  // namespace

int main(int argc, char** argv) {
  const std::string out = argc > 1 ? argv[1] : "fusion_core/data/pose_bp.txt";
  // Training people: seeds 1..23 (23 x 4 poses x 20 windows = 1840 windows, as in seed 003).
  // Held-out people for the report: seeds 1001..1010 (the tests use the same range).
  const auto train = tf::sim::simulate_pose_windows(1, 23, 20);
  const auto held_out = tf::sim::simulate_pose_windows(1001, 10, 20);
  tf::PoseTrainingParams params;
  params.epochs = 400;
  params.eta = 0.05;
  params.seed = 2016;
  const tf::PoseNetwork net = tf::train_pose_network(train.features, train.labels, params);
  std::fprintf(stderr, "windows: %zu train, %zu held out; accuracy %.4f train, %.4f held out\n",
               train.features.size(), held_out.features.size(), accuracy(net, train),
               accuracy(net, held_out));
  tf::StepLengthModel lengths;
  for (int p = 0; p < tf::kPoseCount; ++p) {
    const auto pose = static_cast<tf::PhonePose>(p);
    const auto walks = tf::sim::simulate_calibration_walks(1, 23, pose, net);
    lengths.abc[static_cast<std::size_t>(p)] =
        tf::calibrate_step_length(walks, lengths.abc[static_cast<std::size_t>(p)]);
    const auto& c = lengths.abc[static_cast<std::size_t>(p)];
    std::fprintf(stderr, "pose %d: L = %.4f h + %.4f f + %.4f (%zu walks)\n", p, c[0], c[1], c[2],
                 walks.size());
  }
  std::ofstream f(out);
  f << tf::format_pdr_model(net, lengths);
  f.close();
  if (!f) {
    std::fprintf(stderr, "train_pose: cannot write %s\n", out.c_str());
    return 1;
  }
  std::fprintf(stderr, "wrote %s\n", out.c_str());
  return 0;
}
