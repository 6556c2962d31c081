// Point-cloud registration (DUGMA and the ICP baseline) on synthetic garden-like clouds with known
// transforms and noise; bad input; the DUGMA data set's file format.
#include <gtest/gtest.h>

#include <sstream>

#include <algorithm>
#include <cmath>
#include <random>

#include "evaluation/pose_errors.h"
#include "evaluation/registration_pair_file.h"
#include "evaluation/registration_set.h"
#include "runners/registration_cv.h"
#include "synthetic_clouds.h"
#include "test_support.h"
#include "trimbot/common/input_error.h"
#include "trimbot/perception/registration.h"

namespace trimbot::perception {

using scenarios::RotationErrorDegrees;
using scenarios::TranslationError;
namespace {

TEST(Dugma, RecoversALargeMotionFromIdentity) {
  const PointCloud x = GardenScene(4000, 1, false);
  const Eigen::Isometry3d truth = Transform(20.0, 5.0, {0.4, -0.3, 0.1});
  const PointCloud y = ObservedFrom(x, truth, 2);
  const RegistrationResult r = Register(x, y, Eigen::Isometry3d::Identity());
  EXPECT_LT(RotationErrorDegrees(r.transform, truth), 0.5);
  EXPECT_LT(TranslationError(r.transform, truth), 0.01);
  EXPECT_GT(r.pairs, 1000);
  EXPECT_TRUE(std::isfinite(r.final_cost));
}

TEST(Dugma, UsesAnisotropicCovariances) {
  const PointCloud x = GardenScene(4000, 3, true);
  const Eigen::Isometry3d truth = Transform(-12.0, 3.0, {-0.2, 0.3, 0.05});
  const PointCloud y = ObservedFrom(x, truth, 4);
  const RegistrationResult r = Register(x, y, Eigen::Isometry3d::Identity());
  EXPECT_LT(RotationErrorDegrees(r.transform, truth), 0.5);
  EXPECT_LT(TranslationError(r.transform, truth), 0.015);
}

// The baselines (Open3D's ICP variants) through the same API. ICP and point-to-plane ICP from the
// guess the benchmark uses (20 deg, 0.5 m off; the hand-written ICP they replace ended 6.6-9.3 deg
// off there); generalized ICP from 8 deg, 0.2 m (from 20 deg it ends 16-20 deg off on this scene and
// at 1,000 points in the benchmark: its basin is narrower).
TEST(Icp, BaselinesThroughTheSameApiConverge) {
  const PointCloud x = GardenScene(4000, 5, false);
  const struct {
    RegistrationMethod method;
    Eigen::Isometry3d truth;
  } cases[] = {{RegistrationMethod::kIcpPointToPoint, Transform(20.0, 5.0, {0.4, -0.3, 0.1})},
               {RegistrationMethod::kIcpPointToPlane, Transform(20.0, 5.0, {0.4, -0.3, 0.1})},
               {RegistrationMethod::kGeneralizedIcp, Transform(8.0, 2.0, {0.15, -0.1, 0.05})}};
  for (const auto& c : cases) {
    const PointCloud y = ObservedFrom(GardenScene(8000, 5, false), c.truth, 6);
    RegistrationOptions icp;
    icp.method = c.method;
    const RegistrationResult r = Register(x, y, Eigen::Isometry3d::Identity(), icp);
    EXPECT_LT(RotationErrorDegrees(r.transform, c.truth), 1.0) << static_cast<int>(c.method);
    EXPECT_LT(TranslationError(r.transform, c.truth), 0.02) << static_cast<int>(c.method);
    EXPECT_TRUE(r.converged);
    EXPECT_GT(r.pairs, 1000);
  }
}

TEST(Registration, BadPointsAreDroppedAndCountedNeverNaN) {
  PointCloud x = GardenScene(2000, 7, false);
  const Eigen::Isometry3d truth = Transform(8.0, 0.0, {0.1, 0.0, 0.0});
  PointCloud y = ObservedFrom(x, truth, 8);
  x.points[3] = Eigen::Vector3d(NAN, 0, 0);
  x.covariances[4](1, 1) = NAN;
  x.covariances[5] = Eigen::Matrix3d::Zero();                 // singular
  x.covariances[6] = Eigen::Vector3d(1, -1, 1).asDiagonal();  // not positive definite
  y.covariances[0] = 1e6 * Eigen::Matrix3d::Identity();       // above max_variance: unusable
  const RegistrationResult r = Register(x, y, Eigen::Isometry3d::Identity());
  EXPECT_EQ(r.target_points.non_finite, 2);
  EXPECT_EQ(r.target_points.unusable_covariance, 2);
  EXPECT_EQ(r.source_points.unusable_covariance, 1);
  EXPECT_TRUE(r.transform.matrix().allFinite());
  EXPECT_LT(RotationErrorDegrees(r.transform, truth), 0.5);
}

TEST(Registration, EmptyOrMismatchedInputIsAClearError) {
  const PointCloud x = GardenScene(500, 9, false);
  PointCloud empty;
  EXPECT_THROW(Register(x, empty, Eigen::Isometry3d::Identity()), RegistrationError);
  PointCloud all_nan;
  all_nan.Add(Eigen::Vector3d::Constant(NAN), Eigen::Matrix3d::Identity());
  all_nan.Add(Eigen::Vector3d::Constant(NAN), Eigen::Matrix3d::Identity());
  all_nan.Add(Eigen::Vector3d::Constant(NAN), Eigen::Matrix3d::Identity());
  try {
    Register(all_nan, x, Eigen::Isometry3d::Identity());
    FAIL() << "expected a RegistrationError";
  } catch (const RegistrationError& e) {
    EXPECT_NE(std::string(e.what()).find("target 0 of 3"), std::string::npos) << e.what();
  }
  PointCloud mismatched = x;
  mismatched.covariances.pop_back();
  EXPECT_THROW(Register(x, mismatched, Eigen::Isometry3d::Identity()), std::invalid_argument);
  Eigen::Isometry3d bad_guess = Eigen::Isometry3d::Identity();
  bad_guess.translation().x() = NAN;
  EXPECT_THROW(Register(x, x, bad_guess), RegistrationError);
}

TEST(RegistrationPairFile, ReadsTheDataSetFormatAndNamesBadLines) {
  const std::string good = testing::WriteTempFile(
      "pair_good.txt",
      "# comment\nR 1 0 0 0 1 0 0 0 1\nt 0.5 0 0\nX 2  # x y z c\n0 0 0 1 0 0 1 0 1\n1 0 0 nan 0 0 1 0 1\n"
      "Y 1\n0 1 0 2 0 0 2 0 2\n");
  const scenarios::RegistrationPair pair = scenarios::LoadRegistrationPair(good);
  EXPECT_EQ(pair.x.size(), 2u);
  EXPECT_EQ(pair.y.size(), 1u);
  EXPECT_NEAR(pair.truth.translation().x(), 0.5, 1e-12);
  EXPECT_TRUE(std::isnan(pair.x.covariances[1](0, 0)));
  const std::string bad =
      testing::WriteTempFile("pair_bad.txt", "R 1 0 0 0 1 0 0 0 1\nt 0 0 0\nX 1\n0 0 zero 1 0 0 1 0 1\n");
  try {
    scenarios::LoadRegistrationPair(bad);
    FAIL() << "expected an InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("pair_bad.txt: line 4"), std::string::npos) << e.what();
  }
}

}  // namespace
// Cross-validation reports every pair once, from the fold it was left out of, with parameters
// chosen on the other folds, and the ICP baseline beside it.
TEST(CrossValidation, EveryPairFromItsOwnFoldWithTheBaselineBeside) {
  std::vector<scenarios::RegistrationPair> pairs;
  for (std::uint32_t k = 0; k < 4; ++k) {
    scenarios::RegistrationPair pair;
    pair.name = "synthetic_" + std::to_string(k);
    pair.truth = Transform(10.0 + 3.0 * k, 5.0, {0.2, -0.1, 0.05});
    pair.x = GardenScene(1000, 20 + k, false);
    pair.y = ObservedFrom(GardenScene(1000, 30 + k, false), pair.truth, 40 + k);
    pairs.push_back(std::move(pair));
  }
  std::ostringstream table;
  const auto rows = scenarios::CrossValidateDugma(pairs, 2, RegistrationOptions{}, table);
  ASSERT_EQ(rows.size(), 4u);
  for (std::size_t p = 0; p < rows.size(); ++p) {
    EXPECT_EQ(rows[p].pair, pairs[p].name);
    EXPECT_EQ(rows[p].fold, static_cast<int>(p % 2));
    EXPECT_FALSE(rows[p].parameters.empty());
    EXPECT_LT(rows[p].rotation_deg, 1.0) << rows[p].pair;
    EXPECT_GE(rows[p].icp_rotation_deg, 0.0);
  }
  EXPECT_NE(table.str().find("cross-validated (2 folds"), std::string::npos) << table.str();
}

// Registered both ways, a good result agrees with its reverse to within the noise and is trusted.
// (The check is weak: on this scene, wrong minima from guesses 60-180 deg off agree with their
// reverse too, to 0.4-7 deg; on the shared Kinect pairs thinned to every 9th target point it flagged
// both failures, 61 and 48 deg, and no success.)
TEST(Dugma, BothWaysCheckTrustsAGoodResult) {
  const PointCloud x = GardenScene(3000, 51, false);
  const Eigen::Isometry3d truth = Transform(15.0, 5.0, {0.3, -0.2, 0.05});
  const PointCloud y = ObservedFrom(GardenScene(3000, 52, false), truth, 53);
  RegistrationOptions options;
  options.check_consistency = true;
  const RegistrationResult good = Register(x, y, Eigen::Isometry3d::Identity(), options);
  EXPECT_LT(RotationErrorDegrees(good.transform, truth), 1.0);
  EXPECT_TRUE(good.trusted) << good.doubt;
  EXPECT_LT(good.consistency_deg, 2.0);
  EXPECT_GT(good.consistency_deg, 0.0);  // it ran
}

namespace {

// The first `count` pairs of the rendered set (test lawn, seed 1), rendered in a folder of their own.
std::vector<scenarios::RegistrationPair> RenderedPairs(int count, const std::string& folder) {
  scenarios::RegistrationSetOptions options;
  options.pairs = count;
  return scenarios::RenderRegistrationPairs(options, scenarios::ProjectPaths{TRIMBOT_SOURCE_DIR},
                                            testing::TempDir(folder));
}

}  // namespace

// The rendered data set's truth and back-projection agree: the second view moved by the truth lies
// on the first (median distance to the nearest point of X, over the points that have one within
// 0.2 m, about the Kinect-like noise and the point spacing), and far from it without the truth.
TEST(RegistrationSet, RenderedPairsLieOnEachOtherUnderTheirTruth) {
  const auto pairs = RenderedPairs(2, "registration_set");
  ASSERT_EQ(pairs.size(), 2u);
  for (const auto& pair : pairs) {
    EXPECT_GT(pair.x.size(), 1000u);
    EXPECT_GT(pair.y.size(), 1000u);
    const auto median_gap = [&](const Eigen::Isometry3d& T) {
      std::vector<double> gaps;
      for (std::size_t j = 0; j < pair.y.size(); j += 10) {
        const Eigen::Vector3d p = T * pair.y.points[j];
        double best = 1e9;
        for (const auto& q : pair.x.points) best = std::min(best, (q - p).norm());
        if (best < 0.2) gaps.push_back(best);
      }
      std::sort(gaps.begin(), gaps.end());
      return gaps.empty() ? 1e9 : gaps[gaps.size() / 2];
    };
    EXPECT_LT(median_gap(pair.truth), 0.03) << pair.name;
    EXPECT_GT(RotationErrorDegrees(Eigen::Isometry3d::Identity(), pair.truth), 9.9) << "the views differ";
  }
}

}  // namespace trimbot::perception

