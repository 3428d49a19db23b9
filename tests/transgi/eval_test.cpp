// The evaluation harness's own logic: the Pareto front of a sweep.
#include <gtest/gtest.h>

#include "eval/pareto.h"

using transgi::eval::ParetoPoint;

TEST(Pareto, FrontHoldsExactlyThePointsNoOtherBeatsOnBothTimeAndError) {
  // (frame ms, RMSE): a, c, d and f are on the front; b is beaten by a
  // (faster and better), e by d, and g ties a on time but is worse.
  std::vector<ParetoPoint> p = {
      {"m", "a", "", 10, 0.10}, {"m", "b", "", 12, 0.12}, {"m", "c", "", 5, 0.30}, {"m", "d", "", 20, 0.05},
      {"m", "e", "", 25, 0.06}, {"m", "f", "", 40, 0.01}, {"m", "g", "", 10, 0.11},
  };
  transgi::eval::mark_pareto_front(p);
  const bool expected[] = {true, false, true, true, false, true, false};
  for (std::size_t i = 0; i < p.size(); ++i)
    EXPECT_EQ(p[i].on_front, expected[i]) << "point " << p[i].variant << " (" << p[i].frame_ms << " ms, RMSE " << p[i].rmse << ")";
}

TEST(Pareto, IdenticalPointsAreBothOnTheFront) {
  std::vector<ParetoPoint> p = {{"m", "a", "", 10, 0.1}, {"m", "b", "", 10, 0.1}, {"m", "c", "", 11, 0.2}};
  transgi::eval::mark_pareto_front(p);
  EXPECT_TRUE(p[0].on_front);
  EXPECT_TRUE(p[1].on_front);
  EXPECT_FALSE(p[2].on_front);
}
