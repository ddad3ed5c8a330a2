#include "progress.h"

#include <cstdio>
#include <iostream>

namespace plumb::cli {
namespace {

using Clock = std::chrono::steady_clock;

double Seconds(Clock::duration d) { return std::chrono::duration<double>(d).count(); }

/// Forwards to `target`, erasing the progress line before each write.
class ErasingBuffer : public std::streambuf {
 public:
  explicit ErasingBuffer(std::streambuf* target) : target_(target) {}

 protected:
  int_type overflow(int_type c) override {
    Progress::Of().Erase();
    return traits_type::eq_int_type(c, traits_type::eof()) ? target_->pubsync()
                                                           : target_->sputc(traits_type::to_char_type(c));
  }
  std::streamsize xsputn(const char* s, std::streamsize n) override {
    Progress::Of().Erase();
    return target_->sputn(s, n);
  }
  int sync() override { return target_->pubsync(); }

 private:
  std::streambuf* target_;
};

}  // namespace

Progress& Progress::Of() {
  static Progress progress;
  return progress;
}

void Progress::Start(const std::string& command, bool enabled) {
  std::lock_guard<std::mutex> lock(mutex_);
  command_ = command;
  started_ = stage_started_ = Clock::now();
  enabled_ = enabled;
  stopping_ = false;
  if (enabled_ && !ticker_.joinable()) {
    GuardStreams();
    ticker_ = std::thread([this] { Draw(); });
  }
}

void Progress::GuardStreams() {
  original_out_ = std::cout.rdbuf();
  original_err_ = std::cerr.rdbuf();
  guarded_out_ = std::make_unique<ErasingBuffer>(original_out_);
  guarded_err_ = std::make_unique<ErasingBuffer>(original_err_);
  std::cout.rdbuf(guarded_out_.get());
  std::cerr.rdbuf(guarded_err_.get());
}

void Progress::Erase() {
  std::lock_guard<std::mutex> lock(mutex_);
  EraseLocked();
}

void Progress::Stage(const std::string& what) {
  std::lock_guard<std::mutex> lock(mutex_);
  stage_ = what;
  stage_started_ = Clock::now();
  wake_.notify_all();
}

std::string Progress::CurrentStage() {
  std::lock_guard<std::mutex> lock(mutex_);
  return stage_;
}

void Progress::Clear() {
  std::lock_guard<std::mutex> lock(mutex_);
  stage_.clear();
  EraseLocked();
}

void Progress::Stop() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
    stage_.clear();
    EraseLocked();
    wake_.notify_all();
  }
  if (ticker_.joinable()) ticker_.join();
  if (guarded_out_) {
    std::cout.rdbuf(original_out_);
    std::cerr.rdbuf(original_err_);
    guarded_out_.reset();
    guarded_err_.reset();
  }
}

Progress::~Progress() { Stop(); }

void Progress::EraseLocked() {
  if (!drawn_) return;
  std::fputs("\r\033[K", stderr);  // carriage return, erase to the end of the line
  std::fflush(stderr);
  drawn_ = false;
}

void Progress::Draw() {
  std::unique_lock<std::mutex> lock(mutex_);
  const auto period = std::chrono::duration_cast<Clock::duration>(
      std::chrono::duration<double>(kRedrawSeconds));
  while (!stopping_) {
    wake_.wait_for(lock, period);
    if (stopping_ || stage_.empty()) continue;
    const Clock::time_point now = Clock::now();
    if (Seconds(now - started_) < kQuietSeconds) continue;
    std::fprintf(stderr, "\r\033[Kplumb %s: %s  %.1f s", command_.c_str(), stage_.c_str(),
                 Seconds(now - stage_started_));
    std::fflush(stderr);
    drawn_ = true;
  }
}

}  // namespace plumb::cli
