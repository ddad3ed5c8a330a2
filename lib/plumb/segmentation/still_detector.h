// plumb/segmentation/still_detector.h — finds the still segments of a session.
//
// SPEC section 3: the data is split into still segments (detected, or given) and motion
// between them. The detector is imu_tk's idea (a moving-window variance compared with the
// noise of a still period) with the threshold chosen on a normalised cost instead of a
// hand-tuned multiplier:
//
// 1. Noise. Per-axis noise variance sigma^2, correlation times tau_int and tau_sq
//    (plumb/signal/correlation_time.h) and the mean gyroscope output ("still rate") come from
//    - the first `init_still_s` seconds when given (imu_tk's way; the user vouches for them);
//    - otherwise (the default) a first pass: the stretch of max(min_still_s, 2 windows) that
//      minimises sum_axes log(variance) (scale-free, so axes and sensors of different units
//      weigh alike) seeds a provisional detection with a stricter false-alarm level (1e-6),
//      and the noise is pooled over all the still runs that pass finds. Pooling matters: the
//      quietest stretch alone is biased low (it is the minimum of many), and the noise level
//      differs a little from pose to pose.
// 2. Tests on a centred moving window of n samples (window_s). The samples are read once into
//    blocks of about n / 17 samples (plumb/segmentation/block_moments.h); the window is 17
//    blocks centred on a block and is tested once per block, its verdict applying to the
//    centre block, so boundaries are resolved to 1/17 of a window:
//    - accelerometer: s_a = (1/3) sum_axes var_window / sigma^2. For a still IMU each term is
//      chi^2(nu) / nu with nu = (n - 1) / tau_sq degrees of freedom (correlated samples carry
//      fewer); the mean of the three is approximated as chi^2(nu_s) / nu_s with
//      nu_s = 9 / sum_axes(1 / nu + 1 / nu_0), which folds in the uncertainty of the noise
//      estimate itself (nu_0 = (n_0 - 1) / tau_sq from its n_0 samples).
//    - gyroscope, when present and use_gyro: the same variance statistic, and a mean-rate test
//      d = sum_axes (mean_window - still_rate)^2 / V with
//      V = sigma^2 tau_int (1/n + 1/n_0) + allowance^2, chi^2(3) for a still IMU. This catches
//      slow smooth turns, which leave the window variance unchanged. The allowance covers the
//      still rate changing between poses (Earth rate, g-sensitivity, bias drift).
//    - a window spanning a time gap of over half a window is not still, nor one holding a
//      NaN or infinite sample.
//    The thresholds are exact chi^2 quantiles (Boost.Math, plumb/signal/chi_square.h) at
//    1 - false_alarm / (tests x 17): Bonferroni over the tests and over the 17 overlapping
//    window positions in one window length, so that a still IMU fails any test within a
//    window length of data with probability at most false_alarm — no magic multiple.
// 3. A block is still when the window centred on it passes every test (the first and last
//    half windows take the nearest full window's verdict). Consecutive runs whose samples in
//    between hold the same pose (a still vehicle vibrating in bursts) are joined
//    (join_same_pose). Runs of still samples are trimmed
//    by edge_s at both ends and kept when at least min_still_s long.
//
// The report's notes say where the noise came from and its values, the thresholds, how many
// windows failed each test, how many runs were too short, and which accelerometer-still runs
// only the gyroscope tests rejected (a vibrating table or a hand-held pose shows as gyro
// variance far above the quiet noise; gyro_variance_test = false accepts them).
// Accelerometer-only series are handled (the gyroscope tests are skipped, and a slow turn
// about the vertical cannot then be seen). Cost: one pass over the samples into the blocks
// (plus the series' median sample interval), then O(N / block) work, and the correlation time
// on at most 131072 samples of the still period; memory 96 bytes per block, none per sample.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "plumb/core/imu_series.h"
#include "plumb/core/segment.h"
#include "plumb/core/types.h"

