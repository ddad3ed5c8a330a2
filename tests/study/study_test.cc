// Sensitivity studies (plumb/study): the study file and its errors, the designs, the seeds,
// runs that reproduce bit for bit, honest sigmas where the fitted model contains the simulated
// one, and the bias a missing effect leaves.
#include <gtest/gtest.h>

#include <cmath>
#include <set>

#include "plumb/core/error.h"
#include "plumb/core/units.h"
#include "plumb/study/run.h"
#include "plumb/study/study.h"
#include "plumb/study/study_file.h"
#include "plumb/study/summary.h"

namespace plumb::study {
namespace {

using nlohmann::json;

std::string ErrorOf(const json& doc) {
  try {
    ParseStudy(doc, "s.json");
  } catch (const std::exception& e) {
    return e.what();
  }
  return "";
}

json Small(int runs = 4) {
  return json{{"name", "t"}, {"seed", 7}, {"runs", runs}, {"design", "grid"},
              {"base", {{"poses", 9}, {"still_s", 3}, {"turn_s", 2}, {"rate_hz", 100}}},
              {"factors", json::array({{{"name", "poses"}, {"levels", {9, 12}}}})}};
}

/// Every run of `p` summarised.
PointSummary RunPoint(const Study& s, const Point& p) {
  std::vector<RunOutcome> runs;
  for (int r = 0; r < s.runs; ++r) runs.push_back(RunOnce(s, p, r));
  return Summarise(p, runs, SensitivityFactors(s));
}

TEST(Study, ErrorsNameTheFileAndTheKey) {
  json bad = Small();
  bad["factors"][0]["name"] = "posses";
  EXPECT_NE(ErrorOf(bad).find("s.json"), std::string::npos);
  EXPECT_NE(ErrorOf(bad).find("factors[0].name"), std::string::npos) << ErrorOf(bad);
  EXPECT_NE(ErrorOf(bad).find("unknown factor 'posses'"), std::string::npos);
  json range = Small();
  range["factors"][0] = {{"name", "still_s"}, {"range", {1, 10}}};
  EXPECT_NE(ErrorOf(range).find("a range needs the latin_hypercube design"), std::string::npos);
  json runs = Small();
  runs["runs"] = 0;
  EXPECT_NE(ErrorOf(runs).find("key 'runs'"), std::string::npos);
  json base = Small();
  base["base"]["schedule"] = "spiral";
  EXPECT_NE(ErrorOf(base).find("base.schedule"), std::string::npos);
  EXPECT_EQ(ErrorOf(Small()), "");
}

// The bias wander levels take a datasheet's units, as the command's --gyro-bi and the Python
// module's gyro_bi do (core/datasheet_level.h): a YAML study written so is the study with the
// SI numbers, point for point.
TEST(Study, WanderLevelsTakeADatasheetsUnits) {
  const std::string path = std::string(PLUMB_SOURCE_DIR) + "/tests/study/data/datasheet_levels.yaml";
  const Study text = ParseStudy(ReadStudyFile(path), path);
  const double deg_per_h = 1.0 / units::kDegPerHourPerRadPerS;
  const double ug_per_sqrt_h = units::kMicroG / units::kSqrtSecondsPerSqrtHour;
  EXPECT_DOUBLE_EQ(text.base.gyro_bi, 4.0 * deg_per_h);
  EXPECT_DOUBLE_EQ(text.base.accel_bi, 40.0 * units::kMicroG);
  EXPECT_DOUBLE_EQ(text.base.accel_rw, 10.0 * ug_per_sqrt_h);
  EXPECT_DOUBLE_EQ(text.base.gyro_rw, 0.5 * deg_per_h / units::kSqrtSecondsPerSqrtHour);
  const json si = {
      {"name", "datasheet levels"}, {"seed", 5}, {"runs", 2}, {"design", "grid"},
      {"base", {{"poses", 9}, {"still_s", 3}, {"turn_s", 2}, {"rate_hz", 100},
                {"accel_rw", text.base.accel_rw}, {"gyro_rw", text.base.gyro_rw},
                {"accel_bi", text.base.accel_bi}, {"gyro_bi", text.base.gyro_bi}}},
      {"fit", {{"wander_levels", "given"}}},
      {"factors", json::array({{{"name", "gyro_bi"},
                                {"levels", {2.0 * deg_per_h, 4e-5, 8.0 * deg_per_h}},
                                {"sigma", 0.5 * deg_per_h}},
                               {{"name", "accel_rw"}, {"levels", {5.0 * ug_per_sqrt_h, 2e-4}}}})}};
  const Study numbers = ParseStudy(si, "s.json");
  ASSERT_EQ(text.factors.size(), 2u);
  for (std::size_t f = 0; f < 2; ++f) {
    EXPECT_EQ(text.factors[f].levels, numbers.factors[f].levels) << text.factors[f].name;
    EXPECT_EQ(text.factors[f].sigma, numbers.factors[f].sigma) << text.factors[f].name;
  }
  const std::vector<Point> points = DesignPoints(text);
  ASSERT_EQ(points.size(), 6u);
  for (const Point& p : points) {
    EXPECT_EQ(p.values, DesignPoints(numbers)[static_cast<std::size_t>(p.index)].values);
    const Base a = Apply(text, p), b = Apply(numbers, p);
    EXPECT_EQ(a.gyro_bi, b.gyro_bi);
    EXPECT_EQ(a.accel_rw, b.accel_rw);
    EXPECT_EQ(a.gyro_rw, b.gyro_rw);
    EXPECT_EQ(a.accel_bi, b.accel_bi);
  }
  // The study as read keeps the text (a sweep's study.json), and reads back the same.
  EXPECT_EQ(text.source["base"]["gyro_bi"], "4 deg/h");
  EXPECT_EQ(ParseStudy(text.source, path).factors[0].levels, text.factors[0].levels);
}

// A level's unit that the level does not take, or text for another key, is an error naming
// the file and the key, with the parser's words (the command's and Python's).
TEST(Study, AWanderLevelsWrongUnitNamesTheFileAndTheKey) {
  json base = Small();
  base["base"]["gyro_bi"] = "4 furlong/h";
  EXPECT_EQ(ErrorOf(base),
            "s.json:key 'base.gyro_bi': unit 'furlong/h' not known here; use one of rad/s, "
            "deg/s, deg/h (got '4 furlong/h')");
  json level = Small();
  level["factors"][0] = {{"name", "accel_bi"}, {"levels", {"40 ug", "4 deg/h"}}};
  EXPECT_EQ(ErrorOf(level),
            "s.json:key 'factors[0].levels[1]': unit 'deg/h' not known here; use one of m/s^2, "
            "ug, mg (got '4 deg/h')");
  json negative = Small();
  negative["factors"][0] = {{"name", "gyro_bi"}, {"levels", {"4 deg/h"}}, {"sigma", "-1 deg/h"}};
  EXPECT_EQ(ErrorOf(negative),
            "s.json:key 'factors[0].sigma': must be a finite number >= 0 (got '-1 deg/h')");
  json flag = Small();
  flag["base"]["accel_rw"] = true;
  EXPECT_EQ(ErrorOf(flag),
            "s.json:key 'base.accel_rw': expected a finite number or a text with a unit "
            "(m/s^3/sqrt(Hz), m/s^2/sqrt(s), ug/sqrt(s), ug/sqrt(h))");
  json other = Small();  // only the wander levels take units
  other["base"]["still_s"] = "3 s";
  EXPECT_EQ(ErrorOf(other), "s.json:key 'base.still_s': expected a finite number");
  try {
    ParseStudy(StudyYamlToJson("name: t\nbase: {gyro_rw: 2 deg/h}\n", "s.yaml"), "s.yaml");
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()),
              "s.yaml:key 'base.gyro_rw': unit 'deg/h' not known here; use one of "
              "rad/s^2/sqrt(Hz), rad/s/sqrt(s), deg/s/sqrt(s), deg/h/sqrt(h) (got '2 deg/h')");
  }
}

