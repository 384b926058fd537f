// PH index of SPEC §5.4 against its check values.
#include <gtest/gtest.h>

#include <cmath>

#include "core/control/ph_index.hpp"

namespace mixpilot {
namespace {

TEST(PhIndex, SpecCheckValues) {
  const PhIndexSettings s;  // Table 7.1
  EXPECT_NEAR(ph_lambda(0.0, s), 1.000, 5e-4);
  EXPECT_NEAR(ph_lambda(0.05, s), 0.949, 5e-4);
  EXPECT_NEAR(ph_lambda(0.07, s), 0.737, 5e-4);
  EXPECT_NEAR(ph_lambda(0.10, s), 0.392, 5e-4);
  EXPECT_NEAR(ph_lambda(s.r, s), 0.149, 5e-4);
}

TEST(PhIndex, SaturatesBeyondTheBall) {
  const PhIndexSettings s;
  EXPECT_EQ(ph_lambda(0.5, s), ph_lambda(s.r, s));
  EXPECT_EQ(ph_lambda(-1.0, s), ph_lambda(0.0, s));
}

TEST(PhIndex, MonotoneAndInsideTheOpenInterval) {
  const PhIndexSettings s;
  double prev = 2.0;
  for (double d = 0.0; d <= s.r; d += 1e-4) {
    const double l = ph_lambda(d, s);
    EXPECT_GT(l, 0.0);
    EXPECT_LT(l, 1.0) << d;  // open: the pilot never has the whole authority (SPEC §5.4)
    EXPECT_LE(l, prev + 1e-15) << d;
    prev = l;
  }
}

TEST(PhIndex, Log1pFormMatchesTheGompertzLimit) {
  // As ζ → 0, (1 + ζ e^a)^{1/ζ} → exp(e^a): d_sat = μ1 r exp(−e^a). At ζ = 1e-13 the two agree
  // to ~1e-12 (the naive pow(1 + ζ e^a, 1/ζ) rounds 1 + ζ e^a and keeps only ~3 digits).
  const PhIndexSettings s;
  for (double d : {0.02, 0.05, 0.08, 0.12}) {
    const double a = -s.theta2 * (d - s.mu2 * s.r);
    const double d_sat = s.mu1 * s.r * std::exp(-std::exp(a));
    const double lambda = std::sqrt(s.r * s.r - d_sat * d_sat) / s.r;
    EXPECT_NEAR(ph_lambda(d, s), lambda, 1e-9) << d;
  }
}

}  // namespace
}  // namespace mixpilot
