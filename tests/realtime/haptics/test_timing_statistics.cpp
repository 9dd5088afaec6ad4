// Percentiles of the servo's duration histogram against the nearest-rank definition computed
// directly on the sorted samples (a second method), to the 0.5 us bin width.

#include "realtime/haptics/timing_statistics.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

using namespace kerf;

TEST(TimingStatistics, PercentilesMatchSortedSamplesToTheBinWidth) {
  DurationHistogram h;
  std::vector<double> samples;
  std::mt19937_64 random(3);
  std::lognormal_distribution<double> duration(std::log(20e-6), 0.6); // ~20 us, long tail
  for (int k = 0; k < 50000; ++k) {
    samples.push_back(duration(random));
    h.add(samples.back());
  }
  std::sort(samples.begin(), samples.end());
  for (double p : {1.0, 50.0, 90.0, 99.0, 99.9}) {
    // Nearest rank: the ceil(p/100 n)-th smallest sample.
    const auto rank = static_cast<std::size_t>(std::ceil(p / 100.0 * static_cast<double>(samples.size())));
    const double exact = samples[rank - 1];
    EXPECT_GE(h.percentile(p), exact) << p;
    EXPECT_LE(h.percentile(p), exact + DurationHistogram::bin_width) << p;
  }
  EXPECT_EQ(h.percentile(100.0), samples.back());
  EXPECT_EQ(h.max(), samples.back());
  EXPECT_EQ(h.count(), 50000u);
}

TEST(TimingStatistics, OverflowAndBadValues) {
  DurationHistogram h;
  EXPECT_EQ(h.percentile(50.0), 0.0); // empty
  h.add(-1.0);                        // counts as zero
  h.add(0.25);                        // beyond 10 ms: overflow bin, exact maximum kept
  EXPECT_EQ(h.count(), 2u);
  EXPECT_EQ(h.percentile(50.0), DurationHistogram::bin_width); // the zero sample's bin upper edge
  EXPECT_EQ(h.percentile(100.0), 0.25);
  h.clear();
  EXPECT_EQ(h.count(), 0u);
}
