#include "isoflex/app/progress.hpp"

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>

namespace isoflex::app {

namespace {
constexpr int kBarWidth = 30;
constexpr auto kRedrawInterval = std::chrono::milliseconds(100);
}  // namespace

void EtaEstimator::add(double wall_seconds, double fraction) {
  samples_.push_back({wall_seconds, fraction});
  // Keep one sample at or before the window's start, so that the window spans `window_` seconds.
  std::size_t first = 0;
  while (first + 2 < samples_.size() && samples_[first + 1].wall <= wall_seconds - window_) ++first;
  samples_.erase(samples_.begin(), samples_.begin() + static_cast<std::ptrdiff_t>(first));
}

double EtaEstimator::eta() const {
  if (samples_.size() < 2) return -1.0;
  const Sample& a = samples_.front();
  const Sample& b = samples_.back();
  const double rate = (b.fraction - a.fraction) / (b.wall - a.wall);
  if (!(rate > 0.0) || !std::isfinite(rate)) return -1.0;
  return (1.0 - std::min(b.fraction, 1.0)) / rate;
}

ProgressBar::ProgressBar(double t_end, std::FILE* out)
    : t_end_(t_end), out_(out), active_(out != nullptr && isatty(fileno(out)) == 1) {}

ProgressBar::ProgressBar(double t_end, double path_end, std::FILE* out) : ProgressBar(t_end, out) {
  path_end_ = path_end;
}

ProgressBar::~ProgressBar() {
  if (active_ && line_open_) {
    std::fputc('\n', out_);
    std::fflush(out_);
  }
}

std::string ProgressBar::format_duration(double seconds) {
  if (!std::isfinite(seconds) || seconds < 0.0) return "--:--";
  const auto total = static_cast<long long>(std::llround(std::min(seconds, 359999.0)));
  const long long h = total / 3600, m = (total / 60) % 60, s = total % 60;
  if (h > 0) return fmt::format("{}:{:02d}:{:02d}", h, m, s);
  return fmt::format("{:02d}:{:02d}", m, s);
}

std::string ProgressBar::format_line(double fraction, int step, double t, int iterations,
                                     double eta_seconds) {
  if (!std::isfinite(fraction)) fraction = 0.0;
  fraction = std::clamp(fraction, 0.0, 1.0);
  const int filled = static_cast<int>(std::floor(fraction * kBarWidth + 1e-9));
  const int percent = static_cast<int>(std::floor(fraction * 100.0 + 1e-9));
  return fmt::format("[{}{}] {:3d}%  step {}  t={:.4f}  it={}  ETA {}", std::string(filled, '#'),
                     std::string(kBarWidth - filled, '.'), percent, step, t, iterations,
                     format_duration(eta_seconds));
}

void ProgressBar::on_snapshot(const integrate::Snapshot& s) {
  if (!active_) return;
  const auto now = std::chrono::steady_clock::now();
  if (!have_snapshot_) {
    have_snapshot_ = true;
    wall_start_ = now;
    t_start_ = s.t;
  }
  step_ = s.step;
  t_ = s.t;
  path_ = s.path;
  iterations_ = s.newton_iterations;
  if (!line_open_ || now - last_draw_ >= kRedrawInterval) draw(false);
}

void ProgressBar::on_finish() {
  if (!active_ || !have_snapshot_) return;
  draw(true);
  std::fputc('\n', out_);
  std::fflush(out_);
  line_open_ = false;
}

void ProgressBar::draw(bool final) {
  const auto now = std::chrono::steady_clock::now();
  const double span = t_end_ - t_start_;
  const double fraction = path_end_ != 0.0 ? path_ / path_end_
                          : span > 0.0     ? (t_ - t_start_) / span
                                           : 1.0;
  eta_.add(std::chrono::duration<double>(now - wall_start_).count(), fraction);
  const double eta = final ? 0.0 : eta_.eta();
  // "\r" returns to the line start, "\x1b[K" clears what a longer previous line left behind.
  fmt::print(out_, "\r{}\x1b[K", format_line(fraction, step_, t_, iterations_, eta));
  std::fflush(out_);
  line_open_ = true;
  last_draw_ = now;
}

}  // namespace isoflex::app
