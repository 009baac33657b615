#include "telltale/fusion/mounting.hpp"

#include <Eigen/Dense>
#include <cmath>
#include <sstream>

namespace telltale::fusion {

std::optional<Eigen::Matrix3d> parse_axis_remap(const std::string& spec) {
  Eigen::Matrix3d m = Eigen::Matrix3d::Zero();
  bool seen[3] = {false, false, false};
  std::stringstream ss(spec);
  std::string item;
  while (std::getline(ss, item, ',')) {
    // "b=[+-]s" with b, s in {x, y, z}
    if (item.size() < 3 || item.size() > 4 || item[1] != '=') return std::nullopt;
    const int row = item[0] - 'x';
    double sign = 1.0;
    std::size_t k = 2;
    if (item[k] == '-' || item[k] == '+') sign = item[k++] == '-' ? -1.0 : 1.0;
    if (k + 1 != item.size()) return std::nullopt;
    const int col = item[k] - 'x';
    if (row < 0 || row > 2 || col < 0 || col > 2 || seen[row]) return std::nullopt;
    seen[row] = true;
    m(row, col) = sign;
  }
  if (!(seen[0] && seen[1] && seen[2])) return std::nullopt;
  if (!(m * m.transpose()).isIdentity(1e-12) || std::abs(m.determinant() - 1.0) > 1e-12)
    return std::nullopt;
  return m;
}

}  // namespace telltale::fusion
