#include "app/wizard_controller.hpp"

#include "input/mapping.hpp"

namespace mixpilot::cli {

void WizardController::handle(const ui::WizardRequest& r, input::Gamepad& pad, int stick_mode,
                              std::string& message) {
  const auto end = [&] {
    pad.watch(-1);
    wizard_.reset();
  };
  std::visit(ui::overloaded{
                 [&](const ui::MapGamepad& m) {
                   for (const input::GamepadInfo& g : pad.devices()) {
                     if (g.instance != m.instance) continue;
                     wizard_.emplace(stick_mode, g.guid, g.name);
                     device_ = g.name;
                     pad.watch(g.instance);
                     message.clear();
                   }
                 },
                 [&](const ui::WizardSkip&) {
                   if (wizard_) (void)wizard_->skip();  // a required step is not skipped
                 },
                 [&](const ui::WizardBack&) {
                   if (wizard_) wizard_->back();
                 },
                 [&](const ui::WizardSave&) {
                   if (!wizard_) return;
                   const std::string line = wizard_->mapping();
                   if (line.empty()) return;  // not every stick bound yet: the wizard goes on
                   const std::string path = input::user_mappings_path();
                   std::string error;
                   if (input::save_mapping(path, line, error)) {
                     pad.add_mapping(line);
                     message = device_ + " is mapped (saved in " + path + ").";
                   } else {
                     message = error;
                   }
                   end();
                 },
                 [&](const ui::WizardCancel&) {
                   if (wizard_) end();
                 },
             },
             r);
}

void WizardController::update(input::Gamepad* pad, std::optional<ui::WizardView>& view) {
  if (!wizard_ || !pad) {
    view.reset();
    return;
  }
  raw_ = pad->raw();
  wizard_->feed(raw_);
  ui::WizardView& w = view.emplace();
  w.device = device_;
  w.step = wizard_->current();
  w.steps = wizard_->steps().size();
  w.done = wizard_->done();
  if (!w.done) {
    w.prompt = wizard_->steps()[w.step].prompt;
    w.optional = wizard_->steps()[w.step].optional;
  }
  w.hint = wizard_->hint();
  w.bindings = wizard_->bindings();
  w.mapping = wizard_->mapping();
  w.raw = &raw_;
}

}  // namespace mixpilot::cli
