// The paired comparison of overrun counts (overrun_comparison.hpp) against exact enumerations
// worked by hand, and its verdicts on made-up counts: a view that adds misses in every session
// fails it, one that adds none passes it, and too few differing pairs decide nothing.

#include "tests/viewer/overrun_comparison.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <vector>

using namespace kerf::test;

TEST(OverrunComparison, SignFlipPValuesByEnumeration) {
  // No differences: nothing against the null hypothesis.
  EXPECT_EQ(sign_flip_p_value(std::vector<long>{0, 0}), 1.0);
  // m differences all positive: only the all-plus sign vector reaches D, p = 2^-m.
  EXPECT_DOUBLE_EQ(sign_flip_p_value(std::vector<long>{1, 3, 2, 0, 5}), 1.0 / 16.0);
  // (1, -1): D = 0; sums over the 4 sign vectors 2, 0, 0, -2: three reach 0, p = 3/4.
  EXPECT_DOUBLE_EQ(sign_flip_p_value(std::vector<long>{1, -1}), 0.75);
  // (3, -1, 1): D = 3; sums ±3 ±1 ±1: 5, 3, 3, 1, -1, -3, -3, -5: three reach 3, p = 3/8.
  EXPECT_DOUBLE_EQ(sign_flip_p_value(std::vector<long>{3, -1, 1}), 0.375);
  // All negative (the view's sessions missed less): every vector reaches D, p = 1.
  EXPECT_DOUBLE_EQ(sign_flip_p_value(std::vector<long>{-2, -1}), 1.0);
  EXPECT_THROW(sign_flip_p_value(std::vector<long>(25, 1)), std::invalid_argument);
}

TEST(OverrunComparison, VerdictsOnMadeUpCounts) {
  constexpr double alpha = 0.01;
  // A machine that holds its deadlines, and a view that does too: the check.
  const std::vector<OverrunPair> clean(10);
  EXPECT_EQ(compare_overruns(clean, alpha).verdict, OverrunVerdict::view_missed_nothing);
  // The view's sessions clean, the machine's own sessions not: the view missed nothing.
  std::vector<OverrunPair> machine(10);
  machine[3].without = 2;
  EXPECT_EQ(compare_overruns(machine, alpha).verdict, OverrunVerdict::view_missed_nothing);
  // A view that adds 60 misses a second (one per frame) to 1.5 s sessions on a machine that
  // misses 0-2 by itself: every pair differs the same way, p = 2^-10 < alpha.
  std::vector<OverrunPair> bad;
  for (int i = 0; i < 10; ++i) bad.push_back({static_cast<std::uint64_t>(i % 3), static_cast<std::uint64_t>(90 + i % 3)});
  const OverrunComparison b = compare_overruns(bad, alpha);
  EXPECT_EQ(b.verdict, OverrunVerdict::view_worse);
  EXPECT_DOUBLE_EQ(b.p_value, std::ldexp(1.0, -10));
  // The same machine, a view that changes nothing: misses on both sides, either way round.
  const std::vector<OverrunPair> same{{1, 0}, {0, 2}, {2, 1}, {0, 0}, {1, 1}, {3, 0}, {0, 1}, {1, 2}, {2, 0}, {0, 1}};
  const OverrunComparison s = compare_overruns(same, alpha);
  EXPECT_EQ(s.unequal_pairs, 8);
  EXPECT_EQ(s.verdict, OverrunVerdict::view_not_worse);
  EXPECT_GT(s.p_value, 0.3);
  // Only three pairs differ: even three of three the view's way (p = 1/8) would not be
  // significant, so the comparison decides nothing — not a pass.
  const std::vector<OverrunPair> few{{0, 1}, {0, 0}, {0, 2}, {1, 1}, {0, 1}, {0, 0}};
  const OverrunComparison f = compare_overruns(few, alpha);
  EXPECT_EQ(f.unequal_pairs, 3);
  EXPECT_EQ(f.verdict, OverrunVerdict::inconclusive);
  EXPECT_THROW(compare_overruns(few, 0.0), std::invalid_argument);
}
