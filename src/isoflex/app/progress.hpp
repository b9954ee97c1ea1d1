#pragma once
// A one-line progress display on a terminal:
//   [############..................]  42%  step 420  t=4.2000  it=3  ETA 00:05
// redrawn at most ten times a second and finished with a newline; the ETA by EtaEstimator. Writes
// nothing at all when `out` is not a terminal (log files, pipes, tests).
#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

#include "isoflex/integrate/snapshot.hpp"

namespace isoflex::app {

// The time a run still needs, from the measured rate of its recent progress: the fraction done
// per second of wall time over the samples of the last `window` seconds (at least the last two
// samples), not the average since the start — a run that slows down (Newton stalling on stiff
// shells late in the run) gets an ETA at its present speed.
class EtaEstimator {
 public:
  explicit EtaEstimator(double window_seconds = 10.0) : window_(window_seconds) {}
  void add(double wall_seconds, double fraction);
  // Seconds to fraction 1; < 0 while unknown (fewer than two samples, no progress in the window).
  double eta() const;

 private:
  struct Sample {
    double wall, fraction;
  };
  double window_;
  std::vector<Sample> samples_;  // the window's samples and the one before it, oldest first
};

class ProgressBar : public integrate::Observer {
 public:
  explicit ProgressBar(double t_end, std::FILE* out = stderr);
  // Progress measured by Snapshot::path from 0 to path_end instead of t (a static run under
  // displacement control, whose load factor t need not grow).
  ProgressBar(double t_end, double path_end, std::FILE* out);
  // Ends a line left open (a run aborted by an exception) so that messages start on a fresh line.
  ~ProgressBar() override;
  ProgressBar(const ProgressBar&) = delete;
  ProgressBar& operator=(const ProgressBar&) = delete;

  void on_snapshot(const integrate::Snapshot& s) override;
  void on_finish() override;

  bool active() const { return active_; }

  // The text of the line (without carriage return); eta_seconds < 0 means unknown ("--:--").
  static std::string format_line(double fraction, int step, double t, int iterations,
                                 double eta_seconds);
  // "mm:ss", or "h:mm:ss" from one hour on.
  static std::string format_duration(double seconds);

 private:
  void draw(bool final);

  double t_end_;
  std::FILE* out_;
  bool active_;
  bool line_open_ = false;
  bool have_snapshot_ = false;
  int step_ = 0;
  double t_ = 0.0;
  double t_start_ = 0.0;
  double path_end_ = 0.0;  // > 0: the fraction is path / path_end
  double path_ = 0.0;
  int iterations_ = 0;
  std::chrono::steady_clock::time_point wall_start_{};
  std::chrono::steady_clock::time_point last_draw_{};
  EtaEstimator eta_;
};

}  // namespace isoflex::app
