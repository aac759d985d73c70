// Ceres logs through glog, and a few of its messages are written at ERROR severity whatever
// Solver::Options::logging_type says (e.g. "Terminating: Residual and Jacobian evaluation
// failed.", or a rank-deficient ceres::Covariance). glog prints those to stderr before
// InitGoogleLogging is called, so they would reach the user beside uphill's own one-line
// message. uphill reads every outcome from the solver's Summary (or Covariance's return value)
// and reports it itself, so the library's log lines carry nothing the user needs: they are
// silenced. A developer who wants them sets GLOG_minloglevel (0 = everything), which is then
// left as it is.
#pragma once

namespace uphill {

// Raises glog's minimum severity to FATAL, once per process, unless GLOG_minloglevel is set.
// Idempotent and thread-safe; every solve and covariance in the libraries calls it first.
void QuietSolverLogs();

}  // namespace uphill
