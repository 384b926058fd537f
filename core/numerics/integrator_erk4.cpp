#include "core/numerics/integrator_erk4.hpp"

namespace mixpilot {

// The one compiled copy of each shipped model's steps (see the header).
MIXPILOT_ERK4_STEPS(, models::MikroKopter)
MIXPILOT_ERK4_STEPS(, models::Crazyflie)
MIXPILOT_ERK4_STEPS(, models::Pendubot)
MIXPILOT_ERK4_STEPS(, models::WithExternalForce<models::MikroKopter>)
MIXPILOT_ERK4_STEPS(, models::WithExternalForce<models::Crazyflie>)

}  // namespace mixpilot
