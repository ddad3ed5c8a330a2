#include "plumb/sim/truth.h"

#include <cmath>
#include <random>

#include "plumb/core/error.h"
#include "plumb/core/units.h"

namespace plumb::sim {

void SetParameter(const model::Model& model, model::ParameterBlocks& theta,
                  const std::string& full_name, double reported_value) {
  if (theta.empty()) theta = model.ZeroParameters();
  if (theta.size() != static_cast<std::size_t>(model.num_terms())) {
    throw Error("parameter blocks have " + std::to_string(theta.size()) + " blocks; model '" +
                model.spec() + "' has " + std::to_string(model.num_terms()));
  }
  const auto where = model.FindParameter(full_name);
  if (!where) throw Error("model '" + model.spec() + "' has no parameter '" + full_name + "'");
  if (!std::isfinite(reported_value)) {
    throw Error("value of '" + full_name + "' must be finite");
  }
  const auto k = static_cast<std::size_t>(where->first);
  const auto i = static_cast<std::size_t>(where->second);
  const auto& info = model.terms()[k].effect->info();
  if (theta[k].size() != static_cast<std::size_t>(info.size())) {
    throw Error("parameter block of '" + info.name + "' has " + std::to_string(theta[k].size()) +
                " values; expected " + std::to_string(info.size()));
  }
  theta[k][i] = reported_value - info.parameters[i].nominal;
}

void SetTruth(SimulationOptions& options, const std::string& name, double reported_value) {
  const std::size_t dot = name.find('.');
  if (name.rfind("imu", 0) != 0 || dot == std::string::npos) {
    SetParameter(options.model, options.truth, name, reported_value);
    return;
  }
  const std::string k = name.substr(3, dot - 3);
  const bool digits = !k.empty() && k.find_first_not_of("0123456789") == std::string::npos;
  const int imu = digits && k.size() < 4 ? std::stoi(k) : 0;
  if (imu < 1 || imu > static_cast<int>(options.board.size())) {
    throw Error(name + ": " + (options.board.empty()
                                   ? std::string("the session has no other IMU")
                                   : "the board has IMU 1 to " +
                                         std::to_string(options.board.size())));
  }
  BoardImuTruth& b = options.board[static_cast<std::size_t>(imu - 1)];
  SetParameter(b.model, b.truth, name.substr(dot + 1), reported_value);
}

model::ParameterBlocks RandomParameters(const model::Model& model, double scale,
                                        std::uint64_t seed) {
  if (!std::isfinite(scale) || scale < 0.0) {
    throw Error("random parameter scale " + Number(scale) + " must be finite and >= 0");
  }
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  model::ParameterBlocks theta = model.ZeroParameters();
  for (std::size_t k = 0; k < theta.size(); ++k) {
    const auto& term = model.terms()[k];
    for (std::size_t i = 0; i < theta[k].size(); ++i) {
      const double draw = normal(rng);  // drawn even when fixed, to keep the sequence stable
      if (!term.fixed[i]) theta[k][i] = scale * term.effect->info().parameters[i].typical * draw;
    }
  }
  return theta;
}

std::vector<BoardImuTruth> RandomBoard(int n_imus, const model::Model& model, double truth_scale,
                                       std::uint64_t seed) {
  if (n_imus < 1 || n_imus > 16) {
    throw Error("a board of " + std::to_string(n_imus) + " IMUs: give 1 to 16");
  }
  // Its own stream: the seed's bits mixed (any fixed map would do), so that the board does not
  // repeat the draws of the noise or of IMU 0's truth made from the same seed.
  std::mt19937_64 rng(seed ^ 0xA0761D6478BD642FULL);
  std::normal_distribution<double> normal(0.0, 1.0);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  auto direction = [&] {
    const double x = normal(rng), y = normal(rng), z = normal(rng);
    return Vec3(x, y, z).normalized();
  };
  std::vector<BoardImuTruth> board;
  for (int k = 1; k < n_imus; ++k) {
    BoardImuTruth b;
    const double angle_deg =
        kBoardRotationMin_deg + (kBoardRotationMax_deg - kBoardRotationMin_deg) * unit(rng);
    const Vec3 axis = direction();
    b.R_b_i = Quat(Eigen::AngleAxisd(angle_deg / units::kDegPerRad, axis));
    const double length_m =
        kBoardLeverArmMin_m + (kBoardLeverArmMax_m - kBoardLeverArmMin_m) * unit(rng);
    b.lever_arm_m = length_m * direction();
    b.time_offset_s = kBoardTimeOffsetMax_s * (2.0 * unit(rng) - 1.0);
    b.model = model;
    b.truth = RandomParameters(model, truth_scale, rng());
    board.push_back(std::move(b));
  }
  return board;
}

}  // namespace plumb::sim
