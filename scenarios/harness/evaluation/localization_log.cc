#include "evaluation/localization_log.h"

#include <cmath>
#include <iomanip>
#include <sstream>

#include "evaluation/pose_errors.h"
#include "trimbot/common/pose2.h"

namespace trimbot::scenarios {
namespace {

const char* ToString(stack::FixOutcome outcome) {
  switch (outcome) {
    case stack::FixOutcome::kAccepted:
      return "accepted";
    case stack::FixOutcome::kRejectedOutlier:
      return "rejected as an outlier";
    case stack::FixOutcome::kRelocalized:
      return "relocalized";
    case stack::FixOutcome::kTooOld:
      return "too old";
    case stack::FixOutcome::kInvalid:
      return "invalid";
  }
  return "invalid";
}

}  // namespace

void LocalizationLog::AddAttempt(const stack::LocalizationAttempt& attempt, const TruePose* truth) {
  Row row;
  row.stamp = attempt.stamp;
  row.have_truth = truth != nullptr;
  if (truth != nullptr) row.truth = *truth;
  const bool localized = attempt.failed_stage == visual_localization::FailedStage::kNone;
  row.outcome = localized ? "pending" : std::string("no pose: ") + visual_localization::ToString(attempt.failed_stage);
  row.failure = attempt.failure;
  row.features = attempt.features;
  row.matches = attempt.matches;
  row.inliers = attempt.inliers;
  row_of_stamp_[attempt.stamp] = rows_.size();
  rows_.push_back(row);
}

void LocalizationLog::AddFix(const stack::AppliedFix& applied, const TruePose* truth) {
  const auto it = row_of_stamp_.find(applied.fix.stamp);
  if (it == row_of_stamp_.end()) return;  // not a frame of this log (another source's fix)
  Row& row = rows_[it->second];
  row.outcome = ToString(applied.outcome);
  const Eigen::Matrix3d& covariance = applied.fix.covariance;
  row.sigma_m = LargestPositionSigma(covariance);
  if (truth == nullptr) return;
  const Eigen::Vector3d error(applied.fix.x - truth->x, applied.fix.y - truth->y,
                              WrapAngle(applied.fix.yaw - truth->yaw));
  row.error_m = error.head<2>().norm();
  row.nees = PlanarNees(error, covariance);
}

std::map<std::string, int> LocalizationLog::Outcomes() const {
  std::map<std::string, int> counts;
  for (const Row& row : rows_) ++counts[row.outcome];
  return counts;
}

std::string LocalizationLog::Csv() const {
  std::ostringstream csv;
  csv << "t,true_x,true_y,true_yaw,outcome,failure,features,matches,inliers,error_m,sigma_m,nees\n";
  csv << std::fixed;
  for (const Row& row : rows_) {
    csv << std::setprecision(3) << row.stamp << ',';
    if (row.have_truth)
      csv << row.truth.x << ',' << row.truth.y << ',' << std::setprecision(4) << row.truth.yaw;
    else
      csv << ",,";
    // The failure text may hold commas; quoted as CSV quotes.
    csv << ',' << row.outcome << ",\"" << row.failure << "\"," << row.features << ',' << row.matches << ','
        << row.inliers << ',';
    if (row.error_m >= 0.0) csv << std::setprecision(4) << row.error_m;
    csv << ',';
    if (row.sigma_m >= 0.0) csv << std::setprecision(4) << row.sigma_m;
    csv << ',';
    if (row.nees >= 0.0) csv << std::setprecision(3) << row.nees;
    csv << '\n';
  }
  return csv.str();
}

}  // namespace trimbot::scenarios
