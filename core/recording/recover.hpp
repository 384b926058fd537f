#pragma once
// Recovering a recording cut short by a crash, `kill -9` or a full disk: the temporary
// "<name>.mcap.XXXXXX.tmp" that the writer leaves (core/base/output_file.hpp) holds every
// record written up to the cut. recover_recording() reads it with
// McapReadOptions::allow_truncated and writes a complete, valid recording of its whole control
// steps, closed by a "mixpilot_end" record marked recovered (docs/recording-format.md).
#include <cstdint>
#include <optional>
#include <string>

#include "core/recording/mcap.hpp"

namespace mixpilot {

struct RecoveryResult {
  uint64_t bytes_total = 0;        // size of the cut-short file
  uint64_t bytes_used = 0;         // end of its last complete record
  uint64_t messages = 0;           // messages written to the recovered file
  uint64_t messages_left_out = 0;  // complete messages of the last, possibly partial, step
  uint64_t steps = 0;              // control steps in the recovered file (/vehicle/state)
  bool interrupted = true;         // as written to mixpilot_end
  // The temporary was already a complete recording (its run was stopped between finishing it
  // and moving it into place): it was put in place as it is, and the temporary removed.
  bool was_complete = false;
};

// Recovers `in_path` into `out_path` (an OutputFile: never over an existing file unless
// `overwrite`; `out_path` may equal `in_path` with `overwrite`). Copies the Header's profile and
// library, every schema, channel and Metadata record, and the messages of every control step
// but the last one when the file has no "mixpilot_end" record: the cut may have fallen inside
// that step, and a step is kept whole or not at all (every message of step k is logged at k·Δt).
// The messages written are therefore a prefix of the original's. The end record says
// recovered, interrupted (unless the original's end record said otherwise) and the step count.
// A file cut before its first whole control step is refused ("nothing to recover": such a
// recording would hold no flight), and so is one that does not decode as a recording. A
// complete file is refused too, unless it is a writer's temporary ("<name>.XXXXXX.tmp"), which
// is then put in place as it is. The output never replaces the input. nullopt with the reason
// on failure; nothing is written then.
std::optional<RecoveryResult> recover_recording(const std::string& in_path,
                                                const std::string& out_path, bool overwrite,
                                                std::string& error);

// The same from a file already read with allow_truncated (`name` for messages).
std::optional<RecoveryResult> recover_recording(const McapFile& cut, const std::string& name,
                                                const std::string& out_path, bool overwrite,
                                                std::string& error);

// Where `mixpilot recover FILE` writes by default: the temporary's own target
// ("run.mcap.Ab12Cd.tmp" and "run.mcap.tmp" give "run.mcap"), else "<stem>.recovered.mcap".
std::string default_recovery_path(const std::string& in_path);

// The target of a writer's temporary ("run.mcap.Ab12Cd.tmp" or "run.mcap.tmp" → "run.mcap");
// nullopt for any other name.
std::optional<std::string> temporary_target(const std::string& path);

}  // namespace mixpilot
