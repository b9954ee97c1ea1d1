#pragma once
// The one Newton iteration of isoflex: the time step of EnergyMomentumIntegrator and the load
// step of StaticNewtonSolver (every static model) run this loop, with the convergence tests of
// docs/theory/schemes.md §6:
//   • ‖R‖∞ ≤ residual_tolerance · scale (the scale is the caller's: momentum terms in a time
//     step, forces and reactions in a load step), or
//   • a correction at round-off level (the caller measures it in configuration units; its error
//     is its square), after which the residual is evaluated once more and reported.
// A residual that grows by six orders of magnitude (or overflows) diverged; its scale would be the
// diverged iterate's, so the scale at the start is reported. A failure is an outcome, not an
// exception: the time step retries from other predictors or in halves, the load step in smaller
// increments; `failure_message` words it the same way for both.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <exception>
#include <new>
#include <stdexcept>
#include <string>
#include <vector>

#include "isoflex/math/types.hpp"

namespace isoflex::integrate {

struct NewtonOptions {
  int max_iterations = 25;
  double residual_tolerance = 1e-10;
  // Stop as soon as the residual grew by 10⁶ (load steps, where a diverging iterate soon leaves
  // the domain of the model); otherwise a growing residual gets every iteration, as the violent
  // first corrections of thin shells in a time step can still converge.
  bool stop_when_diverging = false;
  // Skip the Newton matrix where quadratic convergence predicts the next residual to be the last
  // (‖R_k‖ ≈ ‖R_{k−1}‖ (‖R_{k−1}‖/‖R_{k−2}‖)² below the tolerance); if the prediction fails it is
  // evaluated at the same iterate, so the iterates do not change.
  bool predict_last_matrix = false;
  // Chord corrections near the root: the next correction reuses the last Newton matrix, and the
  // caller its factorization, when its predicted contraction is this factor or less (0: never).
  // Newton's error eₖ₊₁ ≈ C eₖ² becomes eₖ₊₁ ≈ C ‖xₖ − x_J‖ eₖ with x_J the iterate of the
  // matrix: after a Newton correction with contraction θ = C ‖Δx‖ that is about θ², after a chord
  // correction about its own θ. Near the root a chord step gains as many digits as a Newton step
  // and costs a residual and a solve with a kept factorization (docs/theory/schemes.md §6).
  double chord_contraction = 0.0;
  // Corrections applied before the residual test may end the iteration (a bordered step whose
  // extra equation the start does not satisfy: displacement control).
  int min_corrections = 0;
};

struct NewtonOutcome {
  bool converged = false;
  int iterations = 0;     // corrections applied
  double residual = 0.0;  // ‖R‖∞ at the last evaluation
  double scale = 0.0;     // the residual scale (at the start of the iteration if it diverged)
  double first_residual = 0.0;
  std::string reason;  // why it failed: "Newton did not converge in 25 iterations", …
};

// "{where}: {reason}; residual … after … iterations (tolerance … x scale …)".
inline std::string failure_message(const std::string& where, const NewtonOutcome& o,
                                   double residual_tolerance) {
  const bool diverged = o.reason.rfind("Newton diverged", 0) == 0;
  if (diverged)
    return fmt::format("{}: {} (tolerance {:.1e} x scale {:.3e} at the start)", where, o.reason,
                       residual_tolerance, o.scale);
  return fmt::format(
      "{}: {}; residual {:.3e} after {} iterations (tolerance {:.1e} x scale {:.3e})", where,
      o.reason, o.residual, o.iterations, residual_tolerance, o.scale);
}

// A step (or load step) that could not be solved. residual(): ‖R‖∞ where the last Newton attempt
// stopped, NaN for a failure that is no Newton outcome (non-finite results, a degenerate path).
class NewtonFailure : public std::runtime_error {
 public:
  explicit NewtonFailure(const std::string& what) : std::runtime_error(what) {}
  NewtonFailure(const std::string& where, const NewtonOutcome& o, double residual_tolerance)
      : std::runtime_error(failure_message(where, o, residual_tolerance)), residual_(o.residual) {}
  double residual() const { return residual_; }
  // The work the failed step did before it gave up, so that a step retried in halves reports
  // it (step_subdivision.hpp): Newton iterations and abandoned starts.
  NewtonFailure& spent(int iterations, int starts) {
    iterations_ = iterations;
    starts_ = starts;
    return *this;
  }
  int spent_iterations() const { return iterations_; }
  int spent_starts() const { return starts_; }

