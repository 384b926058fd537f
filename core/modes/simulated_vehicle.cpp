#include "core/modes/simulated_vehicle.hpp"

namespace mixpilot {

void add_position_noise(double sigma, std::mt19937_64& rng,
                        std::normal_distribution<double>& noise, double* y) {
  for (int i = 0; i < 3; ++i) y[i] += sigma * noise(rng);
}

}  // namespace mixpilot