TEST(Study, GridOneAtATimeAndLatinHypercube) {
  json doc = Small();
  doc["factors"] = json::array({{{"name", "poses"}, {"levels", {9, 12, 18}}},
                                {{"name", "still_s"}, {"levels", {3, 10}}}});
  const std::vector<Point> grid = DesignPoints(ParseStudy(doc, "s.json"));
  ASSERT_EQ(grid.size(), 6U);
  EXPECT_EQ(grid[1].values, (std::vector<double>{9, 10}));  // last factor fastest
  EXPECT_EQ(grid[5].values, (std::vector<double>{18, 10}));
  doc["design"] = "one_at_a_time";
  const std::vector<Point> oat = DesignPoints(ParseStudy(doc, "s.json"));
  // The base (9, 3), then poses 12, 18 and still_s 10 with the other at the base.
  ASSERT_EQ(oat.size(), 4U);
  EXPECT_EQ(oat[0].values, (std::vector<double>{9, 3}));
  EXPECT_EQ(oat[3].values, (std::vector<double>{9, 10}));
  doc["design"] = {{"latin_hypercube", 10}};
  doc["factors"][1] = {{"name", "still_s"}, {"range", {2, 12}}};
  const std::vector<Point> lhs = DesignPoints(ParseStudy(doc, "s.json"));
  ASSERT_EQ(lhs.size(), 10U);
  std::set<int> strata;
  for (const Point& p : lhs) strata.insert(static_cast<int>(std::floor(p.values[1] - 2.0)));
  EXPECT_EQ(strata.size(), 10U);  // one draw in each tenth of the range
  EXPECT_EQ(DesignPoints(ParseStudy(doc, "s.json"))[3].values, lhs[3].values);  // seeded
}

