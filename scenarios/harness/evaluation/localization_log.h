#pragma once
// Where the stack's visual localization breaks: every ring frame it tried, at the true pose of the
// frame's stamp, with what came of it - no pose (and at which stage, why), or a fix and the EKF's
// verdict on it (accepted, rejected as an outlier, a re-localization, too old), the fix's error
// against the truth and its consistency with the covariance it stated. Written per trial as
// localization.csv; its outcome counts go into result.json.
#include <Eigen/Core>

#include <map>
#include <string>
#include <vector>

#include "trimbot/stack/telemetry.h"

namespace trimbot::scenarios {

struct TruePose {
  double x = 0.0, y = 0.0, yaw = 0.0;
};

class LocalizationLog {
 public:
  // A frame the localizer tried; `truth`: the true pose at its stamp (null: not known).
  void AddAttempt(const stack::LocalizationAttempt& attempt, const TruePose* truth);
  // A fix of one of those frames as it reached the EKF (matched to its frame by stamp).
  void AddFix(const stack::AppliedFix& applied, const TruePose* truth);

  // Frames by outcome: "no pose: <stage>", "accepted", "rejected as an outlier", "relocalized",
  // "too old", "invalid", "pending" (its fix had not arrived when the trial ended).
  std::map<std::string, int> Outcomes() const;
  // t, true x/y/yaw, outcome, failure, features, matches, inliers, error_m, sigma_m, nees.
  std::string Csv() const;
  bool empty() const { return rows_.empty(); }

 private:
  struct Row {
    double stamp = 0.0;
    bool have_truth = false;
    TruePose truth;
    std::string outcome, failure;
    int features = 0, matches = 0, inliers = 0;
    double error_m = -1.0, sigma_m = -1.0, nees = -1.0;  // -1: no fix (or no truth)
  };
  std::vector<Row> rows_;
  std::map<double, std::size_t> row_of_stamp_;
};

}  // namespace trimbot::scenarios