namespace plumb::segmentation {

struct StillDetectorOptions {
  /// Length of the still period at the start of the series used for the noise, s, >= 0;
  /// rounded down to whole blocks. 0 = automatic (pooled over a first pass, see above).
  double init_still_s = 0.0;
  /// Length of the centred moving window, s, > 0; rounded to a whole number of blocks (17 of
  /// them when the window holds at least 17 samples), at least 5 samples.
  double window_s = 1.0;
  /// Probability that a still IMU fails any test within one window length of data, (0, 0.5).
  double false_alarm = 1e-3;
  /// Shortest still segment kept, after trimming, s, >= 0.
  double min_still_s = 2.0;
  /// Margin trimmed at both ends of each still run, s, >= 0.
  double edge_s = 0.2;
  /// Test the gyroscope too when the series has one (both gyroscope tests).
  bool use_gyro = true;
  /// With use_gyro: also apply the gyroscope variance test. Off (the default) keeps only the
  /// mean-rate test, which accepts rotation jitter about a still attitude (a hand or a table
  /// that is not quite still: mikoff's poses show gyro scatter 2-8x the quiet noise while the
  /// accelerometer is still) but still rejects turns. The jitter averages out in the segment
  /// mean, and its extra scatter enters the data-derived noise used for whitening.
  bool gyro_variance_test = false;
  /// Allowance for the still rate changing between poses, gyroscope units (rad/s for SI
  /// series), per axis, >= 0. Negative = automatic: the per-sample noise standard deviation of
  /// the still period on that axis (a steady turn is then caught from about 5 of those, the
  /// square root of the chi^2(3) threshold).
  double rate_allowance = -1.0;
  /// Join consecutive still runs when the samples between them hold the same pose (a still
  /// vehicle vibrating in bursts): equal accelerometer means, no rotation (see
  /// JoinSamePose in join_same_pose.cc for the three chi^2(3) tests).
  bool join_same_pose = true;
  /// Units of the series for the report's notes, e.g. "m/s^2" and "rad/s", or "counts".
  std::string acc_unit = "m/s^2";
  std::string gyr_unit = "rad/s";
};

/// The noise the thresholds were derived from.
struct NoiseEstimate {
  /// The still periods the noise was pooled over (sample ranges; labels empty).
  std::vector<StillSegment> periods;
  std::size_t samples = 0;  ///< samples in those periods, n_0
  std::string source;       ///< "initial" (init_still_s) or "auto" (pooled first pass)
  std::string acc_unit = "m/s^2";  ///< the series' accelerometer unit (of the means and sigmas)
  std::string gyr_unit = "rad/s";  ///< the series' gyroscope unit
  Vec3 acc_mean = Vec3::Zero();     ///< mean accelerometer output over the periods, series units
  Vec3 acc_sigma = Vec3::Zero();    ///< per-axis accelerometer noise std, series units
  Vec3 acc_tau_int = Vec3::Ones();  ///< integrated autocorrelation time, samples
  Vec3 acc_tau_sq = Vec3::Ones();   ///< 1 + 2 sum rho^2, samples (variance dof factor)
  bool has_gyro = false;            ///< whether the gyroscope fields are filled
  Vec3 gyr_sigma = Vec3::Zero();    ///< per-axis gyroscope noise std, series units
  Vec3 gyr_tau_int = Vec3::Ones();  ///< as acc_tau_int, for the gyroscope, samples
  Vec3 gyr_tau_sq = Vec3::Ones();   ///< as acc_tau_sq, for the gyroscope, samples
  Vec3 gyr_still_rate = Vec3::Zero();  ///< mean gyroscope output over the periods, series units
};

/// Thresholds on the normalised statistics, and what failed.
struct DetectionDetail {
  std::size_t window_samples = 0;  ///< n, samples in the moving window
  std::size_t block_samples = 0;   ///< samples per block: the window is tested every block
  double acc_dof = 0.0;            ///< nu_s of the accelerometer variance statistic
  double acc_threshold = 0.0;      ///< on s_a (dimensionless; 1 is the still mean)
  double gyr_dof = 0.0;            ///< nu_s of the gyroscope variance statistic (0 if unused)
  double gyr_threshold = 0.0;      ///< on s_g (0 if unused)
  double rate_threshold = 0.0;     ///< on d, chi^2(3) quantile (0 if unused)
  Vec3 rate_allowance = Vec3::Zero();  ///< allowance used, gyroscope units
  std::size_t windows = 0;             ///< window positions tested (one per block)
  std::size_t failed_acc = 0;          ///< windows failing the accelerometer variance test
  std::size_t failed_gyr = 0;          ///< windows failing the gyroscope variance test
  std::size_t failed_rate = 0;         ///< windows failing the mean-rate test
  std::size_t failed_gap = 0;          ///< windows spanning a time gap
  std::size_t failed_nonfinite = 0;    ///< windows holding a NaN or infinite sample
  std::size_t still_runs = 0;          ///< runs of still samples before the length filter
  /// Runs that pass the accelerometer test and are long enough but that the gyroscope tests
  /// reject (no kept segment inside them).
  std::size_t rejected_by_gyro = 0;
};

struct SegmentationResult {
  std::vector<StillSegment> segments;  ///< ordered, non-overlapping, labelled "still #k"
  SegmentationReport report;           ///< method, threshold, window, counts and notes
  NoiseEstimate noise;                 ///< empty for given segments
  DetectionDetail detail;              ///< empty for given segments
};

/// Detects the still segments of `series` (accelerometer required, gyroscope optional).
/// Throws plumb::Error for options out of range or inconsistent series arrays, and
/// plumb::InsufficientDataError when the series is empty or shorter than one window, when the
/// initial still period is shorter than one window or holds NaN or infinite samples, or when
/// no still period gives a usable noise estimate.
SegmentationResult DetectStillSegments(const ImuSeries& series,
                                       const StillDetectorOptions& options = {});

}  // namespace plumb::segmentation