TEST(Study, SeedsDifferPerPointAndRunAndDoNotChange) {
  EXPECT_NE(RunSeed(1, 0, 0), RunSeed(1, 0, 1));
  EXPECT_NE(RunSeed(1, 0, 1), RunSeed(1, 1, 0));
  EXPECT_NE(RunSeed(1, 0, 0), RunSeed(2, 0, 0));
  // Pinned: a seed that changed between versions would change every stored study's runs.
  EXPECT_EQ(RunSeed(1, 3, 5), 1830763696555688506ULL);
}

TEST(Study, ARunReproducesBitForBit) {
  const Study s = ParseStudy(Small(), "s.json");
  const Point p = DesignPoints(s)[1];
  const RunOutcome a = RunOnce(s, p, 2), b = RunOnce(s, p, 2);
  ASSERT_FALSE(a.failed) << a.failure;
  EXPECT_EQ(a.error, b.error);
  EXPECT_EQ(a.sigma, b.sigma);
  EXPECT_EQ(a.nees, b.nees);
  EXPECT_NE(RunOnce(s, p, 3).error, a.error);
}

TEST(Study, SigmasAreHonestWhereTheFitContainsTheSimulation) {
  // The simulator's default sensor, 12 poses of 5 s, 40 runs: NEES/dof in its band.
  json doc = Small(40);
  doc["base"]["poses"] = 12;
  doc["base"]["still_s"] = 5;
  doc["factors"] = json::array();
  const Study s = ParseStudy(doc, "s.json");
  const PointSummary sum = RunPoint(s, DesignPoints(s).front());
  EXPECT_EQ(sum.failed, 0);
  EXPECT_EQ(sum.nees_dof, 40 * 21);
  EXPECT_GT(sum.nees_per_dof, sum.nees_low);
  EXPECT_LT(sum.nees_per_dof, sum.nees_high);
  // Mean sigma and RMS error agree for every parameter (within the RMS's own spread).
  for (const ParameterSummary& q : sum.parameters) {
    EXPECT_NEAR(q.rms_error / q.mean_sigma, 1.0, 0.45) << q.name;
  }
}

TEST(Study, AMissingEffectShowsAsBias) {
  // A g-sensitive gyroscope (G.zy = 2e-4 rad/s per m/s^2) fitted with the base model: the
  // gyro biases absorb part of it, so NEES rises above its band and chi2/dof with it.
  json doc = Small(10);
  doc["base"]["poses"] = 12;
  doc["simulate"] = "base+gyro_g_sensitivity";
  doc["base"]["truth"] = {{"gyro_g_sensitivity.G.zy", 2e-4}};
  doc["factors"] = json::array();
  const Study s = ParseStudy(doc, "s.json");
  const PointSummary sum = RunPoint(s, DesignPoints(s).front());
  EXPECT_GT(sum.nees_per_dof, sum.nees_high);
  EXPECT_GT(sum.mean_chi2_dof, 2.0);
}

