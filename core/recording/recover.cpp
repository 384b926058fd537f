#include "core/recording/recover.hpp"

#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <map>

#include "core/base/output_file.hpp"
#include "core/recording/recording.hpp"

namespace mixpilot {

namespace {

// Messages to keep: all of them when the file's end record was written (the cut fell in the
// summary), else all but those of the last log time, i.e. of the last step, which the cut may
// have left incomplete.
std::size_t whole_step_messages(const McapFile& cut, bool has_end) {
  std::size_t keep = cut.messages.size();
  if (has_end || keep == 0) return keep;
  const uint64_t last = cut.messages.back().log_time;
  while (keep > 0 && cut.messages[keep - 1].log_time == last) --keep;
  return keep;
}

// A complete recording left as a temporary (its run was stopped between writing its last byte
// and moving it into place): checked to read back as a recording, copied to `out_path` as it
// is, and the temporary removed once the copy is in place.
std::optional<RecoveryResult> put_in_place(const McapFile& whole, const std::string& in_path,
                                           const std::string& out_path, bool overwrite,
                                           std::string& error) {
  const std::optional<RecordingContents> contents = decode_recording(whole, in_path, error);
  if (!contents) return std::nullopt;
  if (contents->states.empty()) {
    error = in_path + ": a complete recording of no control step; nothing to put in place";
    return std::nullopt;
  }
  OutputFile out;
  if (!out.open(out_path, overwrite, error)) return std::nullopt;
  if (std::fwrite(whole.bytes.data(), 1, whole.bytes.size(), out.stream()) != whole.bytes.size()) {
    error = out_path + ": write failed: " + std::strerror(errno) + "; nothing written";
    out.discard();
    return std::nullopt;
  }
  if (!out.commit(error, /*keep_partial=*/false)) return std::nullopt;
  ::unlink(in_path.c_str());  // its bytes are now at out_path
  RecoveryResult result;
  result.bytes_total = result.bytes_used = whole.bytes.size();
  result.messages = whole.messages.size();
  result.steps = contents->states.size();
  result.interrupted = contents->end ? contents->end->interrupted : true;
  result.was_complete = true;
  return result;
}

}  // namespace

std::optional<RecoveryResult> recover_recording(const McapFile& cut, const std::string& name,
                                                const std::string& out_path, bool overwrite,
                                                std::string& error) {
  if (cut.complete) {
    error = name + ": a complete recording; nothing to recover";
    return std::nullopt;
  }
  // Only what reads back as a recording is rewritten as one.
  const std::optional<RecordingContents> contents = decode_recording(cut, name, error);
  if (!contents) return std::nullopt;

  RecoveryResult result;
  result.bytes_total = cut.bytes.size();
  result.bytes_used = cut.parsed_bytes;
  const std::size_t keep = whole_step_messages(cut, contents->end.has_value());
  result.messages = keep;
  result.messages_left_out = cut.messages.size() - keep;
  uint16_t state_channel = 0;
  for (const auto& [id, c] : cut.channels)
    if (c.topic == "/vehicle/state") state_channel = id;
  uint64_t steps = 0;
  for (std::size_t i = 0; i < keep; ++i) steps += cut.messages[i].channel_id == state_channel;
  if (steps == 0) {  // a recording without a step is no flight: `score` could not replay it
    error = name + ": cut before its first whole control step (" +
            std::to_string(cut.parsed_bytes) + " of " + std::to_string(cut.bytes.size()) +
            " bytes readable); nothing to recover";
    return std::nullopt;
  }

  McapWriter w;
  McapWriteOptions options;
  options.overwrite = overwrite;
  options.profile = cut.profile;
  options.library = cut.library;
  if (!w.open(out_path, error, options)) return std::nullopt;
  // The writer numbers schemas and channels 1, 2, ...: map the original ids.
  std::map<uint16_t, uint16_t> schema_id, channel_id;
  for (const auto& [id, s] : cut.schemas) schema_id[id] = w.add_schema(s.name, s.encoding, s.data);
  for (const auto& [id, c] : cut.channels) {
    const uint16_t schema = c.schema_id == 0 ? 0 : schema_id.at(c.schema_id);
    channel_id[id] = w.add_channel(schema, c.topic, c.message_encoding, c.metadata);
  }
  for (const auto& md : cut.metadata)
    if (md.name != kEndMetadataName) w.write_metadata(md.name, md.metadata);
  for (std::size_t i = 0; i < keep; ++i) {
    const McapMessage& m = cut.messages[i];
    w.write_message(channel_id.at(m.channel_id), m.sequence, m.log_time, m.publish_time,
                    cut.data(m));
    if (m.channel_id == state_channel) ++result.steps;
  }
  RecordingEnd end;
  end.interrupted = contents->end ? contents->end->interrupted : true;
  end.recovered = true;
  end.steps = result.steps;
  end.dropped_steps = contents->end ? contents->end->dropped_steps : 0;
  result.interrupted = end.interrupted;
  w.write_metadata(kEndMetadataName, to_metadata(end));
  if (!w.close(error)) return std::nullopt;
  return result;
}

std::optional<RecoveryResult> recover_recording(const std::string& in_path,
                                                const std::string& out_path, bool overwrite,
                                                std::string& error) {
  if (same_file(in_path, out_path)) {
    error = out_path + ": the file being recovered; the recovered recording goes to another "
            "file (the cut one stays as it is)";
    return std::nullopt;
  }
  McapReadOptions options;
  options.allow_truncated = true;
  const std::optional<McapFile> cut = read_mcap(in_path, error, options);
  if (!cut) return std::nullopt;
  if (cut->complete && temporary_target(in_path)) return put_in_place(*cut, in_path, out_path,
                                                                      overwrite, error);
  return recover_recording(*cut, in_path, out_path, overwrite, error);
}

std::optional<std::string> temporary_target(const std::string& path) {
  namespace fs = std::filesystem;
  const std::string tmp = ".tmp";
  if (path.size() <= tmp.size() || !path.ends_with(tmp)) return std::nullopt;
  std::string target = path.substr(0, path.size() - tmp.size());
  // "<target>.XXXXXX": the writer's unique suffix (core/recording/output_file.cpp).
  const std::size_t dot = target.rfind('.');
  if (dot != std::string::npos && target.size() - dot == 7 &&
      std::all_of(target.begin() + std::ptrdiff_t(dot) + 1, target.end(),
                  [](unsigned char c) { return std::isalnum(c) != 0; }))
    target.resize(dot);
  const fs::path t(target);
  if (t.filename().empty() || t.filename() == "." || t.filename() == "..") return std::nullopt;
  return target;
}

std::string default_recovery_path(const std::string& in_path) {
  if (auto target = temporary_target(in_path)) return *target;
  const std::filesystem::path p(in_path);
  return (p.parent_path() / (p.stem().string() + ".recovered.mcap")).string();
}

}  // namespace mixpilot
