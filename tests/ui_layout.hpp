#pragma once
// A layout as a person would judge it, read from ImGui's own state after a frame was rendered:
// no pane overlaps another, the overlays on the view (HUD, sticks, session panel, a replay's
// Debrief panel) stay inside it
// and apart, every window stays inside the display, no window holds more than it shows without
// a scrollbar to reach it (a label cut, a row of buttons under the next pane), and no text is
// drawn across its clip rectangle (a legend running out of its pane).
#include <algorithm>
#include <cfloat>
#include <cstdio>
#include <string>
#include <vector>

#include <imgui.h>
#include <imgui_internal.h>

namespace mixpilot::test {

inline std::string describe(const ImRect& r) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "(%.0f, %.0f)-(%.0f, %.0f)", double(r.Min.x), double(r.Min.y),
                double(r.Max.x), double(r.Max.y));
  return buf;
}

// The problems of the frame last rendered (after ImGui::Render()), one line each.
inline std::vector<std::string> layout_problems() {
  constexpr float kTolerance = 1.0f;  // [px] rounding of positions
  std::vector<std::string> out;
  ImGuiContext& g = *GImGui;
  const ImRect display(ImVec2(0, 0), g.IO.DisplaySize);
  const auto inside = [&](const ImRect& r, const ImRect& outer) {
    return r.Min.x >= outer.Min.x - kTolerance && r.Min.y >= outer.Min.y - kTolerance &&
           r.Max.x <= outer.Max.x + kTolerance && r.Max.y <= outer.Max.y + kTolerance;
  };
  const auto overlap = [&](const ImRect& a, const ImRect& b) {
    return std::min(a.Max.x, b.Max.x) - std::max(a.Min.x, b.Min.x) > kTolerance &&
           std::min(a.Max.y, b.Max.y) - std::max(a.Min.y, b.Min.y) > kTolerance;
  };
  const auto shown = [&](const char* name) -> ImGuiWindow* {
    ImGuiWindow* w = ImGui::FindWindowByName(name);
    return w && w->Active && !w->Hidden ? w : nullptr;
  };

  for (ImGuiWindow* w : g.Windows) {
    if (!w->Active || w->Hidden || (w->Flags & ImGuiWindowFlags_Tooltip)) continue;
    const std::string name = w->Name;
    if (!(w->Flags & ImGuiWindowFlags_ChildWindow) && !inside(w->Rect(), display))
      out.push_back(name + " " + describe(w->Rect()) + " leaves the display " + describe(display));
    // What the window's items need against what it shows (its inner clip rectangle).
    const ImVec2 need = w->DC.CursorMaxPos;
    const ImRect& shows = w->InnerClipRect;
    if (!w->ScrollbarX && need.x > shows.Max.x + kTolerance)
      out.push_back(name + ": its content reaches x " + std::to_string(int(need.x)) +
                    " but it shows up to " + std::to_string(int(shows.Max.x)) + " (cut on the right)");
    if (!w->ScrollbarY && need.y > shows.Max.y + kTolerance)
      out.push_back(name + ": its content reaches y " + std::to_string(int(need.y)) +
                    " but it shows up to " + std::to_string(int(shows.Max.y)) + " (cut at the bottom)");
  }

  // The fixed panes tile the display; the overlays lie inside the view, apart.
  const char* panes[] = {"##top", "##view", "##plots", "##transport"};
  const char* overlays[] = {"##hud", "##sticks", "Session", "Debrief"};
  for (std::size_t i = 0; i < std::size(panes); ++i)
    for (std::size_t j = i + 1; j < std::size(panes); ++j)
      if (ImGuiWindow *a = shown(panes[i]), *b = shown(panes[j]); a && b && overlap(a->Rect(), b->Rect()))
        out.push_back(std::string(panes[i]) + " " + describe(a->Rect()) + " overlaps " + panes[j] +
                      " " + describe(b->Rect()));
  if (ImGuiWindow* view = shown("##view")) {
    for (std::size_t i = 0; i < std::size(overlays); ++i) {
      ImGuiWindow* a = shown(overlays[i]);
      if (!a) continue;
      if (!inside(a->Rect(), view->Rect()))
        out.push_back(std::string(overlays[i]) + " " + describe(a->Rect()) + " leaves the view " +
                      describe(view->Rect()));
      for (std::size_t j = i + 1; j < std::size(overlays); ++j)
        if (ImGuiWindow* b = shown(overlays[j]); b && overlap(a->Rect(), b->Rect()))
          out.push_back(std::string(overlays[i]) + " " + describe(a->Rect()) + " overlaps " +
                        overlays[j] + " " + describe(b->Rect()));
    }
  }

  // Text: a glyph's quad that crosses its command's clip rectangle is a cut word (but for a
  // row half scrolled out of a window that scrolls). Glyphs are the vertices textured neither by
  // the atlas's white pixel (shapes) nor by its baked lines.
  const ImFontAtlas& atlas = *g.IO.Fonts;
  const ImFontAtlasCustomRect& baked = atlas.CustomRects[atlas.PackIdLines];
  const ImRect lines_uv(ImVec2(baked.X * atlas.TexUvScale.x, baked.Y * atlas.TexUvScale.y),
                        ImVec2((baked.X + baked.Width) * atlas.TexUvScale.x,
                               (baked.Y + baked.Height) * atlas.TexUvScale.y));
  const ImDrawData* data = ImGui::GetDrawData();
  for (int l = 0; data && l < data->CmdListsCount; ++l) {
    const ImDrawList* list = data->CmdLists[l];
    const ImGuiWindow* owner = list->_OwnerName ? ImGui::FindWindowByName(list->_OwnerName) : nullptr;
    const bool scrolls_x = owner && owner->ScrollbarX, scrolls_y = owner && owner->ScrollbarY;
    for (const ImDrawCmd& cmd : list->CmdBuffer) {
      if (cmd.UserCallback) continue;
      const ImRect clip(cmd.ClipRect.x, cmd.ClipRect.y, cmd.ClipRect.z, cmd.ClipRect.w);
      ImRect cut(ImVec2(FLT_MAX, FLT_MAX), ImVec2(-FLT_MAX, -FLT_MAX));
      for (unsigned i = 0; i < cmd.ElemCount; ++i) {
        const ImDrawVert& v = list->VtxBuffer[int(cmd.VtxOffset + list->IdxBuffer[int(cmd.IdxOffset + i)])];
        if ((v.uv.x == atlas.TexUvWhitePixel.x && v.uv.y == atlas.TexUvWhitePixel.y) ||
            lines_uv.Contains(v.uv))
          continue;
        const bool out_x = v.pos.x < clip.Min.x - kTolerance || v.pos.x > clip.Max.x + kTolerance;
        const bool out_y = v.pos.y < clip.Min.y - kTolerance || v.pos.y > clip.Max.y + kTolerance;
        if ((out_x && !scrolls_x) || (out_y && !scrolls_y)) cut.Add(v.pos);
      }
      if (cut.Min.x <= cut.Max.x)
        out.push_back(std::string("text cut in ") + (list->_OwnerName ? list->_OwnerName : "?") +
                      ": glyphs at " + describe(cut) + " cross the clip rectangle " + describe(clip));
    }
  }
  return out;
}

}  // namespace mixpilot::test
