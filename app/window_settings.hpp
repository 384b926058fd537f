#pragma once
// The window's own settings, in the user's config folder next to the input settings
// ($XDG_CONFIG_HOME/mixpilot/window.toml), written by the app:
//   text_scale = 1.25        # the text size: a factor on the display's scale (0.5-3)
//   welcome = "dismissed"    # the first launch's welcome was done with: it does not come back
// A missing file is the defaults; a broken one gives the defaults and says what was wrong.
#include <optional>
#include <string>

namespace mixpilot::cli {

struct WindowSettings {
  float text_scale = 1.0f;
  bool welcome_dismissed = false;
};

inline constexpr float kMinTextScale = 0.5f, kMaxTextScale = 3.0f;

// "" when the user has no config folder.
std::string default_window_settings_path();
// The settings at `path` ("" the default file). A file that cannot be read or holds something
// else gives the defaults and, in `note`, what was wrong ("FILE:LINE:COL: key: expected ...").
WindowSettings load_window_settings(const std::string& path, std::string& note);
// Writes them to `path` ("" the default file); false with the reason.
[[nodiscard]] bool save_window_settings(const std::string& path, const WindowSettings& s,
                                        std::string& error);

}  // namespace mixpilot::cli