namespace trimbot::perception {
namespace {

// Rendered views of round bushes turned 10-40 deg about them: from the identity a single annealed
// start settles where the two visible halves coincide (the viewer-centred pose), so the heading
// starts about the ground's normal have to find the turn, and the surface likelihood has to pick
// it. The first six pairs of the seed-1 set: a single start gets 3 of them under 5 deg.
TEST(Dugma, HeadingStartsFindTheTurnAboutARoundBush) {
  const auto pairs = RenderedPairs(6, "registration_heading");
  ASSERT_EQ(pairs.size(), 6u);
  RegistrationOptions options;
  options.heading_search_deg = 45.0;
  int under_5_degrees = 0;
  for (const auto& pair : pairs) {
    const RegistrationResult r = Register(pair.x, pair.y, Eigen::Isometry3d::Identity(), options);
    ASSERT_EQ(r.starts.size(), 8u) << pair.name << ": the guess and 7 heading starts (the ground was found)";
    for (const auto& start : r.starts) EXPECT_LE(start.log_likelihood, r.surface_log_likelihood) << pair.name;
    under_5_degrees += RotationErrorDegrees(r.transform, pair.truth) < 5.0 ? 1 : 0;
  }
  EXPECT_GE(under_5_degrees, 6);
}

}  // namespace
}  // namespace trimbot::perception
