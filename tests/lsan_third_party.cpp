// LeakSanitizer (the sanitize preset): allocations third-party libraries keep until exit are not
// ours to fix: SDL's joystick and event state after SDL_QuitSubSystem, Cyclone DDS's global
// state. mixpilot's own code is not suppressed. (Unused in other builds.)
extern "C" const char* __lsan_default_suppressions() {
  return "leak:libSDL2-2.0.so\nleak:libddsc.so\n";
}