 private:
  double residual_ = std::nan("");
  int iterations_ = 0, starts_ = 0;
};

// residual(with_matrix) → R at the current iterate, the Newton matrix kept when asked (a
// std::runtime_error from the model fails the iteration); scale() → the residual scale at the
// iterate just evaluated; correct(R) applies Δ = −A⁻¹R to the iterate, A the last matrix kept,
// and says whether Δ was at round-off level (an exception fails the iteration). history, if given,
// receives ‖R‖∞ of every evaluation.
template <class Residual, class Scale, class Correct>
NewtonOutcome newton_loop(const NewtonOptions& opt, Residual&& residual, Scale&& scale,
                          Correct&& correct, std::vector<double>* history = nullptr) {
  NewtonOutcome out;
  double first_scale = 0.0, r_prev = 0.0, r_prev2 = 0.0;
  // Growth is measured from the first residual (after the min_corrections, whose start may be
  // converged already).
  const auto divergence_base = [&] { return std::max(out.first_residual, 1e-300); };
  // The residual, kept across iterations: one the caller returns by reference (a workspace of
  // its own) is copied into this storage, so that an iteration need not allocate.
  VecX R;
  auto evaluate = [&](bool with_matrix, int it, bool record) {
    try {
      R = residual(with_matrix);
      out.residual = R.size() ? R.template lpNorm<Eigen::Infinity>() : 0.0;
      if (history && record) history->push_back(out.residual);
    } catch (const NewtonFailure&) {
      throw;
    } catch (const std::bad_alloc&) {
      throw;  // out of memory ends the run (app/commands.cpp), no smaller step would fit better
    } catch (const std::runtime_error& e) {
      out.reason = fmt::format("evaluation failed at Newton iteration {}: {}", it, e.what());
      R.resize(0);
    }
  };
  bool last_fresh = false;  // the last correction was made with a matrix of its own iterate
  for (int it = 0;; ++it) {
    out.iterations = it;
    bool with_matrix = it < opt.max_iterations;
    // The chord's contraction predicted from the last correction's θ = r_prev/r_prev2
    // (chord_contraction).
    const double theta = r_prev2 > 0.0 ? r_prev / r_prev2 : 1.0;
    const bool chord =
        with_matrix && it >= 2 && (last_fresh ? theta * theta : theta) <= opt.chord_contraction;
    if (chord)
      with_matrix = false;
    else if (with_matrix && opt.predict_last_matrix && it >= 2 && r_prev2 > 0.0)
      with_matrix = !(r_prev < r_prev2 && r_prev * (r_prev / r_prev2) * (r_prev / r_prev2) <=
                                              opt.residual_tolerance * out.scale);
    evaluate(with_matrix, it, true);
    if (!out.reason.empty()) return out;
    out.scale = scale();
    if (it == opt.min_corrections) {
      out.first_residual = out.residual;
      first_scale = out.scale;
    }
    const bool diverged = !std::isfinite(out.residual) ||
                          (it >= opt.min_corrections && out.residual > 1e6 * divergence_base());
    if (diverged && (opt.stop_when_diverging || !std::isfinite(out.residual))) break;
    if (it >= opt.min_corrections &&
        (out.residual <= opt.residual_tolerance * out.scale || out.residual == 0.0)) {
      out.converged = true;
      return out;
    }
    if (it == opt.max_iterations) break;
    if (!with_matrix && !chord) {  // the prediction failed: the matrix after all, here
      const VecX kept = R;
      evaluate(true, it, false);
      if (!out.reason.empty()) return out;
      R = kept;
    }
    r_prev2 = r_prev;
    r_prev = out.residual;
    last_fresh = with_matrix;
    bool small = false;
    try {
      small = correct(R);
    } catch (const std::bad_alloc&) {
      throw;  // e.g. solve::OutOfMemory from the factorization: not a failed iteration
    } catch (const std::exception& e) {
      out.reason =
          fmt::format("the Newton correction failed at iteration {}: {}", it + 1, e.what());
      return out;
    }
    if (small) {
      out.iterations = it + 1;
      evaluate(false, it + 1, true);
      if (!out.reason.empty()) return out;
      out.converged = std::isfinite(out.residual);
      if (!out.converged) break;
      return out;
    }
  }
  if (!std::isfinite(out.residual) || out.residual > 1e6 * divergence_base()) {
    out.reason =
        fmt::format("Newton diverged: the residual grew from {:.3e} to {:.3e} in {} iterations",
                    out.first_residual, out.residual, out.iterations);
    out.scale = first_scale;
  } else {
    out.reason = "Newton did not converge";
  }
  return out;
}

}  // namespace isoflex::integrate