TEST(Study, AnalyticSensitivityAgreesWithMonteCarloFiniteDifferences) {
  // The fit told a gravity about 0.05 m/s^2 below and above the truth (9.7803 at the site), 8 runs
  // each: (mean error at g + 0.05 - mean error at g - 0.05) / 0.1 against the runs' mean
  // analytic d/dg, within 4 of the finite difference's Monte Carlo standard errors.
  json doc = Small(8);
  doc["base"]["poses"] = 12;
  doc["base"]["lat_deg"] = 6.67;
  doc["base"]["lon_deg"] = -1.57;
  doc["base"]["height_m"] = 250;
  const double g = 9.7806849;  // near WGS84 normal gravity there (geo/site.h)
  doc["factors"] = json::array({{{"name", "fit_gravity_m_s2"}, {"levels", {g - 0.05, g + 0.05}}}});
  const Study s = ParseStudy(doc, "s.json");
  ASSERT_EQ(SensitivityFactors(s), std::vector<std::string>{"fit_gravity_m_s2"});
  std::vector<PointSummary> points;
  for (const Point& p : DesignPoints(s)) points.push_back(RunPoint(s, p));
  int compared = 0;
  for (std::size_t i = 0; i < points[0].parameters.size(); ++i) {
    const ParameterSummary& lo = points[0].parameters[i];
    const ParameterSummary& hi = points[1].parameters[i];
    const double fd = (hi.mean_error - lo.mean_error) / 0.1;
    const double se = std::hypot(lo.sd_error, hi.sd_error) / std::sqrt(s.runs) / 0.1;
    const double analytic = 0.5 * (lo.mean_d_dp[0] + hi.mean_d_dp[0]);
    EXPECT_LT(std::abs(fd - analytic), 4.0 * se + 1e-9) << lo.name << ": fd " << fd << ", analytic "
                                                         << analytic << ", se " << se;
    ++compared;
  }
  EXPECT_EQ(compared, 21);
  // The scale: about -F / g per m/s^2.
  EXPECT_NEAR(points[0].parameters[0].mean_d_dp[0], -1.0 / g, 0.05 / g);
}

TEST(Study, TheAssumedLevelAndHeadingAreDifferentiatedOnThePapersMinute) {
  // The paper's minute, tilted 1 deg and turned 5 deg while the fit assumes level, x north:
  // the analytic d/d(level) of the determined accel x combination (g cos(theta) F_xx per
  // radian: about 0.171 per deg) and d/d(heading) of the gyro y one (-Omega_N per radian at
  // 6.67 deg N: -1.264e-6 rad/s per deg) against the Monte Carlo finite difference between
  // the point and the level one (12 runs), within 4 of its standard errors.
  json doc = Small(12);
  doc["base"] = {{"schedule", "paper_static"}, {"still_s", 60}, {"rate_hz", 100},
                 {"lat_deg", 6.67}, {"lon_deg", -1.57}, {"height_m", 250}};
  doc["design"] = "one_at_a_time";
  doc["factors"] = json::array({{{"name", "level_error_deg"}, {"levels", {0, 1}}},
                                {{"name", "heading_error_deg"}, {"levels", {0, 5}}}});
  const Study s = ParseStudy(doc, "s.json");
  ASSERT_EQ(SensitivityFactors(s), (std::vector<std::string>{"level_error_deg", "heading_error_deg"}));
  const std::vector<Point> points = DesignPoints(s);
  ASSERT_EQ(points.size(), 3U);  // the base, level 1, heading 5
  std::vector<PointSummary> sums;
  for (const Point& p : points) sums.push_back(RunPoint(s, p));
  const auto row = [&](const PointSummary& sum, const std::string& prefix) {
    for (const ParameterSummary& q : sum.parameters) {
      if (q.name.rfind(prefix, 0) == 0 && q.name.size() > prefix.size() + 5) return q;
    }
    ADD_FAILURE() << "no combination " << prefix;
    return ParameterSummary{};
  };
  const struct {
    const char* prefix;
    std::size_t point, factor;
    double step, expected;
  } cases[] = {{"accel.bias.x ", 1, 0, 1.0, 0.1707}, {"gyro.bias.y ", 2, 1, 5.0, -1.264e-6}};
  for (const auto& c : cases) {
    const ParameterSummary base = row(sums[0], c.prefix), moved = row(sums[c.point], c.prefix);
    const double analytic = base.mean_d_dp[c.factor];
    EXPECT_NEAR(analytic, c.expected, 0.01 * std::abs(c.expected)) << c.prefix;
    const double fd = (moved.mean_error - base.mean_error) / c.step;
    const double se = std::hypot(base.sd_error, moved.sd_error) / std::sqrt(s.runs) / c.step;
    EXPECT_LT(std::abs(fd - analytic), 4.0 * se + 0.01 * std::abs(analytic))
        << c.prefix << ": fd " << fd << ", analytic " << analytic << ", se " << se;
  }
}

