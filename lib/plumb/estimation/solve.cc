#include "plumb/estimation/solve.h"

#include "plumb/core/error.h"

namespace plumb::estimation {

void Solve(ceres::Problem& problem, bool rough, const CalibrationOptions& options,
           FitReport& fit) {
  ceres::Solver::Options solver_options;
  solver_options.linear_solver_type = ceres::DENSE_QR;
  solver_options.max_num_iterations = options.max_iterations;
  solver_options.function_tolerance = rough ? kRoughFunctionTolerance : options.function_tolerance;
  solver_options.parameter_tolerance = rough ? kRoughParameterTolerance : options.parameter_tolerance;
  solver_options.gradient_tolerance = kGradientTolerance;
  solver_options.num_threads = 1;
  solver_options.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(solver_options, &problem, &summary);
  fit.solver_report = summary.BriefReport();
  fit.iterations += static_cast<int>(summary.iterations.size());
  fit.converged = summary.termination_type == ceres::CONVERGENCE;
  if (!summary.IsSolutionUsable()) throw Error("the solver failed: " + summary.BriefReport());
}

ObservabilityAnalysis AnalyseAt(CalibrationProblem& calibration, ceres::Problem& problem,
                                const CalibrationOptions& options, UnknownColumns& columns,
                                double* cost, std::vector<double>* residuals,
                                Eigen::MatrixXd* jacobian) {
  columns = calibration.Columns(problem);
  ObservabilityInput in;
  in.J = calibration.Jacobian(problem, columns, cost, residuals);
  in.names = columns.names;
  in.values = columns.values;
  in.is_model = columns.is_model;
  in.rank_tolerance = options.rank_tolerance;
  ObservabilityAnalysis out = AnalyseObservability(in);
  if (jacobian != nullptr) *jacobian = std::move(in.J);
  return out;
}

Solution SolveWithGauge(CalibrationProblem& calibration, const CalibrationOptions& options,
                        FitReport& fit) {
  Solution out;
  calibration.SaveValues();
  {
    BuiltProblem first = calibration.Build({});
    Solve(*first.problem, calibration.has_motion(), options, fit);
    UnknownColumns columns;
    double cost = 0;
    const ObservabilityAnalysis analysis =
        AnalyseAt(calibration, *first.problem, options, columns, &cost, nullptr);
    for (int c : analysis.pivots) {
      const ParameterIndex& index = columns.model_index[static_cast<std::size_t>(c)];
      if (index.first >= 0) out.held_parameters.push_back(index);
    }
  }
  if (calibration.has_motion()) calibration.SetMotionWeightsFromSolution();
  if (!out.held_parameters.empty()) calibration.RestoreValues();
  out.all_free = calibration.Build({});
  if (!out.held_parameters.empty()) out.held = calibration.Build(out.held_parameters);
  if (!out.held_parameters.empty() || calibration.has_motion()) {
    Solve(out.fitted(), false, options, fit);
  }
  return out;
}

}  // namespace plumb::estimation
