#include "near_points.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "coloc/core/error.hpp"

namespace coloc::roadside {
namespace {

// The answer by looking at every point, in float as the index takes it.
bool anyWithinByHand(const std::vector<Eigen::Vector3f>& points, const Eigen::Vector3f& q, double distance) {
  for (const Eigen::Vector3f& p : points) {
    if (!p.allFinite()) continue;
    const float dx = q.x() - p.x(), dy = q.y() - p.y(), dz = q.z() - p.z();
    float sq = dx * dx;
    sq += dy * dy;
    sq += dz * dz;
    if (static_cast<double>(sq) <= distance * distance) return true;
  }
  return false;
}

TEST(NearPoints, AnswersAsLookingAtEveryPointDoesOverAFrameOfRandomPointsAndQueries) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> coordinate(-60.0f, 60.0f), height(-3.0f, 5.0f), offset(-0.12f, 0.12f);
  std::vector<Eigen::Vector3f> points;
  for (int i = 0; i < 20000; ++i) points.emplace_back(coordinate(rng), coordinate(rng), height(rng));
  points.emplace_back(std::numeric_limits<float>::quiet_NaN(), 0.0f, 0.0f);  // left out
  const double distance = 0.15;
  const NearPoints near(points, distance);
  EXPECT_EQ(near.size(), 20000u);
  int agree = 0, within = 0;
  for (int i = 0; i < 20000; ++i) {
    // Half the queries near a point (some within the distance, some just beyond), half anywhere.
    const Eigen::Vector3f q = i % 2 ? points[static_cast<std::size_t>(i)] + Eigen::Vector3f(offset(rng), offset(rng), offset(rng))
                                    : Eigen::Vector3f(coordinate(rng), coordinate(rng), height(rng));
    const bool expected = anyWithinByHand(points, q, distance);
    agree += near.anyWithin(q) == expected ? 1 : 0;
    within += expected ? 1 : 0;
  }
  EXPECT_EQ(agree, 20000);
  EXPECT_GT(within, 2000);  // both answers were asked for
  EXPECT_LT(within, 18000);
}

TEST(NearPoints, APointAtExactlyTheDistanceIsWithinItAndOneAHairBeyondIsNot) {
  const NearPoints near({Eigen::Vector3f(10.0f, 0.0f, 0.0f)}, 0.5);
  EXPECT_TRUE(near.anyWithin(Eigen::Vector3f(10.5f, 0.0f, 0.0f)));
  EXPECT_TRUE(near.anyWithin(Eigen::Vector3f(9.5f, 0.0f, 0.0f)));
  EXPECT_FALSE(near.anyWithin(Eigen::Vector3f(10.5001f, 0.0f, 0.0f)));
  // Across a cell boundary (cells of 1 m): the point's cell is not the query's.
  EXPECT_TRUE(near.anyWithin(Eigen::Vector3f(9.8f, 0.2f, -0.2f)));
}

TEST(NearPoints, ANonFiniteQueryIsNearNothingAndABadDistanceIsRefusedWithItsValue) {
  const NearPoints near({Eigen::Vector3f::Zero()}, 0.2);
  EXPECT_FALSE(near.anyWithin(Eigen::Vector3f(std::numeric_limits<float>::quiet_NaN(), 0.0f, 0.0f)));
  EXPECT_FALSE(near.anyWithin(Eigen::Vector3f(std::numeric_limits<float>::infinity(), 0.0f, 0.0f)));
  EXPECT_FALSE(near.anyWithin(Eigen::Vector3f(1e30f, 0.0f, 0.0f)));
  for (double bad : {0.0, -0.1, std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity()}) {
    try {
      NearPoints refused({Eigen::Vector3f::Zero()}, bad);
      ADD_FAILURE() << "a distance of " << bad << " was taken";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("distance must be finite and > 0"), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace coloc::roadside
