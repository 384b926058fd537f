#include "core/modes/command_script.hpp"

#include "core/base/toml_read.hpp"
#include "core/scenario/scenario_toml.hpp"  // read_text_file

namespace mixpilot {

namespace {

using namespace toml_read;

struct Script {
  std::vector<ScriptedCommand> commands;
  std::string source_path;
};

void read_command(Section c, Diagnostics& d, std::vector<ScriptedCommand>& out) {
  ScriptedCommand sc;
  sc.line = int(c.pos().line);
  c.num("at", sc.at, closed(0, 3600), true);
  std::string kind;
  const Pos kind_at = c.pos("kind");
  c.choice("kind", kind, {"bounds", "gust", "extra_delay", "input_loss", "marker", "end", "pause",
                          "resume"},
           true);
  InstructorCommand& cmd = sc.command;
  bool ok = !kind.empty();
  if (kind == "bounds") {
    cmd.kind = InstructorCommandKind::bounds;
    const bool floor = c.num("floor", cmd.bounds.floor, closed(0, 1));
    const bool ceiling = c.num("ceiling", cmd.bounds.ceiling, closed(0, 1));
    if (!c.table()->contains("floor") && !c.table()->contains("ceiling")) {
      d.add(c.pos(), c.path("floor"), "a bounds command needs floor, ceiling or both");
      ok = false;
    } else if ((floor || !c.table()->contains("floor")) &&
               (ceiling || !c.table()->contains("ceiling")) &&
               cmd.bounds.floor > cmd.bounds.ceiling) {
      d.add(c.pos("floor"), c.path("floor"),
            "expected floor <= ceiling, got floor " + fmt(cmd.bounds.floor) + " and ceiling " +
                fmt(cmd.bounds.ceiling));
      ok = false;
    }
  } else if (kind == "gust") {
    cmd.kind = InstructorCommandKind::gust;
    if (c.vec("force", cmd.force, closed(-kMaxGustForce, kMaxGustForce), true) &&
        cmd.force.norm() > kMaxGustForce) {
      d.add(c.pos("force"), c.path("force"),
            outside("the force's magnitude [N]", cmd.force.norm(), closed(0, kMaxGustForce)));
      ok = false;
    }
    c.num("duration", cmd.duration, left_open(0, kMaxCommandDuration), true);
  } else if (kind == "extra_delay") {
    cmd.kind = InstructorCommandKind::extra_delay;
    c.num("delay", cmd.delay, closed(0, kMaxExtraDelay), true);
  } else if (kind == "input_loss") {
    cmd.kind = InstructorCommandKind::input_loss;
    c.num("duration", cmd.duration, left_open(0, kMaxCommandDuration), true);
  } else if (kind == "marker") {
    cmd.kind = InstructorCommandKind::marker;
    std::string text;
    if (c.string("text", text, true)) {
      if (text.size() > DebriefNote::kCapacity) {
        d.add(c.pos("text"), c.path("text"),
              "expected at most " + std::to_string(DebriefNote::kCapacity) + " bytes, got " +
                  std::to_string(text.size()));
        ok = false;
      }
      cmd.text.assign(text);
    }
  } else if (kind == "end") {
    cmd.kind = InstructorCommandKind::end;
  } else if (kind == "pause" || kind == "resume") {
    d.add(kind_at, c.path("kind"),
          "\"" + kind + "\" is a live command only: a script's times are flight times, which "
          "stand still while the flight is paused (expected bounds, gust, extra_delay, "
          "input_loss, marker or end)");
    ok = false;
  }
  c.finish();
  if (ok) out.push_back(sc);
}

}  // namespace

std::optional<std::vector<ScriptedCommand>> parse_command_script(std::string_view text,
                                                                 const std::string& source,
                                                                 std::string& error) {
  const auto script = parse_document<Script>(text, source, error, [](const toml::table& root,
                                                                     Diagnostics& d) {
    Script s;
    Section top(d, &root, "", Pos{});
    const toml::node* n = top.take("command", true, "[[command]] tables");
    if (n) {
      const toml::array* a = n->as_array();
      if (!a || !a->is_array_of_tables()) {
        d.add(pos_of(n->source()), "command",
              "expected an array of tables ([[command]]), got " + describe(*n));
      } else if (a->size() > kMaxScriptCommands) {
        d.add(pos_of(n->source()), "command",
              outside("the number of commands", double(a->size()),
                      closed(0, double(kMaxScriptCommands))));
      } else {
        for (std::size_t i = 0; i < a->size(); ++i) {
          const toml::node& e = *a->get(i);
          read_command(Section(d, e.as_table(), "command[" + std::to_string(i) + "]",
                               pos_of(e.source())),
                       d, s.commands);
        }
      }
    }
    top.finish();
    return s;
  });
  if (!script) return std::nullopt;
  return script->commands;
}

std::optional<std::vector<ScriptedCommand>> load_command_script(const std::string& path,
                                                                std::string& error) {
  std::string text;
  if (!read_text_file(path, text, error)) return std::nullopt;
  return parse_command_script(text, path, error);
}

}  // namespace mixpilot