json UncertainGravity(int runs, double sigma) {
  json doc = Small(runs);
  doc["base"]["poses"] = 12;
  doc["base"]["still_s"] = 5;
  doc["base"]["lat_deg"] = 6.67;
  doc["base"]["lon_deg"] = -1.57;
  doc["base"]["height_m"] = 250;
  doc["factors"] = json::array(
      {{{"name", "fit_gravity_m_s2"}, {"levels", {9.7806849}}, {"sigma", sigma}}});
  return doc;
}

TEST(Study, AnUncertainFactorIsDrawnPerRunOnItsOwnStream) {
  const Study s = ParseStudy(UncertainGravity(4, 0.01), "s.json");
  const Point p = DesignPoints(s).front();
  const Point a = DrawUncertainFactors(s, p, 0), b = DrawUncertainFactors(s, p, 1);
  EXPECT_NE(a.values[0], p.values[0]);
  EXPECT_NE(a.values[0], b.values[0]);
  EXPECT_EQ(DrawUncertainFactors(s, p, 0).values, a.values);  // reproducible
  EXPECT_NE(FactorSeed(7, 0, 0), RunSeed(7, 0, 0));
  // The same run without the sigma: the same simulated noise, only the gravity differs, so
  // the error moves by the run's own analytic sensitivity times the draw (to second order).
  const Study fixed = ParseStudy(UncertainGravity(4, 0.0), "s.json");
  for (int run = 0; run < 2; ++run) {
    const RunOutcome drawn = RunOnce(s, p, run), level = RunOnce(fixed, p, run);
    ASSERT_FALSE(drawn.failed || level.failed);
    const double dg = DrawUncertainFactors(s, p, run).values[0] - p.values[0];
    for (std::size_t i = 0; i < 6; ++i) {  // the accelerometer matrix
      EXPECT_NEAR(drawn.error[i] - level.error[i], level.d_dp[0][i] * dg,
                  0.02 * std::abs(level.d_dp[0][i] * dg) + 1e-8)
          << drawn.names[i] << ", run " << run;
    }
  }
  json bad = UncertainGravity(4, 0.01);
  bad["factors"][0]["levels"] = {0};
  EXPECT_NE(ErrorOf(bad).find("needs levels > 0"), std::string::npos) << ErrorOf(bad);
  bad = Small();
  bad["factors"][0]["sigma"] = 1;
  EXPECT_NE(ErrorOf(bad).find("poses is a count"), std::string::npos) << ErrorOf(bad);
}

TEST(Study, TheFirstOrderCovarianceOfAnUncertainFactorMatchesTheMonteCarloSpread) {
  // Gravity known to 0.01 m/s^2 (1e-3 relative, 30 times the scale's noise sigma): over 40
  // runs the scale's error spreads by sqrt(sigma^2 + S 0.01^2 S^T), the first-order
  // prediction from the analytic d/dg, within the Monte Carlo spread of a standard deviation
  // from 40 runs (11 %; 3 of it allowed).
  const Study s = ParseStudy(UncertainGravity(40, 0.01), "s.json");
  const PointSummary sum = RunPoint(s, DesignPoints(s).front());
  const auto cov = FirstOrderCovariance(s, sum);
  ASSERT_EQ(cov.size(), sum.parameters.size());
  for (std::size_t i = 0; i < 3; ++i) {  // accel.matrix.xx, xy, xz: scale and cross terms
    const ParameterSummary& q = sum.parameters[i];
    const double predicted = std::sqrt(q.mean_sigma * q.mean_sigma + cov[i][i]);
    EXPECT_NEAR(q.sd_error / predicted, 1.0, 0.33) << q.name << ": sd " << q.sd_error
                                                   << ", predicted " << predicted;
  }
  EXPECT_GT(std::sqrt(cov[0][0]), 20.0 * sum.parameters[0].mean_sigma);
  // Symmetric, and the scales move together (one gravity scales every axis).
  EXPECT_EQ(cov[0][3], cov[3][0]);
  EXPECT_GT(cov[0][3] / std::sqrt(cov[0][0] * cov[3][3]), 0.99);
  // Without an uncertain factor there is no prediction.
  const Study fixed = ParseStudy(UncertainGravity(1, 0.0), "s.json");
  EXPECT_TRUE(FirstOrderCovariance(fixed, sum).empty());
}

