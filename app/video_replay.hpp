#pragma once
// `mixpilot replay REC --video OUT.mp4`: the recording flown again into the app's tape, then
// each frame rendered offscreen exactly as `--screenshot` renders that time and piped to ffmpeg.
#include "app/flight.hpp"

namespace mixpilot::cli {

// The whole command from its checked options (o.video.path set); its exit status.
int replay_to_video(const FlyOptions& o);

}  // namespace mixpilot::cli
