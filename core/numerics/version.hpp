#pragma once
namespace mixpilot {
// "mixpilot <semver>", recorded in session metadata.
const char* version();
}  // namespace mixpilot