TEST(Study, ThePapersClosedFormsLeaveTheNorthEarthRateInTheXGyroBias) {
  // The seed paper's benchmark closed forms (section 4) at 6.67 deg N: the x gyroscope's bias
  // comes out high by the Earth rate's north component, 7.24e-5 rad/s, run after run.
  json doc = Small(3);
  doc["base"] = {{"schedule", "paper_benchmark"}, {"still_s", 5}, {"turn_s", 3}, {"rate_hz", 100},
                 {"lat_deg", 6.67}, {"lon_deg", -1.57}, {"height_m", 250}};
  doc["fit"] = {{"method", "paper_benchmark"}};
  doc["factors"] = json::array();
  const Study s = ParseStudy(doc, "s.json");
  const PointSummary sum = RunPoint(s, DesignPoints(s).front());
  ASSERT_EQ(sum.failed, 0) << (sum.failures.empty() ? "" : sum.failures.front());
  EXPECT_EQ(sum.nees_dof, 0);  // no sigma, no NEES
  for (const ParameterSummary& q : sum.parameters) {
    if (q.name == "gyro.bias.x") EXPECT_NEAR(q.mean_error, 7.24e-5, 1.5e-5);
  }
  doc["base"]["schedule"] = "multipose";
  EXPECT_NE(ErrorOf(doc).find("paper_benchmark needs the paper_benchmark schedule"), std::string::npos);
}

TEST(Study, TheBiasAMissingEffectLeavesIsPredicted) {
  // A g-sensitive gyroscope (G.zy) fitted with the base model: the analytic bias per unit of
  // G.zy (from the effect's probe columns) against the finite difference of two runs that
  // differ in G.zy only (the same point index and run: the same seed, poses and noise).
  json doc = Small(1);
  doc["base"]["poses"] = 12;
  doc["base"]["lat_deg"] = 6.67;
  doc["simulate"] = "base+gyro_g_sensitivity";
  doc["factors"] = json::array({{{"name", "truth.gyro_g_sensitivity.G.zy"}, {"levels", {0.0}}}});
  const Study s = ParseStudy(doc, "s.json");
  ASSERT_EQ(SensitivityFactors(s), std::vector<std::string>{"truth.gyro_g_sensitivity.G.zy"});
  constexpr double kD = 1e-4;
  for (int run = 0; run < 3; ++run) {
    const RunOutcome minus = RunOnce(s, Point{0, {-kD}}, run);
    const RunOutcome plus = RunOnce(s, Point{0, {kD}}, run);
    ASSERT_FALSE(minus.failed || plus.failed);
    ASSERT_EQ(plus.d_dp.size(), 1U);
    double scale = 0.0, worst = 0.0;
    std::string worst_name;
    for (std::size_t i = 0; i < plus.names.size(); ++i) {
      const double fd = (plus.error[i] - minus.error[i]) / (2.0 * kD);
      const double analytic = 0.5 * (plus.d_dp[0][i] + minus.d_dp[0][i]);
      scale = std::max(scale, std::abs(analytic));
      if (std::abs(fd - analytic) > worst) {
        worst = std::abs(fd - analytic);
        worst_name = plus.names[i];
      }
    }
    EXPECT_LT(worst, 0.05 * scale) << "run " << run << ": " << worst_name << ", scale " << scale;
  }
}

