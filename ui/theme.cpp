#include "ui/theme.hpp"

#include <algorithm>
#include <cmath>

#include <fontconfig/fontconfig.h>

namespace mixpilot::ui {
namespace {

ImFont* g_mono = nullptr;
ImFont* g_heading = nullptr;
ImFont* g_large = nullptr;
float g_scale = 1.0f;

// The file fontconfig matches for `family` ("DejaVu Sans") in `style` ("" regular, ":bold"),
// or "" when it is not that family.
std::string find_font(const char* family, const char* style = "") {
  std::string path;
  if (!FcInit()) return path;
  const std::string pattern = std::string(family) + style;
  FcPattern* pat = FcNameParse(reinterpret_cast<const FcChar8*>(pattern.c_str()));
  FcConfigSubstitute(nullptr, pat, FcMatchPattern);
  FcDefaultSubstitute(pat);
  FcResult result = FcResultNoMatch;
  if (FcPattern* match = FcFontMatch(nullptr, pat, &result)) {
    FcChar8* file = nullptr;
    FcChar8* name = nullptr;
    if (FcPatternGetString(match, FC_FILE, 0, &file) == FcResultMatch &&
        FcPatternGetString(match, FC_FAMILY, 0, &name) == FcResultMatch &&
        std::string(reinterpret_cast<const char*>(name)).rfind(family, 0) == 0)
      path = reinterpret_cast<const char*>(file);
    FcPatternDestroy(match);
  }
  FcPatternDestroy(pat);
  return path;
}

}  // namespace

ImU32 authority_colour(double lambda) {
  const double l = std::clamp(lambda, 0.0, 1.0);
  const ImVec4 a = ImGui::ColorConvertU32ToFloat4(colour::kPlannerFill);
  const ImVec4 b = ImGui::ColorConvertU32ToFloat4(colour::kPilot);
  const auto mix = [l](float x, float y) { return float((1.0 - l) * x + l * y); };
  return ImGui::ColorConvertFloat4ToU32(ImVec4(mix(a.x, b.x), mix(a.y, b.y), mix(a.z, b.z), 1.0f));
}

void apply_style(float scale) {
  g_scale = scale;
  ImGui::StyleColorsDark();
  ImGuiStyle& st = ImGui::GetStyle();
  st.WindowRounding = 4.0f;
  st.FrameRounding = 3.0f;
  st.WindowBorderSize = 0.0f;
  st.Colors[ImGuiCol_WindowBg] = ImVec4(0.10f, 0.11f, 0.13f, 0.92f);
  st.Colors[ImGuiCol_TitleBgActive] = ImVec4(0.16f, 0.18f, 0.21f, 1.0f);
  st.Colors[ImGuiCol_Button] = ImVec4(0.22f, 0.25f, 0.30f, 1.0f);
  st.Colors[ImGuiCol_ButtonHovered] = ImVec4(0.30f, 0.34f, 0.40f, 1.0f);
  st.ScaleAllSizes(scale);
}

std::string load_fonts(float scale) {
  ImGuiIO& io = ImGui::GetIO();
  io.Fonts->Clear();
  // Latin-1, Greek, then punctuation, sub- and superscripts, arrows and the mathematical
  // operators (‖ ₁ → √ ≤ ≥), and the geometric shapes (● ▶ ◆).
  static const ImWchar ranges[] = {0x0020, 0x00FF, 0x0370, 0x03FF, 0x2010, 0x22FF,
                                   0x25A0, 0x25FF, 0};
  const float px = std::round(15.0f * scale);
  const std::string sans = find_font("DejaVu Sans");
  const std::string mono = find_font("DejaVu Sans Mono");
  ImFont* main = nullptr;
  if (!sans.empty()) main = io.Fonts->AddFontFromFileTTF(sans.c_str(), px, nullptr, ranges);
  if (!main) {
    ImFontConfig built_in;
    built_in.SizePixels = std::round(13.0f * scale);
    io.Fonts->AddFontDefault(&built_in);
  }
  g_mono = nullptr;
  g_heading = nullptr;
  g_large = nullptr;
  if (main && !mono.empty())
    g_mono = io.Fonts->AddFontFromFileTTF(mono.c_str(), px, nullptr, ranges);
  // The score card's score: bold at 2.4 times the text, ASCII only (a number and its words).
  static const ImWchar ascii[] = {0x0020, 0x007E, 0};
  const std::string bold = main ? find_font("DejaVu Sans", ":bold") : std::string();
  if (!bold.empty())
    g_large = io.Fonts->AddFontFromFileTTF(bold.c_str(), std::round(px * kLargeFactor), nullptr, ascii);
  return main ? sans : std::string();
}

float ui_scale() { return g_scale; }

ImFont* mono_font() { return g_mono ? g_mono : ImGui::GetFont(); }

ImFont* add_heading_font(float scale, float factor) {
  static const ImWchar ranges[] = {0x0020, 0x00FF, 0x0370, 0x03FF, 0x2010, 0x22FF, 0};
  const std::string sans = find_font("DejaVu Sans", ":bold");
  g_heading = sans.empty() ? nullptr
                           : ImGui::GetIO().Fonts->AddFontFromFileTTF(
                                 sans.c_str(), std::round(15.0f * scale * factor), nullptr, ranges);
  return g_heading;
}

ImFont* heading_font() { return g_heading; }

ImFont* large_font() { return g_large; }

}  // namespace mixpilot::ui
