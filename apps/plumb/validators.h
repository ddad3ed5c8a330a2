// apps/plumb/validators.h — the checks every numeric option gets, in one place.
//
// Positive / NonNegative replace CLI11's PositiveNumber / NonNegativeNumber, whose message
// prints the largest double in full (309 digits). RejectNonFiniteNumbers runs on the parsed
// command line before any work: a nan, an inf or an overflowing number (1e999) in a numeric
// option, or as the value of KEY=VALUE or a field of A:B:C in a text option (--truth,
// --temperature), is refused with the option named (exit 2) instead of reaching the solver.
#pragma once

#include <CLI/CLI.hpp>

namespace plumb::cli {

/// A finite number > 0; the message says the value given.
extern const CLI::Validator Positive;
/// A finite number >= 0.
extern const CLI::Validator NonNegative;

/// --jobs: a whole number from 0 (every core) to kJobsPerCore times the machine's cores (at
/// least kMinJobsBound): more threads than that only wait for the cores, and thousands fail to
/// start (libgomp: "Thread creation failed").
inline constexpr int kJobsPerCore = 16;
inline constexpr int kMinJobsBound = 64;
extern const CLI::Validator Jobs;

/// A gravity magnitude found on Earth, m/s^2 (units::kMinEarthGravity..kMaxEarthGravity).
extern const CLI::Validator EarthGravity;

/// An IMU's sample rate, Hz: > 0 and at most units::kMaxImuRate_hz.
extern const CLI::Validator SampleRate;

/// Throws UsageError naming the option and its value when a given option of `app` or of its
/// parsed subcommands holds a number that is not finite (file comment).
void RejectNonFiniteNumbers(const CLI::App& app);

}  // namespace plumb::cli