TEST(Study, ASessionIsATemplateOfPosesAndTiming) {
  // Three segments at 100 Hz (t_mid and sample indices), level, then x down, then y down:
  // holds of 2, 3 and 1 s joined by turns lasting the gaps (1 s, and 0.5 s at least).
  const json doc = {{"segments",
                     {{{"begin", 0}, {"end", 200}, {"t_mid_s", 1.0}, {"attitude_quaternion_wxyz", {1, 0, 0, 0}}},
                      {{"begin", 300}, {"end", 600}, {"t_mid_s", 4.5},
                       {"attitude_quaternion_wxyz", {std::sqrt(0.5), 0, std::sqrt(0.5), 0}}},
                      {{"begin", 600}, {"end", 700}, {"t_mid_s", 6.5},
                       {"attitude_quaternion_wxyz", {std::sqrt(0.5), std::sqrt(0.5), 0, 0}}}}}};
  const sim::Schedule sched = TemplateSchedule(doc, "t.json");
  ASSERT_EQ(sched.size(), 5U);  // hold, turn, hold, turn, hold
  EXPECT_NEAR(sched.step_duration_s(0), 2.0, 1e-9);
  EXPECT_NEAR(sched.step_duration_s(1), 1.0, 1e-9);
  EXPECT_NEAR(sched.step_duration_s(2), 3.0, 1e-9);
  EXPECT_NEAR(sched.step_duration_s(3), 0.5, 1e-9);
  EXPECT_NEAR(sched.step_duration_s(4), 1.0, 1e-9);
  EXPECT_LT(sched.end_R_n_b().angularDistance(Quat(std::sqrt(0.5), std::sqrt(0.5), 0, 0)), 1e-9);
  const json bad = {{"segments", {{{"begin", 0}}}}};
  try {
    TemplateSchedule(bad, "t.json");
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("t.json"), std::string::npos) << e.what();
  }
}

TEST(Study, PointsRoundTripThroughJson) {
  const Study s = ParseStudy(Small(2), "s.json");
  const Point p = DesignPoints(s)[0];
  const PointSummary sum = Summarise(p, {RunOnce(s, p, 0), RunOnce(s, p, 1)});
  const json doc = PointJson(s, sum);
  const PointSummary back = PointFromJson(s, doc, "p.json", p);
  EXPECT_EQ(PointJson(s, back), doc);
  EXPECT_EQ(ResultsCsv(s, {back}), ResultsCsv(s, {sum}));
  // Through the file's indented text, as a resume reads it: the same checksum.
  EXPECT_EQ(PointChecksum(json::parse(doc.dump(2))), doc.at("checksum"));
  Study other = s;
  other.source["seed"] = 8;
  EXPECT_THROW(PointFromJson(other, doc, "p.json", p), InputError);
}

// Issue 35 item 4: a point file copied over another (sweep's resume then kept one point twice
// and lost the other, exit 0) or edited is refused, naming the key and what to do.
TEST(Study, ACopiedOrEditedPointIsRefused) {
  const Study s = ParseStudy(Small(2), "s.json");
  const std::vector<Point> points = DesignPoints(s);
  ASSERT_GE(points.size(), 2U);
  const PointSummary first = Summarise(points[0], {RunOnce(s, points[0], 0), RunOnce(s, points[0], 1)});
  const json doc = PointJson(s, first);
  const auto message = [&](const json& d, const Point& as) {
    try {
      PointFromJson(s, d, "points/p.json", as);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_EQ(message(doc, points[1]),
            "points/p.json:key 'point': holds point " + std::to_string(points[0].index) +
                ", not point " + std::to_string(points[1].index) +
                " of the design (a file copied?): remove the file to run point " +
                std::to_string(points[1].index) + " again");
  json edited = doc;
  edited["runs"] = 99;
  EXPECT_EQ(message(edited, points[0]),
            "points/p.json:key 'checksum': does not match the point's content (edited or "
            "damaged): remove the file to run point " + std::to_string(points[0].index) + " again");
  json unsigned_doc = doc;
  unsigned_doc.erase("checksum");
  EXPECT_EQ(message(unsigned_doc, points[0]),
            "points/p.json:key 'checksum': missing (edited, or written by an older plumb): remove "
            "the file to run point " + std::to_string(points[0].index) + " again");
  // A copy re-signed by hand is still another point.
  json resigned = doc;
  resigned["point"] = points[1].index;
  resigned["checksum"] = PointChecksum(resigned);
  EXPECT_NE(message(resigned, points[1]).find("key 'point'"), std::string::npos);
}

}  // namespace
}  // namespace plumb::study
